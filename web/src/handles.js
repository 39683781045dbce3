// Face handles on the selected split-tree node's box: drag one along its face normal to resize
// the node. While dragging, the node's new box is shown at once and sent as a preview (at most
// 30 a second); the server's re-solved boxes for the whole area of effect reach everyone in the
// room. Releasing sends one resize op — one undo step.
import * as THREE from 'three';
import { editsShown } from './edittools.js';
import { worldBox } from './previewlayer.js';

const PREVIEW_INTERVAL_MS = 1000 / 30;
const HANDLE_COLOUR = 0x00c8ff;
const HANDLE_HOVER = 0xffffff;
const BOX_COLOUR = 0x0a84c8;
const HANDLE_PX = 14;       // handle size on screen, in CSS pixels
const MIN_SIZE_FRACTION = 0.05; // a face cannot pass this close to the opposite face
const MOVE_SLOP_PX = 3;

// Faces in archgram axes: [name, axis, side]; world normal follows x → x, y → −z, z → y.
const FACES = [
  ['x-', 0, -1], ['x+', 0, 1],
  ['y-', 1, -1], ['y+', 1, 1],
  ['z-', 2, -1], ['z+', 2, 1],
];

function worldNormal(axis, side) {
  if (axis === 0) return new THREE.Vector3(side, 0, 0);
  if (axis === 1) return new THREE.Vector3(0, 0, -side);
  return new THREE.Vector3(0, side, 0);
}

export class Handles {
  constructor(editor, viewport, live, preview, tools) {
    this.editor = editor;
    this.viewport = viewport;
    this.live = live;
    this.preview = preview;
    this.tools = tools;
    this.group = new THREE.Group();
    this.group.userData.tool = 'handles';
    this.group.renderOrder = 10;
    viewport.layers.handles.add(this.group);
    this.node = null;   // the node the handles belong to
    this.box = null;    // its box as shown (archgram axes)
    this.drag = null;
    this.hover = null;
    this.lastSent = 0;
    this.sendTimer = null;
    this.sent = 0;      // previews sent (for tests)

    const el = viewport.canvas;
    // Capture phase: a press on a handle must reach neither the orbit controls nor picking.
    el.addEventListener('pointerdown', (e) => this.down(e), { capture: true });
    el.addEventListener('pointermove', (e) => this.move(e));
    el.addEventListener('pointerup', (e) => this.up(e), { capture: true });
    el.addEventListener('pointercancel', (e) => this.up(e, true), { capture: true });
    window.addEventListener('keydown', (e) => {
      if (e.key === 'Escape' && this.drag) this.cancel(); // back to where the drag began
    });

    const s = editor.signals;
    s.selectionChanged.add(() => this.sync());
    s.treeChanged.add(() => this.sync());
    s.modelOpened.add(() => this.sync());
    s.roleChanged.add(() => this.sync()); // viewers get no drag handles
    editor.cloud.signals.viewChanged.add(() => this.sync());
    s.cameraChanged.add(() => this.scale());
  }

  // Handles for a single selected node with a box; none otherwise.
  sync() {
    if (this.drag) this.cancel();
    const tree = this.editor.tree;
    const id = this.editor.selected.single();
    // a point model is edited on the points its grammar derives (drawn in the coordinates of
    // its tree's boxes), not on the uploaded ones
    const editable = tree && this.editor.canEdit && editsShown(this.editor);
    const n = id !== null && editable ? tree.node(id) : null;
    if (!n || !Array.isArray(n.box) || n.box.length !== 6) {
      this.node = null;
      this.box = null;
    } else {
      this.node = n.id;
      this.box = n.box.slice();
    }
    this.build();
  }

  build() {
    for (const c of [...this.group.children]) {
      this.group.remove(c);
      c.geometry?.dispose();
      c.material?.dispose();
    }
    this.hover = null;
    if (this.box) {
      const outline = new THREE.Box3Helper(new THREE.Box3(), BOX_COLOUR);
      outline.material.depthTest = false;
      outline.material.transparent = true;
      outline.renderOrder = 10;
      outline.userData.outline = true;
      this.group.add(outline);
      for (const [name, axis, side] of FACES) {
        const m = new THREE.Mesh(
          new THREE.BoxGeometry(1, 1, 1),
          new THREE.MeshBasicMaterial({ color: HANDLE_COLOUR, depthTest: false, transparent: true, opacity: 0.95 }),
        );
        m.renderOrder = 11;
        m.userData.face = { name, axis, side };
        this.group.add(m);
      }
    }
    this.place();
  }

  // Puts the outline and the handles on this.box.
  place() {
    const box = this.box ? worldBox(this.box) : null;
    for (const c of this.group.children) {
      if (c.userData.outline) {
        c.box.copy(box);
      } else if (c.userData.face) {
        const { axis, side } = c.userData.face;
        const p = box.getCenter(new THREE.Vector3());
        const n = worldNormal(axis, side);
        const half = box.getSize(new THREE.Vector3()).multiplyScalar(0.5);
        p.add(new THREE.Vector3(n.x * half.x, n.y * half.y, n.z * half.z));
        c.position.copy(p);
      }
    }
    this.scale();
  }

  // Keeps the handles a constant size on screen.
  scale() {
    const vp = this.viewport;
    for (const c of this.group.children) {
      if (c.userData.face) c.scale.setScalar(vp.worldPerPixel(c.position) * HANDLE_PX);
    }
    vp.requestRender();
  }

  // The handle under a pointer position, or null.
  hit(e) {
    if (!this.box) return null;
    const ray = this.viewport.ray(e.clientX, e.clientY);
    const hits = ray.intersectObjects(this.group.children.filter((c) => c.userData.face), false);
    return hits.length ? hits[0].object : null;
  }

  // Where along the handle's axis (world units from its start) the pointer ray passes closest.
  along(e, drag) {
    const r = this.viewport.ray(e.clientX, e.clientY).ray;
    const d = drag.normal;
    const w = drag.origin.clone().sub(r.origin);
    const b = d.dot(r.direction);
    const denom = 1 - b * b;
    if (denom < 1e-6) return null; // looking straight down the axis
    return (b * r.direction.dot(w) - d.dot(w)) / denom;
  }

  down(e) {
    if (e.button !== 0 || this.drag) return;
    const handle = this.hit(e);
    if (!handle) return;
    e.stopImmediatePropagation();
    e.preventDefault();
    const { name, axis, side } = handle.userData.face;
    const drag = {
      handle,
      face: name,
      axis,
      side,
      node: this.node,
      start: this.box.slice(),
      normal: worldNormal(axis, side),
      origin: handle.position.clone(),
      pointer: { x: e.clientX, y: e.clientY },
      moved: false,
      sent: 0,
      t0: 0,
      box: this.box.slice(),
    };
    drag.t0 = this.along(e, drag) ?? 0;
    this.drag = drag;
    this.viewport.setOrbit(false);
    this.viewport.canvas.setPointerCapture?.(e.pointerId);
    this.viewport.mark('dragging', name);
  }

  move(e) {
    const drag = this.drag;
    if (!drag) {
      this.setHover(this.hit(e));
      return;
    }
    if (!drag.moved && Math.hypot(e.clientX - drag.pointer.x, e.clientY - drag.pointer.y) < MOVE_SLOP_PX) return;
    drag.moved = true;
    const t = this.along(e, drag);
    if (t === null) return;
    const i = drag.axis + (drag.side > 0 ? 3 : 0);
    const size = drag.start[drag.axis + 3] - drag.start[drag.axis];
    const min = Math.max(size * MIN_SIZE_FRACTION, 1e-3);
    const box = drag.start.slice();
    box[i] = drag.start[i] + drag.side * (t - drag.t0);
    if (box[drag.axis + 3] - box[drag.axis] < min) box[i] = drag.side > 0 ? box[drag.axis] + min : box[drag.axis + 3] - min;
    drag.box = box;
    this.box = box;
    this.place();
    this.preview.show([{ node: drag.node, box }]);
    this.schedule();
  }

  // Sends the latest box now, or once the 30-per-second budget allows.
  schedule() {
    if (this.sendTimer) return;
    const wait = Math.max(0, this.lastSent + PREVIEW_INTERVAL_MS - performance.now());
    this.sendTimer = setTimeout(() => {
      this.sendTimer = null;
      const drag = this.drag;
      if (!drag) return;
      this.lastSent = performance.now();
      this.sent += 1;
      drag.sent += 1;
      const ed = this.editor;
      this.live.send({ type: 'preview', model: ed.model.id, base: ed.model.version, op: this.tools.resizeOp(drag.node, drag.box) });
    }, wait);
  }

  async up(e, cancelled = false) {
    const drag = this.drag;
    if (!drag) return;
    e.stopImmediatePropagation();
    this.drag = null;
    clearTimeout(this.sendTimer);
    this.sendTimer = null;
    this.viewport.setOrbit(true);
    this.viewport.canvas.releasePointerCapture?.(e.pointerId);
    this.viewport.mark('dragging', null);
    const ed = this.editor;
    if (drag.sent) this.live.send({ type: 'preview.end', model: ed.model?.id });
    if (cancelled || !drag.moved || sameBox(drag.box, drag.start)) {
      this.preview.clear();
      this.box = drag.start;
      this.place();
      return;
    }
    const version = await ed.execute(this.tools.resizeOp(drag.node, drag.box));
    if (version === null) {
      // refused: back to what the model is
      this.preview.clear();
      this.sync();
    }
  }

  cancel() {
    const drag = this.drag;
    if (!drag) return;
    this.drag = null;
    clearTimeout(this.sendTimer);
    this.sendTimer = null;
    this.viewport.setOrbit(true);
    this.viewport.mark('dragging', null);
    if (drag.sent) this.live.send({ type: 'preview.end', model: this.editor.model?.id });
    this.preview.clear();
    this.box = drag.start;
    this.place();
  }

  setHover(h) {
    if (h === this.hover) return;
    if (this.hover) this.hover.material.color.set(HANDLE_COLOUR);
    this.hover = h;
    if (h) h.material.color.set(HANDLE_HOVER);
    this.viewport.canvas.style.cursor = h ? 'grab' : '';
    this.viewport.requestRender();
  }

  // Screen position (CSS pixels relative to the canvas) of a face's handle, e.g. 'x+'; for
  // tests and scripted demos.
  screen(face) {
    const h = this.group.children.find((c) => c.userData.face?.name === face);
    return h ? this.viewport.toScreen(h.position) : null;
  }
}

function sameBox(a, b) {
  return a.every((v, i) => Math.abs(v - b[i]) < 1e-9);
}
