// The live drag preview: while someone drags a handle, the server re-solves the resize and
// sends the room the nodes' new boxes; this moves and stretches each component of the
// viewport's model layer from its node's stored box to the previewed one, until the committed
// op's mesh arrives (or the drag is abandoned). Our own drag is shown the same way at once,
// before the server's answer, for the dragged node alone.
import * as THREE from 'three';

const ABANDONED_MS = 3000; // a preview.end not followed by an op: drop the preview after this
const TINY = 1e-9;

// z-up archgram box [minx, miny, minz, maxx, maxy, maxz] → three.js world (y-up: x, z, −y).
export function worldBox(b) {
  return new THREE.Box3(new THREE.Vector3(b[0], b[2], -b[4]), new THREE.Vector3(b[3], b[5], -b[1]));
}

export class PreviewLayer {
  constructor(editor, viewport, live) {
    this.editor = editor;
    this.viewport = viewport;
    this.live = live;
    this.boxes = new Map();   // node -> previewed box (archgram axes)
    this.peer = null;         // whose preview is shown (null: our own)
    this.endTimer = null;
    this.meshes = new Set();  // meshes moved from their loaded place
    this.received = 0;        // preview messages applied (for tests)
    this.refused = 0;         // preview.error answers to ours

    live.on('preview', (msg, inRoom) => {
      if (!inRoom || !Array.isArray(msg.boxes)) return;
      if (msg.base != null && this.editor.version != null && msg.base !== this.editor.version) return;
      this.received += 1;
      this.show(msg.boxes, msg.peer ?? null, msg.author ?? null);
    });
    // Our own preview refused (stale base, invalid op): the committed op will say why, if sent.
    live.on('preview.error', (msg, inRoom) => {
      if (!inRoom) return;
      this.refused += 1;
      const p = msg.problem;
      if (p && !/stale/.test(p.type || '') && this.refused === 1) console.warn(`archgram: preview refused: ${p.title}${p.detail ? `: ${p.detail}` : ''}`);
    });
    live.on('preview.end', (msg, inRoom) => {
      if (!inRoom) return;
      // The op follows; its mesh replaces ours. Only a drag that commits nothing is undone here.
      clearTimeout(this.endTimer);
      this.endTimer = setTimeout(() => this.clear(), ABANDONED_MS);
    });
    const s = editor.signals;
    s.modelOpened.add(() => this.clear());
    s.meshChanged.add(() => this.forget());
    s.treeChanged.add(() => this.forget());
  }

  // Shows previewed boxes [{node, box}] from `peer` (null: our own drag).
  show(boxes, peer = null, author = null) {
    clearTimeout(this.endTimer);
    this.peer = peer;
    for (const { node, box } of boxes) {
      if (Array.isArray(box) && box.length === 6 && box.every(Number.isFinite)) this.boxes.set(node, box);
    }
    this.apply();
    this.viewport.mark('preview', this.boxes.size);
    this.viewport.mark('previewBy', author || peer || 'me');
  }

  // Back to the loaded geometry.
  clear() {
    clearTimeout(this.endTimer);
    this.boxes.clear();
    this.peer = null;
    for (const o of this.meshes) restore(o);
    this.meshes.clear();
    this.viewport.mark('preview', null);
    this.viewport.mark('previewBy', null);
    this.viewport.requestRender();
  }

  // A new mesh or tree replaced what the preview moved: nothing to restore.
  forget() {
    this.meshes.clear();
    this.clear();
  }

  // Each component follows the nearest previewed node at or above its own node.
  apply() {
    const tree = this.editor.tree;
    const vp = this.viewport;
    if (!tree) return;
    for (const [component, meshes] of vp.layers.model.components()) {
      const target = this.nearest(tree, component);
      for (const o of meshes) {
        if (!target) {
          if (this.meshes.has(o)) {
            restore(o);
            this.meshes.delete(o);
          }
          continue;
        }
        remember(o);
        place(o, worldBox(target.from), worldBox(target.to));
        this.meshes.add(o);
      }
    }
    vp.requestRender();
  }

  nearest(tree, component) {
    let id = tree.nodeOfComponent(component);
    const seen = new Set();
    while (id !== null && id !== undefined && !seen.has(id)) {
      seen.add(id);
      const n = tree.node(id);
      if (!n) return null;
      const to = this.boxes.get(id);
      if (to && Array.isArray(n.box) && n.box.length === 6) return { from: n.box, to };
      id = n.parent;
    }
    return null;
  }
}

function remember(o) {
  if (o.userData.previewHome) return;
  o.updateMatrix();
  o.userData.previewHome = { matrix: o.matrix.clone(), auto: o.matrixAutoUpdate };
}

function restore(o) {
  const home = o.userData.previewHome;
  if (!home) return;
  o.matrix.copy(home.matrix);
  o.matrix.decompose(o.position, o.quaternion, o.scale);
  o.matrixAutoUpdate = home.auto;
  o.updateMatrixWorld(true);
  delete o.userData.previewHome;
}

// Maps the mesh so that world box `from` lands on `to`, per axis (scale about `from`'s min
// corner, then translate). A flat axis (size ~0) keeps its scale and only moves by the centre.
function place(o, from, to) {
  const home = o.userData.previewHome;
  const s = new THREE.Vector3();
  const t = new THREE.Vector3();
  for (const k of ['x', 'y', 'z']) {
    const a = from.max[k] - from.min[k];
    const b = to.max[k] - to.min[k];
    if (a > TINY) {
      s[k] = b / a;
      t[k] = to.min[k] - s[k] * from.min[k];
    } else {
      s[k] = 1;
      t[k] = (to.min[k] + to.max[k]) / 2 - (from.min[k] + from.max[k]) / 2;
    }
  }
  // local' = P⁻¹ · A · P · local, with P the parent's world matrix and A the world-space map.
  const A = new THREE.Matrix4().makeScale(s.x, s.y, s.z).premultiply(new THREE.Matrix4().makeTranslation(t.x, t.y, t.z));
  if (o.parent) o.parent.updateMatrixWorld(true);
  const P = o.parent ? o.parent.matrixWorld.clone() : new THREE.Matrix4();
  const m = P.clone().invert().multiply(A).multiply(P).multiply(home.matrix);
  o.matrixAutoUpdate = false;
  o.matrix.copy(m);
  o.updateMatrixWorld(true);
}
