// A point cloud model in the view: colours its points by segment or by label (cloud.js), the
// picked segment in the highlight colour, turns a click on a point into that point's segment,
// and a box dragged over the view (with the ROI or template tool on) into a segment_roi or
// mark_template op. The derived points of a proceduralized cloud (derivedpoints.js) are
// coloured by placement ("segment") or terminal ("label"), the selected nodes' in the highlight
// colour, and a click on one selects its placement's node (Shift+click: one more node), as a
// click on a mesh model's component does. It draws only through the viewport's layers and
// listens to signals.
//
// Box drags: the box sent is the model-coordinate bounding box of the drawn points whose
// screen position falls inside the dragged rectangle (for a template, only the picked
// segment's), padded a little: the shown points are float32 copies of the stored ones.
import * as THREE from 'three';
import { isCloud } from './cloud.js';
import { peerSelections } from './peers.js';

const HIGHLIGHT = new THREE.Color(0xffc820); // as the viewport's picked component
const NONE = new THREE.Color(0x8d96a0);      // points in no segment
const POINT_PX = 3;
const BOX_PAD = 0.005; // metres: float32 positions against the stored doubles
const MIN_DRAG_PX = 6;

// Distinct colours for ids: hues a golden angle apart, mid lightness (never the highlight's).
function idColour(id, offset, out) {
  const hue = (offset + id * 0.6180339887) % 1;
  const h = Math.abs(hue - 0.13) < 0.04 ? hue + 0.08 : hue; // keep clear of the yellow
  return out.setHSL(h, 0.55, 0.5);
}

export class CloudView {
  constructor(editor, viewport) {
    this.editor = editor;
    this.viewport = viewport;
    this.cloud = editor.cloud;
    this.boxHelper = null;
    this.drag = null;
    this.rect = document.createElement('div');
    this.rect.className = 'cloud-drag';
    this.rect.dataset.testid = 'cloud-drag';
    this.rect.hidden = true;
    viewport.container.appendChild(this.rect);

    viewport.signals.shown.add(() => this.shown());
    viewport.signals.pointPicked.add((hit) => this.picked(hit));
    const c = this.cloud.signals;
    c.colourChanged.add(() => this.colourize());
    c.segmentChanged.add(() => this.colourize());
    c.toolChanged.add((tool) => this.toolChanged(tool));
    editor.signals.modelOpened.add(() => this.clearBox());
    const recolour = () => {
      if (this.derived) this.colourize();
    };
    editor.signals.selectionChanged.add(recolour);
    editor.signals.peersChanged.add(recolour); // what the others have selected, in their colours

    const el = viewport.canvas;
    el.addEventListener('pointerdown', (e) => this.dragStart(e));
    el.addEventListener('pointermove', (e) => this.dragMove(e));
    el.addEventListener('pointerup', (e) => this.dragEnd(e));
    el.addEventListener('pointercancel', () => this.dragCancel());
  }

  get points() {
    return this.viewport.layers.model.points;
  }

  // The points on screen are a proceduralized cloud's derivation.
  get derived() {
    return !!this.cloud.info?.derived && isCloud(this.editor.model);
  }

  // A points.glb is on screen: our material, its extras as the cloud's info, our colours.
  shown() {
    if (!isCloud(this.editor.model)) {
      this.viewport.mark('points', null);
      this.viewport.mark('pointsOf', null);
      return;
    }
    this.clearBox();
    let info = null;
    let drawn = 0;
    for (const p of this.points) {
      const g = p.geometry;
      // the file's colours (COLOR_0) are kept aside: ours replace them
      if (!g.userData.fileColour && g.getAttribute('color')) g.userData.fileColour = g.getAttribute('color');
      for (const m of [].concat(p.material)) m.dispose();
      p.material = new THREE.PointsMaterial({ size: POINT_PX, sizeAttenuation: false, vertexColors: true });
      drawn += g.getAttribute('position').count;
      if (!info) p.traverseAncestors((a) => { if (!info && typeof a.userData?.shown === 'number') info = a.userData; });
      if (typeof p.userData?.shown === 'number') info = p.userData;
    }
    this.cloud.setInfo(info ? { ...info, drawn } : { drawn });
    this.viewport.mark('points', drawn); // how many points are drawn
    this.viewport.mark('pointsOf', info?.derived ? 'derived' : 'input'); // and which
    this.colourize();
  }

  // Segment or label colours once segmented; before that the file's colours, or by height.
  colourize() {
    if (!isCloud(this.editor.model)) return;
    const mode = this.cloud.colourBy;
    const derived = this.derived;
    const picked = derived ? null : this.cloud.segment;
    // a derived cloud's placements are the components the selected nodes cover
    const lit = derived ? new Set(this.editor.selected.components()) : null;
    const theirs = derived ? this.peerSelections() : null;
    const c = new THREE.Color();
    for (const p of this.points) {
      const g = p.geometry;
      const n = g.getAttribute('position').count;
      const seg = g.getAttribute('_segment');
      const ids = mode === 'label' ? g.getAttribute('_label') : seg;
      const rgb = new Float32Array(3 * n);
      const file = g.userData.fileColour;
      g.computeBoundingBox();
      const { min, max } = g.boundingBox;
      const span = Math.max(max.y - min.y, 1e-6);
      for (let i = 0; i < n; i++) {
        if (seg && ((picked !== null && seg.getX(i) === picked) || lit?.has(seg.getX(i)))) c.copy(HIGHLIGHT);
        else if (seg && theirs?.has(seg.getX(i))) c.copy(theirs.get(seg.getX(i)));
        else if (ids) {
          const id = ids.getX(i);
          if (id < 0) c.copy(NONE);
          else idColour(id, mode === 'label' ? 0.37 : 0.02, c);
        } else if (file) c.setRGB(file.getX(i), file.getY(i), file.getZ(i));
        else c.setHSL(0.6 - 0.5 * ((g.getAttribute('position').getY(i) - min.y) / span), 0.5, 0.5);
        rgb[3 * i] = c.r;
        rgb[3 * i + 1] = c.g;
        rgb[3 * i + 2] = c.b;
      }
      g.setAttribute('color', new THREE.BufferAttribute(rgb, 3));
    }
    this.viewport.mark('colourBy', mode);
    this.viewport.mark('segment', picked);
    this.viewport.mark('litPlacements', lit ? lit.size : null);
    this.viewport.requestRender();
  }

  // Placement -> the colour of the first other person who has it selected.
  peerSelections() {
    const out = new Map([...peerSelections(this.editor.peers)].map(([c, hex]) => [c, new THREE.Color(hex)]));
    this.viewport.mark('peerPlacements', out.size || null);
    return out;
  }

  // A click on a point picks its segment; a click beside the points drops the pick.
  picked(hit) {
    if (this.derived) {
      this.pickedDerived(hit);
      return;
    }
    const seg = hit?.points.geometry.getAttribute('_segment');
    if (hit && !seg) this.editor.notify('The cloud is not segmented yet: segment it to pick segments');
    const id = seg ? seg.getX(hit.index) : -1;
    this.cloud.setSegment(id >= 0 ? id : null);
  }

  // A derived point stands for its placement: its node is selected (Shift: added or taken out).
  pickedDerived(hit) {
    const selected = this.editor.selected;
    const component = hit?.points.userData.component;
    if (typeof component !== 'number') {
      if (!hit?.extend) selected.clear();
      return;
    }
    const node = this.editor.tree?.nodeOfComponent(component) ?? null;
    if (hit.extend && node !== null) selected.toggle(node);
    else selected.set({ component, group: null });
  }

  // --- box drags ------------------------------------------------------------------------------
  toolChanged(tool) {
    this.viewport.setOrbit(!tool); // the drag draws a box instead of orbiting
    this.viewport.mark('cloudTool', tool);
    if (!tool) this.dragCancel();
  }

  local(e) {
    const r = this.viewport.canvas.getBoundingClientRect();
    return { x: e.clientX - r.left, y: e.clientY - r.top };
  }

  dragStart(e) {
    if (!this.cloud.tool || e.button !== 0 || !this.points.length) return;
    this.drag = { from: this.local(e), to: this.local(e) };
    this.viewport.canvas.setPointerCapture?.(e.pointerId);
    this.drawRect();
  }

  dragMove(e) {
    if (!this.drag) return;
    this.drag.to = this.local(e);
    this.drawRect();
  }

  dragCancel() {
    this.drag = null;
    this.rect.hidden = true;
  }

  drawRect() {
    const { from, to } = this.drag;
    Object.assign(this.rect.style, {
      left: `${Math.min(from.x, to.x)}px`,
      top: `${Math.min(from.y, to.y)}px`,
      width: `${Math.abs(to.x - from.x)}px`,
      height: `${Math.abs(to.y - from.y)}px`,
    });
    this.rect.hidden = false;
  }

  async dragEnd(e) {
    if (!this.drag) return;
    this.drag.to = this.local(e);
    const { from, to } = this.drag;
    const tool = this.cloud.tool;
    this.dragCancel();
    if (Math.abs(to.x - from.x) < MIN_DRAG_PX || Math.abs(to.y - from.y) < MIN_DRAG_PX) return;
    const only = tool === 'template' ? this.cloud.segment : null;
    if (tool === 'template' && only === null) {
      this.editor.fail({ title: 'No segment picked', detail: 'click a point of the segment the template is in first' });
      return;
    }
    // a template for proceduralize is what the person sees in the rectangle: the points
    // behind it (the far wall through a window) stay out
    const box = this.boxUnder(from, to, only, tool === 'procTemplate');
    if (!box) {
      this.editor.fail({ title: 'No points in the box', detail: only === null ? 'drag over the points' : `drag over points of segment ${only}` });
      return;
    }
    this.cloud.setTool(null);
    this.showBox(box);
    if (tool === 'roi') await this.cloud.segmentRoi(box);
    else if (tool === 'procTemplate') this.cloud.addProcTemplate(box);
    else await this.cloud.markTemplate(box);
  }

  // The padded model-coordinate box of the drawn points inside the screen rectangle (of
  // segment `only` when given; with `front`, only those within the rectangle's size behind the
  // nearest of them), or null when none is.
  boxUnder(a, b, only, front = false) {
    const vp = this.viewport;
    const w = vp.canvas.clientWidth, h = vp.canvas.clientHeight;
    const x0 = Math.min(a.x, b.x), x1 = Math.max(a.x, b.x), y0 = Math.min(a.y, b.y), y1 = Math.max(a.y, b.y);
    vp.camera.updateMatrixWorld();
    const v = new THREE.Vector3(), s = new THREE.Vector3();
    const inside = []; // [x, y, z, distance to the camera] per point in the rectangle
    for (const p of this.points) {
      p.updateWorldMatrix(true, false);
      const pos = p.geometry.getAttribute('position');
      const seg = p.geometry.getAttribute('_segment');
      if (only !== null && !seg) continue;
      for (let i = 0; i < pos.count; i++) {
        if (only !== null && seg.getX(i) !== only) continue;
        v.fromBufferAttribute(pos, i).applyMatrix4(p.matrixWorld);
        s.copy(v).project(vp.camera);
        if (s.z < -1 || s.z > 1) continue; // behind the camera or past its far plane
        const sx = ((s.x + 1) / 2) * w, sy = ((1 - s.y) / 2) * h;
        if (sx < x0 || sx > x1 || sy < y0 || sy > y1) continue;
        // glTF is y-up: archgram's (x, y, z) is (x, -z, y) of the scene
        inside.push([v.x, -v.z, v.y, front ? v.distanceTo(vp.camera.position) : 0]);
      }
    }
    if (!inside.length) return null;
    let reach = Infinity;
    if (front) {
      let near = Infinity;
      for (const q of inside) near = Math.min(near, q[3]);
      const px = Math.max(x1 - x0, y1 - y0);
      reach = near + px * (2 * near * Math.tan(THREE.MathUtils.degToRad(vp.camera.fov) / 2)) / (h || 1);
    }
    const lo = [Infinity, Infinity, Infinity], hi = [-Infinity, -Infinity, -Infinity];
    for (const q of inside) {
      if (q[3] > reach) continue;
      for (let k = 0; k < 3; k++) {
        lo[k] = Math.min(lo[k], q[k]);
        hi[k] = Math.max(hi[k], q[k]);
      }
    }
    return [...lo.map((x) => x - BOX_PAD), ...hi.map((x) => x + BOX_PAD)];
  }

  // The box sent, drawn until the points are loaded again.
  showBox(box) {
    this.clearBox();
    const b = new THREE.Box3(new THREE.Vector3(box[0], box[2], -box[4]), new THREE.Vector3(box[3], box[5], -box[1]));
    this.boxHelper = this.viewport.layers.handles.add(new THREE.Box3Helper(b, HIGHLIGHT));
  }

  clearBox() {
    if (this.boxHelper) this.viewport.layers.handles.remove(this.boxHelper);
    this.boxHelper = null;
  }
}
