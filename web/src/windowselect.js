// Select-by-window (paper §4.1): while the tool is on, dragging a rectangle over the viewport
// selects the visible nodes whose boxes it covers — all eight corners in front of the camera
// and inside the rectangle, as server/core/parts/select.h defines it. The drag neither orbits
// nor picks; Escape abandons it.
import * as THREE from 'three';
import { worldBox } from './previewlayer.js';
import { Signal } from './signal.js';

const MIN_PX = 4; // a smaller rectangle is a click

export class WindowSelect {
  constructor(editor, viewport) {
    this.editor = editor;
    this.viewport = viewport;
    this.active = false;
    this.drag = null; // {x0, y0, x1, y1} in CSS pixels of the canvas
    this.changed = new Signal(); // active
    this.rect = document.createElement('div');
    this.rect.className = 'select-window';
    this.rect.dataset.testid = 'select-window';
    this.rect.hidden = true;
    viewport.container.appendChild(this.rect);

    const c = viewport.canvas;
    // Capture phase: the press must reach neither the orbit controls nor picking.
    c.addEventListener('pointerdown', (e) => this.down(e), { capture: true });
    c.addEventListener('pointermove', (e) => this.move(e), { capture: true });
    c.addEventListener('pointerup', (e) => this.up(e), { capture: true });
    c.addEventListener('pointercancel', () => this.cancel(), { capture: true });
    window.addEventListener('keydown', (e) => {
      if (e.key === 'Escape' && this.drag) this.cancel();
    });
  }

  setActive(on) {
    this.active = !!on;
    if (!this.active) this.cancel();
    this.viewport.mark('windowSelect', this.active ? 'on' : null);
    this.changed.dispatch(this.active);
  }

  local(e) {
    const r = this.viewport.canvas.getBoundingClientRect();
    return { x: e.clientX - r.left, y: e.clientY - r.top };
  }

  down(e) {
    if (!this.active || e.button !== 0 || !this.editor.tree) return;
    e.stopImmediatePropagation();
    e.preventDefault();
    const p = this.local(e);
    this.drag = { x0: p.x, y0: p.y, x1: p.x, y1: p.y };
    this.viewport.canvas.setPointerCapture?.(e.pointerId);
    this.draw();
  }

  move(e) {
    if (!this.drag) return;
    e.stopImmediatePropagation();
    const p = this.local(e);
    this.drag.x1 = p.x;
    this.drag.y1 = p.y;
    this.draw();
  }

  up(e) {
    if (!this.drag) return;
    e.stopImmediatePropagation();
    const d = this.drag;
    this.cancel();
    if (Math.abs(d.x1 - d.x0) < MIN_PX || Math.abs(d.y1 - d.y0) < MIN_PX) return;
    const nodes = this.nodesIn(Math.min(d.x0, d.x1), Math.min(d.y0, d.y1), Math.max(d.x0, d.x1), Math.max(d.y0, d.y1));
    if (nodes.length) this.editor.selected.nodes(nodes);
    else this.editor.selected.clear();
  }

  cancel() {
    this.drag = null;
    this.rect.hidden = true;
  }

  draw() {
    const d = this.drag;
    const r = this.rect;
    r.hidden = false;
    r.style.left = `${Math.min(d.x0, d.x1)}px`;
    r.style.top = `${Math.min(d.y0, d.y1)}px`;
    r.style.width = `${Math.abs(d.x1 - d.x0)}px`;
    r.style.height = `${Math.abs(d.y1 - d.y0)}px`;
  }

  // The visible nodes whose boxes lie inside [x0, x1] × [y0, y1] (CSS pixels of the canvas).
  nodesIn(x0, y0, x1, y1) {
    const tree = this.editor.tree;
    if (!tree) return [];
    const cam = this.viewport.camera;
    cam.updateMatrixWorld();
    const w = this.viewport.canvas.clientWidth || 1;
    const h = this.viewport.canvas.clientHeight || 1;
    const out = [];
    const v = new THREE.Vector3();
    for (const n of tree.nodes.values()) {
      if (!n.visible || !Array.isArray(n.box) || n.box.length !== 6) continue;
      const b = worldBox(n.box);
      let inside = true;
      for (let k = 0; k < 8 && inside; k++) {
        v.set(k & 1 ? b.max.x : b.min.x, k & 2 ? b.max.y : b.min.y, k & 4 ? b.max.z : b.min.z).project(cam);
        const sx = ((v.x + 1) / 2) * w;
        const sy = ((1 - v.y) / 2) * h;
        inside = v.z > -1 && v.z < 1 && sx >= x0 && sx <= x1 && sy >= y0 && sy <= y1;
      }
      if (inside) out.push(n.id);
    }
    return out;
  }
}
