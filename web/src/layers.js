// The viewport's layers: each a group in the scene that one part of the client draws into, so
// no module reaches into the scene or another module's objects.
//   model    the loaded model, its meshes by component (picking, colours, drag previews), or
//            the points of a point cloud model (a derived cloud's by placement, its components)
//   preview  stand-ins drawn in place of model components (an extrusion's live preview)
//   handles  tools drawn over the model (resize handles, the split plane)
import * as THREE from 'three';

// Frees the GPU resources of an object and everything under it.
export function dispose(object) {
  object.traverse((o) => {
    o.geometry?.dispose();
    for (const m of [].concat(o.material ?? [])) m.dispose();
  });
}

export class Layer {
  constructor(viewport, name) {
    this.viewport = viewport;
    this.group = new THREE.Group();
    this.group.name = name;
    viewport.scene.add(this.group);
  }

  add(object) {
    this.group.add(object);
    this.viewport.requestRender();
    return object;
  }

  // Takes an object out of the layer and frees it.
  remove(object) {
    if (!object) return;
    this.group.remove(object);
    dispose(object);
    this.viewport.requestRender();
  }

  clear() {
    for (const o of [...this.group.children]) this.remove(o);
  }

  get objects() {
    return this.group.children;
  }
}

// The model on screen: one root (a loaded GLB scene) and its meshes by component id.
export class ModelLayer extends Layer {
  constructor(viewport) {
    super(viewport, 'model');
    this.root = null;
    this.byComponent = new Map(); // component -> meshes (and the Points of a derived cloud)
    this.points = [];             // THREE.Points of a point cloud model
    this.tint = null;             // (mesh) => THREE.Color | null: a colouring that overrides labels
  }

  // Shows `root` in place of what was there; each mesh is filed under its component.
  set(root) {
    this.clear();
    this.root = root;
    root.traverse((o) => {
      if (o.isPoints) this.points.push(o);
      if (!o.isMesh && !o.isPoints) return;
      const owner = componentOwner(o);
      const component = owner ? owner.userData.component : -1;
      o.userData.componentId = component;
      o.userData.groupName = owner ? owner.userData.group ?? null : null;
      o.userData.label = owner && typeof owner.userData.label === 'string' ? owner.userData.label : null;
      if (!this.byComponent.has(component)) this.byComponent.set(component, []);
      this.byComponent.get(component).push(o);
    });
    this.add(root);
  }

  clear() {
    super.clear();
    this.root = null;
    this.byComponent.clear();
    this.points = [];
  }

  meshes(component) {
    return this.byComponent.get(component) || [];
  }

  // Hides these components' meshes (something else stands in for them) until unhide().
  hide(components) {
    for (const c of components) for (const m of this.meshes(c)) m.visible = false;
    this.viewport.requestRender();
  }

  unhide() {
    for (const meshes of this.byComponent.values()) for (const m of meshes) m.visible = true;
    this.viewport.requestRender();
  }

  // [component, meshes] pairs.
  components() {
    return this.byComponent.entries();
  }

  // World bounds of the whole model (empty when nothing is loaded).
  bounds() {
    return this.root ? new THREE.Box3().setFromObject(this.root) : new THREE.Box3();
  }

  // The component under a ray, as its owner object ({component, group} in userData), or null.
  hit(raycaster) {
    if (!this.root) return null;
    const hit = raycaster.intersectObject(this.root, true).find((h) => h.object.isMesh);
    return hit ? componentOwner(hit.object) : null;
  }
}

// The nearest object (itself or an ancestor) that the GLB marked with a component id.
function componentOwner(o) {
  for (let x = o; x; x = x.parent) {
    if (typeof x.userData?.component === 'number') return x;
  }
  return null;
}
