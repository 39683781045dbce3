// The 2D plan editor of the edited building: its loops (outer rings and holes) drawn in an
// SVG, corners dragged (previewed live in 3D, committed as a plan op on release), a corner
// inserted by double-clicking an edge, the selected corner removed with Delete, a profile
// assigned to the clicked edge, anchors shown and added on an edge, steps (natural and
// forced) placed on an edge and drawn, and the edges an offset event leaves out picked. The
// step tool's settings and the list of steps and offset events are planfeatures.js.
import { el } from './dom.js';
import { anchorSpot, clone, makeStep, mergeEdges, offsetEdge, round3, shiftEdges, stepKind, stepOutline, toggleOffsetEdge } from './plandoc.js';

const SVG = 'http://www.w3.org/2000/svg';
const MARGIN = 22;   // px around the plan
const CLICK_SLOP = 3; // px a press may move and still be a click
export const PROFILE_COLOURS = ['#3d85c6', '#e07b39', '#58b27a', '#b565c9', '#d4b13a', '#4fb3b3', '#e0585b', '#8f9aa8'];

export function svg(tag, attrs = {}) {
  const n = document.createElementNS(SVG, tag);
  for (const [k, v] of Object.entries(attrs)) if (v !== undefined && v !== null) n.setAttribute(k, String(v));
  return n;
}

// Colour of each profile name of a description, in the order they are declared.
export function profileColours(plan) {
  const m = new Map();
  Object.keys(plan?.profiles || {}).forEach((name, i) => m.set(name, PROFILE_COLOURS[i % PROFILE_COLOURS.length]));
  return m;
}

// What a click on an edge does: select it, or place an anchor or a step there, or take it
// out of the selected offset event (or put it back).
const TOOLS = {
  anchor: 'Click an edge to place an anchor there',
  step: 'Click an edge to place a step there',
  offset: 'Click edges to leave them out of the selected offset event (again: back in)',
};

export class PlanEditor {
  constructor(editor, container) {
    this.editor = editor;
    this.ext = editor.extrusion;
    const ext = this.ext;
    this.sel = null;        // {kind: 'corner'|'edge', loop, index}
    this.drag = null;
    this.frame = null;      // plan → screen mapping, kept while dragging

    this.title = el('span.plan-title', { 'data-testid': 'plan-title' });
    this.status = el('span.plan-status', { 'data-testid': 'plan-status' });
    this.profileSel = el('select.plan-profile', { 'data-testid': 'edge-profile', title: 'Profile of the selected edge', disabled: true });
    this.profileSel.addEventListener('change', () => this.assignProfile(this.profileSel.value));
    this.delBtn = el('button', { type: 'button', 'data-testid': 'delete-corner', disabled: true, title: 'Remove the selected corner (Delete)' }, 'Delete corner');
    this.delBtn.addEventListener('click', () => this.deleteCorner());
    this.anchorBtn = el('button', { type: 'button', 'data-testid': 'anchor-mode', title: TOOLS.anchor }, 'Add anchor');
    this.anchorBtn.addEventListener('click', () => ext.setTool('anchor'));
    this.anchorHeight = el('input.num', { type: 'number', step: '0.1', min: '0', value: '1', 'data-testid': 'anchor-height', title: 'Anchor height (m)' });
    this.anchorKind = el(
      'select',
      { 'data-testid': 'anchor-kind', title: 'Relative: a fraction of the edge as it is at that height; absolute: metres from the first corner' },
      el('option', { value: 'relative' }, 'relative'),
      el('option', { value: 'absolute' }, 'absolute'),
    );
    this.svg = svg('svg', { class: 'plan-svg', 'data-testid': 'plan-editor', tabindex: 0 });
    this.svg.addEventListener('keydown', (e) => {
      if ((e.key === 'Delete' || e.key === 'Backspace') && this.sel?.kind === 'corner') {
        e.preventDefault();
        this.deleteCorner();
      } else if (e.key === 'Escape') {
        if (ext.tool) ext.setTool(ext.tool);
        else this.select(null);
      }
    });
    this.svg.addEventListener('pointerdown', (e) => {
      if (e.target === this.svg) this.select(null);
    });
    this.hint = el('div.plan-hint');
    container.append(
      el('div.pane-bar', {}, this.title, this.status),
      el('div.pane-bar.tools', {},
        el('label', {}, 'edge ', this.profileSel),
        this.delBtn,
        this.anchorBtn,
        el('label', {}, 'at ', this.anchorHeight, ' m'),
        this.anchorKind),
      el('div.plan-box', {}, this.svg, this.hint),
    );

    new ResizeObserver(() => {
      if (!this.drag) {
        this.frame = null;
        this.render();
      }
    }).observe(this.svg);
    const s = ext.signals;
    // The drawer holding both editors is shown for extrusion models only.
    const drawer = container.closest('section');
    s.docChanged.add(() => {
      if (drawer) drawer.hidden = !ext.active || !ext.doc;
    });
    s.buildingChanged.add((b) => {
      // A reload of the same building (after an op) keeps what is selected.
      if (b?.index !== this.shown) this.sel = null;
      this.shown = b?.index;
      this.frame = null;
      this.render();
    });
    s.draftChanged.add(() => {
      if (!this.drag) this.frame = null;
      this.render();
    });
    s.previewChanged.add((p) => this.renderStatus(p));
    s.toolChanged.add(() => this.render());
    s.featureChanged.add(() => this.render());
    this.render();
  }

  get plan() {
    return this.ext.draft;
  }

  // A changed draft, shown at once and committed as a plan op.
  commit(draft) {
    this.ext.commitPlan(draft);
  }

  // --- plan ↔ screen ------------------------------------------------------------------------
  // Fits the loops and the steps' outlines.
  fit() {
    const plan = this.plan;
    const w = Math.max(40, this.svg.clientWidth);
    const h = Math.max(40, this.svg.clientHeight);
    let x0 = Infinity;
    let y0 = Infinity;
    let x1 = -Infinity;
    let y1 = -Infinity;
    const outlines = (plan.steps || []).map((st) => stepOutline(plan, st)).filter(Boolean);
    for (const pts of [...plan.loops.map((l) => l.points), ...outlines]) {
      for (const [x, y] of pts) {
        x0 = Math.min(x0, x);
        y0 = Math.min(y0, y);
        x1 = Math.max(x1, x);
        y1 = Math.max(y1, y);
      }
    }
    if (!(x1 >= x0)) [x0, y0, x1, y1] = [0, 0, 1, 1];
    const dx = Math.max(x1 - x0, 1e-6);
    const dy = Math.max(y1 - y0, 1e-6);
    const s = Math.min((w - 2 * MARGIN) / dx, (h - 2 * MARGIN) / dy);
    const ox = (w - s * dx) / 2;
    const oy = (h - s * dy) / 2;
    return {
      w,
      h,
      s,
      toScreen: (x, y) => [ox + (x - x0) * s, h - oy - (y - y0) * s],
      toPlan: (sx, sy) => [x0 + (sx - ox) / s, y0 + (h - oy - sy) / s],
    };
  }

  eventPoint(e) {
    const r = this.svg.getBoundingClientRect();
    return this.frame.toPlan(e.clientX - r.left, e.clientY - r.top);
  }

  // --- drawing --------------------------------------------------------------------------------
  render() {
    const ext = this.ext;
    const plan = this.plan;
    const b = ext.building;
    const tool = ext.tool;
    this.svg.replaceChildren();
    this.anchorBtn.classList.toggle('on', tool === 'anchor');
    this.svg.classList.toggle('anchoring', tool !== null);
    this.svg.dataset.tool = tool ?? '';
    if (!plan) {
      this.hint.classList.remove('tool');
      this.title.textContent = b ? `${b.id}` : '';
      this.hint.textContent = !ext.active
        ? ''
        : b
          ? 'This footprint has no building description.'
          : 'Click a building in the 3D view (or a footprint in the city report) to edit its plan.';
      this.hint.hidden = false;
      this.profileSel.disabled = true;
      this.delBtn.disabled = true;
      return;
    }
    this.hint.hidden = !tool;
    this.hint.classList.toggle('tool', !!tool);
    this.hint.textContent = tool ? TOOLS[tool] : '';
    if (this.sel && !(this.sel.index < (plan.loops[this.sel.loop]?.points.length ?? 0))) this.sel = null; // gone
    const state = b?.status && b.status !== 'ok' ? ` · ${b.status}` : '';
    this.title.textContent = `${ext.batch ? `building ${b?.id ?? ext.current}` : 'plan'}${state}`;
    this.title.title = b?.reason || '';
    if (!this.frame) this.frame = this.fit();
    const f = this.frame;
    this.svg.setAttribute('viewBox', `0 0 ${f.w} ${f.h}`);
    const colours = profileColours(plan);
    const path = (pts) => pts.map(([x, y], i) => `${i ? 'L' : 'M'}${f.toScreen(x, y).map((v) => v.toFixed(1)).join(',')}`).join('') + 'Z';

    // Area: all loops in one path, holes cut out by the even-odd rule.
    this.svg.append(svg('path', { d: plan.loops.map((l) => path(l.points)).join(''), class: 'plan-area', 'fill-rule': 'evenodd' }));

    // Steps under the edges, so edges stay clickable where a step overlaps them.
    const feature = ext.feature;
    (plan.steps || []).forEach((st, i) => {
      const outline = stepOutline(plan, st);
      if (!outline) return;
      const on = feature?.kind === 'step' && feature.index === i;
      const g = svg('path', {
        d: path(outline),
        class: `plan-step ${stepKind(st)}${on ? ' selected' : ''}`,
        stroke: colours.get(st.profile) || '#888',
        'data-testid': 'plan-step',
        'data-index': i,
        'data-kind': stepKind(st),
      });
      const t = svg('title');
      t.textContent = `${stepKind(st)} step ${st.name ?? i} · ${st.height} m · ${st.profile}`;
      g.append(t);
      g.addEventListener('pointerdown', (e) => {
        if (e.button !== 0 || ext.tool) return;
        e.stopPropagation();
        ext.selectFeature({ kind: 'step', index: i });
      });
      this.svg.append(g);
    });

    const offset = feature?.kind === 'offset' ? plan.offsets?.[feature.index] : null;
    plan.loops.forEach((l, li) => {
      const n = l.points.length;
      for (let i = 0; i < n; i++) {
        const [ax, ay] = f.toScreen(...l.points[i]);
        const [bx, by] = f.toScreen(...l.points[(i + 1) % n]);
        const selected = this.sel?.kind === 'edge' && this.sel.loop === li && this.sel.index === i;
        const left = offsetEdge(offset, li, i)?.disabled === true;
        const g = svg('g', {
          class: `plan-edge${selected ? ' selected' : ''}${left ? ' offset-off' : ''}`,
          'data-testid': 'plan-edge',
          'data-loop': li,
          'data-edge': i,
          'data-profile': l.profiles[i],
        });
        if (offset) g.dataset.offset = left ? 'disabled' : 'moves';
        g.append(
          svg('line', { x1: ax, y1: ay, x2: bx, y2: by, class: 'edge-line', stroke: colours.get(l.profiles[i]) || '#888' }),
          svg('line', { x1: ax, y1: ay, x2: bx, y2: by, class: 'edge-hit' }),
        );
        const title = svg('title');
        title.textContent = `edge ${i}${plan.loops.length > 1 ? ` of loop ${li}` : ''} · ${l.profiles[i]}${offset ? (left ? ' · left out of the offset' : ' · offset') : ''}`;
        g.append(title);
        g.addEventListener('pointerdown', (e) => this.edgeDown(e, li, i));
        g.addEventListener('dblclick', (e) => this.insertCorner(e, li, i));
        this.svg.append(g);
      }
    });

    for (const [ai, a] of (plan.anchors || []).entries()) {
      const spot = anchorSpot(plan, a);
      if (!spot) continue;
      const [x, y] = f.toScreen(spot.x, spot.y);
      const m = svg('rect', {
        x: x - 5, y: y - 5, width: 10, height: 10, class: 'plan-anchor', 'data-testid': 'plan-anchor', 'data-index': ai,
        transform: `rotate(45 ${x} ${y})`,
      });
      const t = svg('title');
      const where = typeof a.relative === 'number' ? `${Math.round(a.relative * 100)}% of edge ${a.edge}` : `${a.absolute} m along edge ${a.edge}`;
      t.textContent = `anchor ${a.name ?? ai} · ${where} · height ${a.height} m`;
      m.append(t);
      m.addEventListener('pointerdown', (e) => this.edgeDown(e, a.loop ?? 0, a.edge)); // as if on its edge
      this.svg.append(m);
    }

    plan.loops.forEach((l, li) => {
      l.points.forEach(([px, py], i) => {
        const [x, y] = f.toScreen(px, py);
        const selected = this.sel?.kind === 'corner' && this.sel.loop === li && this.sel.index === i;
        const c = svg('circle', {
          cx: x, cy: y, r: selected ? 7 : 5.5,
          class: `plan-corner${selected ? ' selected' : ''}`,
          'data-testid': 'plan-corner',
          'data-loop': li,
          'data-index': i,
        });
        c.addEventListener('pointerdown', (e) => this.cornerDown(e, li, i));
        this.svg.append(c);
      });
    });
    this.renderTools();
  }

  renderTools() {
    const plan = this.plan;
    const edge = this.sel?.kind === 'edge' ? this.sel : null;
    this.profileSel.disabled = !edge;
    const names = Object.keys(plan?.profiles || {});
    const current = edge ? plan.loops[edge.loop].profiles[edge.index] : '';
    this.profileSel.replaceChildren(
      el('option', { value: '', disabled: true }, edge ? '' : '—'),
      ...names.map((n) => el('option', { value: n }, n)),
    );
    this.profileSel.value = current || '';
    const loop = this.sel?.kind === 'corner' ? plan.loops[this.sel.loop] : null;
    this.delBtn.disabled = !loop || loop.points.length <= 3;
  }

  renderStatus(p) {
    this.status.className = 'plan-status';
    if (!p) {
      this.status.textContent = '';
    } else if (p.state === 'busy') {
      this.status.textContent = 'previewing…';
    } else if (p.state === 'ok') {
      this.status.textContent = `preview ${this.ext.previews}`;
      this.status.classList.add('ok');
    } else {
      this.status.textContent = p.problem?.detail || p.problem?.title || 'invalid';
      this.status.classList.add('bad');
    }
    this.status.dataset.state = p?.state ?? '';
  }

  // Selection only restyles what is drawn: the pressed element stays (a double-click needs it).
  select(sel) {
    this.sel = sel;
    if (!this.plan) return;
    for (const g of this.svg.querySelectorAll('.plan-edge')) {
      g.classList.toggle('selected', sel?.kind === 'edge' && sel.loop === Number(g.dataset.loop) && sel.index === Number(g.dataset.edge));
    }
    for (const c of this.svg.querySelectorAll('.plan-corner')) {
      const on = sel?.kind === 'corner' && sel.loop === Number(c.dataset.loop) && sel.index === Number(c.dataset.index);
      c.classList.toggle('selected', on);
      c.setAttribute('r', on ? 7 : 5.5);
    }
    this.renderTools();
  }

  // --- corners ------------------------------------------------------------------------------
  cornerDown(e, loop, index) {
    if (e.button !== 0) return;
    e.preventDefault();
    e.stopPropagation();
    this.svg.focus({ preventScroll: true });
    this.select({ kind: 'corner', loop, index });
    if (!this.editor.canEdit) return; // viewers look at corners, they do not drag them
    const target = this.svg; // the pressed element is redrawn; the svg keeps the capture
    target.setPointerCapture?.(e.pointerId);
    const start = { x: e.clientX, y: e.clientY };
    const base = clone(this.plan);
    let moved = false;
    this.drag = { loop, index };
    const move = (ev) => {
      if (!moved && Math.hypot(ev.clientX - start.x, ev.clientY - start.y) <= CLICK_SLOP) return;
      moved = true;
      const draft = clone(base);
      draft.loops[loop].points[index] = this.eventPoint(ev).map(round3);
      this.ext.edit(draft);
    };
    const up = () => {
      target.removeEventListener('pointermove', move);
      target.removeEventListener('pointerup', up);
      target.removeEventListener('pointercancel', up);
      this.drag = null;
      if (moved) this.ext.commitPlan();
    };
    target.addEventListener('pointermove', move);
    target.addEventListener('pointerup', up);
    target.addEventListener('pointercancel', up);
  }

  deleteCorner() {
    const sel = this.sel;
    if (sel?.kind !== 'corner') return;
    const draft = clone(this.plan);
    const l = draft.loops[sel.loop];
    if (l.points.length <= 3) {
      this.editor.fail({ title: 'Cannot remove the corner', detail: 'a loop needs at least three corners' });
      return;
    }
    // Edges index-1 and index merge into one that keeps the earlier edge's profile.
    l.points.splice(sel.index, 1);
    l.profiles.splice(sel.index, 1);
    const n = l.points.length;
    mergeEdges(draft, sel.loop, sel.index, Math.min((sel.index - 1 + n + 1) % (n + 1), n - 1));
    this.sel = null;
    this.commit(draft);
  }

  // --- edges --------------------------------------------------------------------------------
  edgeDown(e, loop, index) {
    if (e.button !== 0) return;
    e.stopPropagation();
    this.svg.focus({ preventScroll: true });
    const tool = this.editor.canEdit ? this.ext.tool : null;
    if (tool === 'anchor') this.addAnchor(e, loop, index);
    else if (tool === 'step') this.addStep(e, loop, index);
    else if (tool === 'offset') this.toggleOffset(loop, index);
    else this.select({ kind: 'edge', loop, index });
  }

  // The click's foot on edge i of loop l, as a fraction of the edge.
  footOn(e, loop, index) {
    const l = this.plan.loops[loop];
    const p = l.points[index];
    const q = l.points[(index + 1) % l.points.length];
    const [x, y] = this.eventPoint(e);
    const dx = q[0] - p[0];
    const dy = q[1] - p[1];
    const len2 = dx * dx + dy * dy || 1;
    const t = Math.min(1, Math.max(0, ((x - p[0]) * dx + (y - p[1]) * dy) / len2));
    return { t, x: p[0] + dx * t, y: p[1] + dy * t, len: Math.sqrt(len2) };
  }

  insertCorner(e, loop, index) {
    e.preventDefault();
    e.stopPropagation();
    if (this.ext.tool || !this.editor.canEdit) return; // the clicks were for the tool
    const foot = this.footOn(e, loop, index);
    if (foot.t < 0.02 || foot.t > 0.98) return; // on a corner: nothing to insert
    const draft = clone(this.plan);
    const l = draft.loops[loop];
    l.points.splice(index + 1, 0, [round3(foot.x), round3(foot.y)]);
    l.profiles.splice(index + 1, 0, l.profiles[index]); // both halves keep the edge's profile
    shiftEdges(draft, loop, index, 1);
    this.sel = { kind: 'corner', loop, index: index + 1 };
    this.commit(draft);
  }

  assignProfile(name) {
    const sel = this.sel;
    if (sel?.kind !== 'edge' || !name) return;
    const draft = clone(this.plan);
    if (draft.loops[sel.loop].profiles[sel.index] === name) return;
    draft.loops[sel.loop].profiles[sel.index] = name;
    this.commit(draft);
  }

  addAnchor(e, loop, index) {
    const foot = this.footOn(e, loop, index);
    const height = Math.max(0, Number(this.anchorHeight.value) || 0);
    const draft = clone(this.plan);
    const a = { name: `anchor${(draft.anchors?.length ?? 0) + 1}`, loop, edge: index, height };
    if (this.anchorKind.value === 'absolute') a.absolute = round3(foot.t * foot.len);
    else a.relative = round3(foot.t);
    draft.anchors = [...(draft.anchors || []), a];
    this.ext.setTool(null);
    this.commit(draft);
  }

  // A step (the step tool's kind and sizes) at the clicked point of the edge.
  addStep(e, loop, index) {
    const ext = this.ext;
    const params = ext.stepTool;
    const bad = stepProblem(params, this.plan);
    if (bad) {
      this.editor.fail({ title: 'Cannot place the step', detail: bad });
      return;
    }
    const foot = this.footOn(e, loop, index);
    const draft = clone(this.plan);
    const i = draft.steps?.length ?? 0;
    const step = makeStep(params.kind, { ...params, loop, edge: index, relative: foot.t, name: `${params.kind === 'forced' ? 'forced' : 'step'}${i + 1}` });
    draft.steps = [...(draft.steps || []), step];
    ext.setTool(null);
    ext.setDraft(draft);
    ext.selectFeature({ kind: 'step', index: i });
    this.commit(draft);
  }

  // The clicked edge out of (or back into) the selected offset event.
  toggleOffset(loop, index) {
    const f = this.ext.feature;
    if (f?.kind !== 'offset' || !this.plan.offsets?.[f.index]) return;
    this.commit(toggleOffsetEdge(this.plan, f.index, loop, index));
  }
}

// Why the step tool cannot place a step on this plan, or null.
function stepProblem({ height, width, depth, profile }, plan) {
  if (!(height > 0)) return 'its height must be more than 0 m';
  if (!(width >= 0.002)) return 'its width must be at least 2 mm';
  if (!(Math.abs(depth) >= 0.002)) return 'its depth must be at least 2 mm either way';
  if (!plan?.profiles?.[profile]) return 'choose the profile of its new edges';
  return null;
}
