// The 3D view: loads a model's GLB, frames it, renders on demand and turns clicks into
// component selections. It only reacts to editor signals and reports picks/camera moves back.
// Once the model is proceduralized its components are coloured by label (the tree's colours).
// A point cloud model is its points.glb at the cloud's budget (cloud.js), or once
// proceduralized the points its grammar derives (derivedpoints.js); cloudview.js colours the
// points and turns a picked point into a segment or a node.
// Other modules draw through its layers (layers.js) and its camera helpers, never its scene.
import * as THREE from 'three';
import { OrbitControls } from 'three/examples/jsm/controls/OrbitControls.js';
import { GLTFLoader } from 'three/examples/jsm/loaders/GLTFLoader.js';
import { isCloud } from './cloud.js';
import { derivedScene } from './derivedpoints.js';
import { Layer, ModelLayer } from './layers.js';
import { peerSelections } from './peers.js';
import { Signal } from './signal.js';

// Flat, light background; model colours are mid-tones kept well away from it so the model
// always stands out (and the grid stays close to it so it never does).
export const BACKGROUND = 0xdde3ea;
const GRID_CENTER = 0xbcc4cd;
const GRID_LINES = 0xccd3da;
const PALETTE = [0xc4683f, 0x4f7cac, 0x6a994e, 0x9a6fa8, 0x3d8a8a, 0x8a6d5a, 0xa84f62, 0x5b6b7d];
// A picked component turns bright yellow, a colour the palette never uses.
const HIGHLIGHT = new THREE.Color(0xffc820);
const HIGHLIGHT_GLOW = new THREE.Color(0x3a2a00);
const CLICK_SLOP_PX = 5;
const POINT_PICK_PX = 6; // a click this close to a drawn point picks it

export class Viewport {
  constructor(editor, api, container) {
    this.editor = editor;
    this.api = api;
    this.container = container;
    this.signals = {
      shown: new Signal(), // {model, version}: that model's mesh is on screen now
      pointPicked: new Signal(), // {points, index, extend} of a click on a point cloud (null: none)
    };

    this.renderer = new THREE.WebGLRenderer({ antialias: true });
    this.renderer.setPixelRatio(window.devicePixelRatio || 1);
    this.renderer.domElement.setAttribute('data-testid', 'viewport-canvas');
    container.appendChild(this.renderer.domElement);
    this.canvas = this.renderer.domElement;

    this.scene = new THREE.Scene();
    this.scene.background = new THREE.Color(BACKGROUND);
    const hemi = new THREE.HemisphereLight(0xffffff, 0x8d8475, 1.0);
    this.scene.add(hemi);
    this.sun = new THREE.DirectionalLight(0xffffff, 1.3);
    this.sun.position.set(0.6, 1.0, 0.45);
    this.scene.add(this.sun);
    this.scene.add(this.sun.target);

    this.grid = null;
    this.layers = {
      model: new ModelLayer(this),
      preview: new Layer(this, 'preview'),
      handles: new Layer(this, 'handles'),
    };
    this.loadToken = 0;
    this.loading = null; // loadKey of what is loading or on screen
    this.frameOf = null; // 'mesh' | 'input' | 'derived': the coordinates the camera was framed in
    this.shown = null; // {model, version} on screen

    this.camera = new THREE.PerspectiveCamera(45, 1, 0.1, 1000);
    this.camera.position.set(12, 9, 14);
    this.controls = new OrbitControls(this.camera, this.canvas);
    this.controls.addEventListener('change', () => {
      this.requestRender();
      this.reportCamera();
    });

    this.pointerDown = null;
    const el = this.canvas;
    el.addEventListener('pointerdown', (e) => {
      if (e.button === 0) this.pointerDown = { x: e.clientX, y: e.clientY };
    });
    el.addEventListener('pointerup', (e) => {
      const d = this.pointerDown;
      this.pointerDown = null;
      if (e.button !== 0 || !d) return;
      if (Math.hypot(e.clientX - d.x, e.clientY - d.y) > CLICK_SLOP_PX) return; // an orbit drag
      this.pick(e.clientX, e.clientY, e.shiftKey);
    });

    this.status = document.createElement('div');
    this.status.className = 'viewport-status';
    container.appendChild(this.status);

    this.frame = 0;
    new ResizeObserver(() => this.resize()).observe(container);
    window.addEventListener('resize', () => this.resize());
    this.resize();
    this.makeGrid(10);

    const s = editor.signals;
    s.modelOpened.add((model) => this.load(model));
    s.meshChanged.add((model) => this.load(model, { keepCamera: true }));
    s.pointsChanged.add((model) => this.load(model, { keepCamera: true }));
    const reloadCloud = () => {
      if (isCloud(editor.model)) this.load(editor.model, { keepCamera: true });
    };
    editor.cloud.signals.budgetChanged.add(reloadCloud);
    editor.cloud.signals.viewChanged.add(reloadCloud);
    s.treeChanged.add(() => this.colourize());
    s.selectionChanged.add(() => this.highlight());
    s.peersChanged.add(() => this.highlight());
  }

  requestRender() {
    if (this.frame) return;
    this.frame = requestAnimationFrame(() => {
      this.frame = 0;
      this.renderer.render(this.scene, this.camera);
    });
  }

  resize() {
    const w = Math.max(1, this.container.clientWidth);
    const h = Math.max(1, this.container.clientHeight);
    this.renderer.setSize(w, h, true);
    this.camera.aspect = w / h;
    this.camera.updateProjectionMatrix();
    this.requestRender();
  }

  setStatus(text) {
    this.status.textContent = text || '';
    this.status.hidden = !text;
  }

  // A data attribute on the view (what tests and scripted demos wait for); null removes it.
  mark(name, value) {
    if (value === null || value === undefined) delete this.container.dataset[name];
    else this.container.dataset[name] = String(value);
  }

  // --- loading ------------------------------------------------------------------------------
  // keepCamera: the same model with a new mesh (it stays where the person was looking).
  async load(model, { keepCamera = false } = {}) {
    // one change may announce itself twice (a cloud's restore: its points and its derivation)
    const key = model ? this.loadKey(model) : null;
    if (keepCamera && key !== null && key === this.loading) return;
    this.loading = key;
    const token = ++this.loadToken;
    const layer = this.layers.model;
    // a cloud's uploaded points are local to its offset, its derived ones in the tree's
    // coordinates: switching between them frames the view again
    const frame = !model ? null : !isCloud(model) ? 'mesh' : this.editor.cloud.showsDerived(model) ? 'derived' : 'input';
    const reframe = !(keepCamera && layer.root && frame === this.frameOf);
    this.frameOf = frame;
    this.shown = null;
    this.mark('model', null);
    this.mark('version', null);
    if (reframe) layer.clear();
    if (!model) {
      this.setStatus('Open or import a model');
      return;
    }
    const version = model.version;
    const cloud = isCloud(model);
    const derived = this.editor.cloud.showsDerived(model);
    const budget = this.editor.cloud.budget;
    if (reframe) this.setStatus(cloud ? 'Loading points…' : 'Loading mesh…');
    try {
      let scene;
      if (derived) {
        const buffer = await this.api.derivedBuffer(model, budget);
        if (token !== this.loadToken) return;
        scene = derivedScene(buffer, budget, model.id);
      } else {
        const buffer = cloud ? await this.api.pointsBuffer(model, budget) : await this.api.meshBuffer(model);
        if (token !== this.loadToken) return;
        scene = (await new GLTFLoader().parseAsync(buffer, '')).scene;
      }
      if (token !== this.loadToken) return;
      this.show(scene, reframe);
      this.setStatus('');
      this.shown = { model: model.id, version };
      this.mark('model', model.id); // which model is on screen
      this.mark('version', version); // and which version of its mesh
      this.signals.shown.dispatch(this.shown);
    } catch (err) {
      if (token !== this.loadToken) return;
      this.loading = null;
      if (derived && err.status === 409) {
        // restored to before its proceduralization: its figures say so, and its uploaded
        // points are drawn (editor.updateModel)
        this.api.getModel(model.id).then((m) => this.editor.updateModel(m), (e) => this.editor.fail(e));
        return;
      }
      this.setStatus(cloud ? 'The points could not be shown' : 'The mesh could not be shown');
      this.editor.fail(err.problem || { title: 'Cannot show the mesh', detail: err.message });
    }
  }

  // What a load shows: the model's version, and for a cloud which points within which budget.
  loadKey(model) {
    const cloud = this.editor.cloud;
    return `${model.id}:${model.version}:${isCloud(model) ? `${cloud.showsDerived(model) ? 'derived' : 'input'}:${cloud.budget}` : ''}`;
  }

  show(root, reframe = true) {
    const layer = this.layers.model;
    layer.set(root);
    for (const meshes of layer.byComponent.values()) {
      for (const o of meshes) {
        if (!o.isMesh) continue; // points are coloured by cloudview.js
        // Own material per mesh so a highlight touches only the picked component.
        for (const m of [].concat(o.material)) m.dispose();
        o.material = new THREE.MeshStandardMaterial({
          roughness: 0.85,
          metalness: 0,
          side: THREE.DoubleSide,
          polygonOffset: true,
          polygonOffsetFactor: 1,
          polygonOffsetUnits: 1,
        });
      }
    }
    if (reframe) this.frameModel();
    this.colourize();
  }

  // Base colours: the model layer's tint when one is set (e.g. the city view's height
  // colours), else by label with the tree's colours once the model is proceduralized;
  // otherwise one palette colour per kind of group ("window_3" and "window_7" are both
  // windows), or per component when ungrouped.
  colourize() {
    const tree = this.editor.tree;
    const layer = this.layers.model;
    const groupColour = new Map();
    for (const meshes of layer.byComponent.values()) {
      for (const o of meshes) {
        if (!o.isMesh) continue;
        const byLabel = tree && o.userData.label !== null ? tree.colourOf(o.userData.label) : null;
        let colour;
        if (byLabel) {
          colour = new THREE.Color(byLabel);
        } else {
          const group = o.userData.groupName;
          const key = group !== null ? `g:${groupKind(group)}` : `c:${o.userData.componentId}`;
          if (!groupColour.has(key)) groupColour.set(key, PALETTE[groupColour.size % PALETTE.length]);
          colour = new THREE.Color(groupColour.get(key));
        }
        o.userData.baseColour = (layer.tint && layer.tint(o)) || colour;
      }
    }
    this.highlight();
  }

  // --- camera -------------------------------------------------------------------------------
  // Places the camera so the whole model fits, and the grid under it.
  frameModel() {
    const box = this.layers.model.bounds();
    if (box.isEmpty()) return;
    const sphere = box.getBoundingSphere(new THREE.Sphere());
    const r = Math.max(sphere.radius, 1e-3);
    const dist = (r / Math.sin(this.fitAngle() / 2)) * 1.15;
    this.look(sphere.center, new THREE.Vector3(1, 0.75, 1.25), dist, { near: dist / 200, far: dist * 50 });

    const size = box.getSize(new THREE.Vector3());
    this.makeGrid(niceSize(Math.max(size.x, size.z) * 3));
    this.grid.position.set(sphere.center.x, box.min.y - r * 1e-3, sphere.center.z);
    this.sun.position.copy(sphere.center).addScaledVector(new THREE.Vector3(0.6, 1.0, 0.45), dist);
    this.sun.target.position.copy(sphere.center);
    this.requestRender();
  }

  // A steep look down that fits the model's ground extent (the orbit framing fits a bounding
  // sphere from low down, which leaves a flat city small).
  frameGround() {
    const box = this.layers.model.bounds();
    if (box.isEmpty()) return;
    const size = box.getSize(new THREE.Vector3());
    const centre = box.getCenter(new THREE.Vector3());
    const r = Math.max(0.5 * Math.hypot(size.x, size.z), size.y, 1e-3);
    const dist = (r / Math.tan(this.fitAngle() / 2)) * 1.05;
    this.look(centre, new THREE.Vector3(0.35, 1, 0.6), dist, { near: dist / 500, far: dist * 20 });
  }

  // The narrower of the vertical and horizontal fields of view.
  fitAngle() {
    const fov = THREE.MathUtils.degToRad(this.camera.fov);
    return Math.min(fov, 2 * Math.atan(Math.tan(fov / 2) * this.camera.aspect));
  }

  // Looks at `target` from `dist` away along `direction`.
  look(target, direction, dist, { near, far }) {
    this.camera.position.copy(target).addScaledVector(direction.clone().normalize(), dist);
    this.camera.near = near;
    this.camera.far = far;
    this.camera.updateProjectionMatrix();
    this.controls.target.copy(target);
    this.controls.update();
    this.requestRender();
    this.reportCamera();
  }

  // Orbiting on or off (a tool dragging in the view turns it off).
  setOrbit(enabled) {
    this.controls.enabled = enabled;
  }

  // A ray through a pointer position (client pixels).
  ray(clientX, clientY) {
    const rect = this.canvas.getBoundingClientRect();
    const ndc = new THREE.Vector2(((clientX - rect.left) / rect.width) * 2 - 1, -((clientY - rect.top) / rect.height) * 2 + 1);
    const rc = new THREE.Raycaster();
    rc.setFromCamera(ndc, this.camera);
    return rc;
  }

  // Where a world point is drawn, in CSS pixels relative to the canvas.
  toScreen(point) {
    this.camera.updateMatrixWorld();
    const p = point.clone().project(this.camera);
    return { x: ((p.x + 1) / 2) * this.canvas.clientWidth, y: ((1 - p.y) / 2) * this.canvas.clientHeight };
  }

  // World size of one CSS pixel at a point (to keep tools a constant size on screen).
  worldPerPixel(point) {
    const h = this.canvas.clientHeight || 1;
    const d = this.camera.position.distanceTo(point);
    return (2 * d * Math.tan(THREE.MathUtils.degToRad(this.camera.fov) / 2)) / h;
  }

  makeGrid(size) {
    if (this.grid) {
      this.scene.remove(this.grid);
      this.grid.geometry.dispose();
      this.grid.material.dispose();
    }
    this.grid = new THREE.GridHelper(size, 20, GRID_CENTER, GRID_LINES);
    this.scene.add(this.grid);
    this.requestRender();
  }

  // --- picking ------------------------------------------------------------------------------
  // Shift adds the component's split-tree node to the selection (or takes it out).
  pick(clientX, clientY, extend = false) {
    const layer = this.layers.model;
    if (!layer.root) return;
    if (layer.points.length) {
      const hit = this.hitPoint(clientX, clientY);
      this.signals.pointPicked.dispatch(hit && { ...hit, extend });
      return;
    }
    const owner = layer.hit(this.ray(clientX, clientY));
    const selected = this.editor.selected;
    if (!owner) {
      selected.clear();
      return;
    }
    const node = this.editor.tree?.nodeOfComponent(owner.userData.component) ?? null;
    if (extend && node !== null) {
      selected.toggle(node);
      return;
    }
    selected.set({ component: owner.userData.component, group: owner.userData.group ?? null });
  }

  // The drawn point nearest the camera within a few pixels of a pointer position, as
  // {points, index} (the THREE.Points object and the point's index in it), or null.
  hitPoint(clientX, clientY) {
    const rc = this.ray(clientX, clientY);
    rc.params.Points.threshold = this.worldPerPixel(this.controls.target) * POINT_PICK_PX;
    const hit = rc.intersectObjects(this.layers.model.points, false)[0];
    return hit ? { points: hit.object, index: hit.index } : null;
  }

  // Our selection in yellow; what others have selected in their colours.
  highlight() {
    const on = new Set(this.editor.selected.components());
    const theirs = new Map([...peerSelections(this.editor.peers)].map(([c, hex]) => [c, new THREE.Color(hex)]));
    for (const [component, meshes] of this.layers.model.components()) {
      const lit = on.has(component);
      const peer = lit ? null : theirs.get(component);
      for (const mesh of meshes) {
        if (!mesh.isMesh) continue; // cloudview.js lights picked points
        mesh.material.color.copy(lit ? HIGHLIGHT : peer || mesh.userData.baseColour);
        mesh.material.emissive.copy(lit ? HIGHLIGHT_GLOW : peer ? peer.clone().multiplyScalar(0.25) : BLACK);
      }
    }
    this.requestRender();
  }

  reportCamera() {
    const round = (v) => [v.x, v.y, v.z].map((n) => Math.round(n * 1000) / 1000);
    this.editor.setCamera({ position: round(this.camera.position), target: round(this.controls.target) });
  }
}

const BLACK = new THREE.Color(0x000000);

function groupKind(name) {
  const m = /^[A-Za-z]+/.exec(String(name));
  return m ? m[0].toLowerCase() : String(name);
}

function niceSize(x) {
  if (!(x > 0)) return 10;
  const p = 10 ** Math.floor(Math.log10(x));
  for (const m of [1, 2, 5, 10]) if (m * p >= x) return m * p;
  return 10 * p;
}
