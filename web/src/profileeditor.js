// The profile editor: the edited building's profiles as polylines in (offset w, height z),
// w growing towards the inside of the plan. The chosen profile's points are dragged
// (previewed live, committed on release), inserted by double-clicking a segment, removed
// with Delete; "Insert overhang" adds the same outward horizontal segment at one height to
// every profile of the building, so the eave stays level all round. Priority tags decide
// which plane carries on where collinear neighbours with different slopes meet: the
// profile's, and the clicked segment's (empty: the profile's). The rule for equal tags
// belongs to the plan (planfeatures.js).
import { el } from './dom.js';
import { clone, profilePoints, segmentPriority, withPoints, withPriority, withSegmentPriority } from './plandoc.js';
import { profileColours, svg } from './planeditor.js';

const MARGIN = 24;
const CLICK_SLOP = 3;
const round = (v) => Math.round(v * 1000) / 1000;

// The profile with an outward horizontal segment of `width` at height h: the polyline is cut
// at h (extending its last segment upwards if it ends lower), the rest moves out by width.
export function withOverhang(points, h, width) {
  const pts = points.map((p) => p.slice());
  const n = pts.length;
  let at = -1; // index of the point at height h once inserted
  for (let i = 0; i < n; i++) {
    if (Math.abs(pts[i][1] - h) < 1e-9) {
      at = i;
      break;
    }
    if (i + 1 < n && pts[i][1] < h && pts[i + 1][1] > h) {
      const t = (h - pts[i][1]) / (pts[i + 1][1] - pts[i][1]);
      pts.splice(i + 1, 0, [round(pts[i][0] + (pts[i + 1][0] - pts[i][0]) * t), h]);
      at = i + 1;
      break;
    }
  }
  if (at < 0) {
    // Above the last point: the last segment carries on upwards (a vertical wall if flat).
    const [ax, az] = pts[n - 2] || [0, 0];
    const [bx, bz] = pts[n - 1];
    const slope = bz > az ? (bx - ax) / (bz - az) : 0;
    pts.push([round(bx + slope * (h - bz)), h]);
    at = pts.length - 1;
  }
  // A horizontal segment may not start right after another one.
  if (at > 0 && Math.abs(pts[at - 1][1] - h) < 1e-9) return null;
  const out = pts.slice(0, at + 1);
  out.push([round(pts[at][0] - width), h]);
  const rest = pts.slice(at + 1).map(([w, z]) => [round(w - width), z]);
  if (!rest.length) {
    // The horizontal segment may not be the last: carry on with the slope below it.
    const [ax, az] = pts[at - 1] || [0, 0];
    const slope = h > az ? (pts[at][0] - ax) / (h - az) : 0;
    rest.push([round(pts[at][0] - width + slope), h + 1]);
  }
  return out.concat(rest);
}

export class ProfileEditor {
  constructor(editor, container) {
    this.editor = editor;
    this.ext = editor.extrusion;
    const ext = this.ext;
    this.name = null;   // the chosen profile
    this.sel = null;    // index of the selected point
    this.seg = null;    // index of the selected segment (its priority tag is edited)
    this.frame = null;
    this.drag = null;

    this.choose = el('select', { 'data-testid': 'profile-select', title: 'Profile to edit' });
    this.choose.addEventListener('change', () => {
      this.name = this.choose.value;
      this.sel = null;
      this.seg = null;
      this.render();
    });
    this.everywhere = el('input', { type: 'checkbox', 'data-testid': 'profile-everywhere' });
    this.everyLabel = el('label.every', { title: 'Replace this profile in every building of the model that has it' }, this.everywhere, ' all buildings');
    this.addBtn = el('button', { type: 'button', 'data-testid': 'profile-add', title: 'Add a point above the last one' }, '+ point');
    this.addBtn.addEventListener('click', () => this.appendPoint());
    this.delBtn = el('button', { type: 'button', 'data-testid': 'profile-delete', disabled: true, title: 'Remove the selected point (Delete)' }, '− point');
    this.delBtn.addEventListener('click', () => this.deletePoint());
    this.ohWidth = el('input.num', { type: 'number', step: '0.1', min: '0.05', value: '0.5', 'data-testid': 'overhang-width', title: 'Overhang width (m)' });
    this.ohBtn = el('button', { type: 'button', 'data-testid': 'insert-overhang', title: 'Add an outward horizontal segment at the selected point’s height (else the eave) to every profile of this building' }, 'Insert overhang');
    this.ohBtn.addEventListener('click', () => this.insertOverhang());
    this.readout = el('span.plan-status', { 'data-testid': 'profile-readout' });
    this.priority = tagInput('profile-priority', 'Priority tag of the whole profile: the higher wins where collinear neighbours meet (default 0)');
    this.priority.addEventListener('change', () => this.setPriority(this.priority.value));
    this.segPriority = tagInput('segment-priority', 'Priority tag of the selected segment (empty: the profile’s)');
    this.segPriority.addEventListener('change', () => this.setSegmentPriority(this.segPriority.value));
    this.roofOnly = true;
    this.zoomBtn = el('button', { type: 'button', 'data-testid': 'profile-zoom', title: 'Show the whole profile or only from its first bend up' }, 'whole');
    this.zoomBtn.addEventListener('click', () => {
      this.roofOnly = !this.roofOnly;
      this.zoomBtn.textContent = this.roofOnly ? 'whole' : 'roof';
      this.frame = null;
      this.render();
    });
    this.svg = svg('svg', { class: 'profile-svg', 'data-testid': 'profile-editor', tabindex: 0 });
    this.svg.addEventListener('keydown', (e) => {
      if ((e.key === 'Delete' || e.key === 'Backspace') && this.sel !== null) {
        e.preventDefault();
        this.deletePoint();
      }
    });
    this.legend = el('ul.legend.profile-legend', { 'data-testid': 'profile-legend' });
    container.append(
      el('div.pane-bar', {}, el('label', {}, 'profile ', this.choose), this.zoomBtn, this.everyLabel, this.readout),
      el('div.pane-bar.tools', {}, this.addBtn, this.delBtn, el('label', {}, 'overhang ', this.ohWidth, ' m'), this.ohBtn),
      el('div.pane-bar.tools', {},
        el('label', {}, 'priority ', this.priority),
        el('label', {}, 'segment ', this.segPriority)),
      el('div.plan-box', {}, this.svg),
      this.legend,
    );
    new ResizeObserver(() => {
      if (!this.drag) {
        this.frame = null;
        this.render();
      }
    }).observe(this.svg);
    ext.signals.buildingChanged.add((b) => {
      // A reload of the same building (after an op) keeps what is selected.
      if (b?.index !== this.shown) {
        this.sel = null;
        this.seg = null;
      }
      this.shown = b?.index;
      this.frame = null;
      this.render();
    });
    ext.signals.draftChanged.add(() => {
      if (!this.drag) this.frame = null;
      this.render();
    });
    this.render();
  }

  get plan() {
    return this.ext.draft;
  }

  fit() {
    const w = Math.max(40, this.svg.clientWidth);
    const h = Math.max(40, this.svg.clientHeight);
    let w0 = 0;
    let w1 = 1;
    let z1 = 1;
    for (const p of Object.values(this.plan.profiles || {})) {
      for (const [pw, pz] of profilePoints(p)) {
        w0 = Math.min(w0, pw);
        w1 = Math.max(w1, pw);
        z1 = Math.max(z1, pz);
      }
    }
    // Room to drag beyond the current extent.
    const padW = Math.max(1, 0.25 * (w1 - w0));
    w0 -= padW;
    w1 += padW;
    // Tall walls under a small roof: by default show from just below the lowest bend up.
    let z0 = 0;
    if (this.roofOnly) {
      let bend = Infinity;
      for (const p of Object.values(this.plan.profiles || {})) {
        const pts = profilePoints(p);
        if (pts.length > 2) bend = Math.min(bend, pts[1][1]);
      }
      if (Number.isFinite(bend)) z0 = Math.max(0, Math.floor(bend - 1.5));
    }
    z1 += Math.max(1, 0.25 * (z1 - z0));
    const dz = z1 - z0;
    const s = Math.min((w - 2 * MARGIN) / (w1 - w0), (h - 2 * MARGIN) / dz);
    const ox = (w - s * (w1 - w0)) / 2;
    const oy = (h - s * dz) / 2;
    return {
      w, h, s, w0, w1, z0, z1,
      toScreen: (pw, pz) => [ox + (pw - w0) * s, h - oy - (pz - z0) * s],
      toProfile: (sx, sy) => [w0 + (sx - ox) / s, z0 + (h - oy - sy) / s],
    };
  }

  eventPoint(e) {
    const r = this.svg.getBoundingClientRect();
    return this.frame.toProfile(e.clientX - r.left, e.clientY - r.top);
  }

  points() {
    return profilePoints(this.plan?.profiles?.[this.name]);
  }

  render() {
    const plan = this.plan;
    this.svg.replaceChildren();
    const names = Object.keys(plan?.profiles || {});
    this.everyLabel.hidden = !this.ext.batch;
    for (const b of [this.addBtn, this.ohBtn, this.choose, this.priority]) b.disabled = !plan;
    if (!plan) {
      this.choose.replaceChildren();
      this.legend.replaceChildren();
      this.delBtn.disabled = true;
      this.segPriority.disabled = true;
      return;
    }
    if (!names.includes(this.name)) {
      // The profile of most edges first: usually the roof.
      const counts = new Map();
      for (const l of plan.loops) for (const p of l.profiles) counts.set(p, (counts.get(p) || 0) + 1);
      const size = (n) => profilePoints(plan.profiles[n]).length;
      this.name = [...counts].sort((a, b) => b[1] - a[1] || size(b[0]) - size(a[0]))[0]?.[0] ?? names[0];
      this.sel = null;
    }
    if (this.sel !== null && this.sel >= this.points().length) this.sel = null;
    if (this.seg !== null && this.seg >= this.points().length - 1) this.seg = null;
    this.choose.replaceChildren(...names.map((n) => el('option', { value: n }, n)));
    this.choose.value = this.name;
    const colours = profileColours(plan);
    this.legend.replaceChildren(
      ...names.map((n) => el('li.chip', {}, el('span.swatch', { style: `background:${colours.get(n)}` }), n)),
    );
    if (!this.frame) this.frame = this.fit();
    const f = this.frame;
    this.svg.setAttribute('viewBox', `0 0 ${f.w} ${f.h}`);

    // Ground line and the plan edge (w = 0), metre ticks up the wall.
    const [gx0, gy] = f.toScreen(f.w0, f.z0);
    const [gx1] = f.toScreen(f.w1, f.z0);
    const [ex, ey0] = f.toScreen(0, f.z0);
    const [, ey1] = f.toScreen(0, f.z1);
    this.svg.append(
      svg('line', { x1: gx0, y1: gy, x2: gx1, y2: gy, class: 'axis' }),
      svg('line', { x1: ex, y1: ey0, x2: ex, y2: ey1, class: 'axis faint' }),
    );
    const step = f.z1 - f.z0 > 40 ? 10 : f.z1 - f.z0 > 12 ? 5 : 1;
    for (let z = Math.floor(f.z0 / step) * step + step; z < f.z1; z += step) {
      const [, y] = f.toScreen(0, z);
      const t = svg('text', { x: gx0 + 2, y: y - 2, class: 'tick' });
      t.textContent = `${z} m`;
      this.svg.append(svg('line', { x1: gx0, y1: y, x2: gx1, y2: y, class: 'grid' }), t);
    }

    // Other profiles faint, the chosen one on top with its points.
    const poly = (pts) => pts.map(([w, z]) => f.toScreen(w, z).map((v) => v.toFixed(1)).join(',')).join(' ');
    for (const n of names) {
      if (n === this.name) continue;
      this.svg.append(svg('polyline', { points: poly(profilePoints(plan.profiles[n])), class: 'profile-line other', stroke: colours.get(n) }));
    }
    const pts = this.points();
    const profile = plan.profiles[this.name];
    pts.forEach((p, i) => {
      if (i + 1 >= pts.length) return;
      const [ax, ay] = f.toScreen(...p);
      const [bx, by] = f.toScreen(...pts[i + 1]);
      const tag = segmentPriority(profile, i);
      const seg = svg('line', {
        x1: ax, y1: ay, x2: bx, y2: by,
        class: `profile-seg${this.seg === i ? ' selected' : ''}`,
        stroke: colours.get(this.name),
        'data-testid': 'profile-segment',
        'data-index': i,
        'data-priority': tag.value,
      });
      const t = svg('title');
      t.textContent = `segment ${i} · priority ${tag.value}${tag.own === null ? ' (the profile’s)' : ''}`;
      seg.append(t);
      seg.addEventListener('pointerdown', (e) => {
        if (e.button !== 0) return;
        this.seg = i;
        this.render();
      });
      seg.addEventListener('dblclick', (e) => this.insertPoint(e, i));
      this.svg.append(seg);
      if (tag.own !== null) {
        const label = svg('text', { x: (ax + bx) / 2 + 6, y: (ay + by) / 2 - 4, class: 'tick seg-tag' });
        label.textContent = `p${tag.own}`;
        this.svg.append(label);
      }
    });
    // The last segment goes on upwards until the roof closes: hint it.
    if (pts.length >= 2) {
      const [ax, az] = pts[pts.length - 2];
      const [bx, bz] = pts[pts.length - 1];
      const len = Math.hypot(bx - ax, bz - az) || 1;
      const k = (0.15 * f.z1) / len;
      const [x0, y0] = f.toScreen(bx, bz);
      const [x1, y1] = f.toScreen(bx + (bx - ax) * k, bz + (bz - az) * k);
      this.svg.append(svg('line', { x1: x0, y1: y0, x2: x1, y2: y1, class: 'profile-more', stroke: colours.get(this.name) }));
    }
    pts.forEach(([w, z], i) => {
      const [x, y] = f.toScreen(w, z);
      const c = svg('circle', {
        cx: x, cy: y, r: this.sel === i ? 7 : 5.5,
        class: `profile-point${this.sel === i ? ' selected' : ''}${i === 0 ? ' fixed' : ''}`,
        'data-testid': 'profile-point',
        'data-index': i,
      });
      const t = svg('title');
      t.textContent = `point ${i}: w ${w}, z ${z}`;
      c.append(t);
      c.addEventListener('pointerdown', (e) => this.pointDown(e, i));
      this.svg.append(c);
    });
    this.delBtn.disabled = this.sel === null || this.sel === 0 || pts.length <= 2;
    const p = this.sel !== null ? pts[this.sel] : null;
    this.readout.textContent = p ? `w ${p[0]} · z ${p[1]}` : '';
    this.renderPriorities(profile);
  }

  // The tag fields follow the description unless the person is typing in them.
  renderPriorities(profile) {
    const typing = (input) => document.activeElement === input;
    if (!typing(this.priority)) this.priority.value = String(Array.isArray(profile) ? 0 : profile?.priority ?? 0);
    this.segPriority.disabled = this.seg === null;
    if (!typing(this.segPriority)) {
      const own = this.seg === null ? null : segmentPriority(profile, this.seg).own;
      this.segPriority.value = own === null ? '' : String(own);
      this.segPriority.placeholder = this.seg === null ? '—' : 'profile’s';
    }
  }

  // --- priority tags --------------------------------------------------------------------------
  setPriority(text) {
    const v = tagValue(text, false);
    if (v === undefined) return this.badTag('the profile’s priority is a whole number');
    const draft = clone(this.plan);
    draft.profiles[this.name] = withPriority(draft.profiles[this.name], v);
    return this.commit(draft);
  }

  setSegmentPriority(text) {
    if (this.seg === null) return null;
    const v = tagValue(text, true);
    if (v === undefined) return this.badTag('a segment’s priority is a whole number (empty: the profile’s)');
    const draft = clone(this.plan);
    draft.profiles[this.name] = withSegmentPriority(draft.profiles[this.name], this.seg, v);
    return this.commit(draft);
  }

  badTag(detail) {
    this.editor.fail({ title: 'Cannot set the priority', detail });
    this.render();
    return null;
  }

  // The description with the chosen profile's points replaced.
  draftWith(points) {
    const draft = clone(this.plan);
    draft.profiles[this.name] = withPoints(draft.profiles[this.name], points);
    return draft;
  }

  // Commits the chosen profile: a profile op where it means this one building's profile (a
  // single building) or when asked for every building; otherwise a plan op for this building.
  commit(draft) {
    const profile = draft.profiles[this.name];
    if (!this.ext.batch || this.everywhere.checked) {
      this.ext.setDraft(draft);
      return this.ext.commitProfile(this.name, profile);
    }
    return this.ext.commitPlan(draft);
  }

  pointDown(e, index) {
    if (e.button !== 0) return;
    e.preventDefault();
    e.stopPropagation();
    this.svg.focus({ preventScroll: true });
    this.sel = index;
    this.render();
    if (index === 0 || !this.editor.canEdit) return; // the first point stays; viewers only look
    const target = this.svg; // the pressed element is redrawn; the svg keeps the capture
    target.setPointerCapture?.(e.pointerId);
    const start = { x: e.clientX, y: e.clientY };
    const base = this.points().map((p) => p.slice());
    let moved = false;
    this.drag = { index };
    const move = (ev) => {
      if (!moved && Math.hypot(ev.clientX - start.x, ev.clientY - start.y) <= CLICK_SLOP) return;
      moved = true;
      let [w, z] = this.eventPoint(ev);
      // Heights never decrease along a profile.
      const lo = base[index - 1][1];
      const hi = index + 1 < base.length ? base[index + 1][1] : Infinity;
      z = Math.min(hi, Math.max(lo, z));
      const pts = base.map((p) => p.slice());
      pts[index] = [round(w), round(z)];
      this.ext.edit(this.draftWith(pts));
    };
    const up = () => {
      target.removeEventListener('pointermove', move);
      target.removeEventListener('pointerup', up);
      target.removeEventListener('pointercancel', up);
      this.drag = null;
      if (moved) this.commit(this.plan);
    };
    target.addEventListener('pointermove', move);
    target.addEventListener('pointerup', up);
    target.addEventListener('pointercancel', up);
  }

  insertPoint(e, i) {
    e.preventDefault();
    if (!this.editor.canEdit) return;
    const pts = this.points().map((p) => p.slice());
    const [w, z] = this.eventPoint(e);
    const [aw, az] = pts[i];
    const [bw, bz] = pts[i + 1];
    const dw = bw - aw;
    const dz = bz - az;
    const t = Math.min(0.95, Math.max(0.05, ((w - aw) * dw + (z - az) * dz) / (dw * dw + dz * dz || 1)));
    pts.splice(i + 1, 0, [round(aw + dw * t), round(az + dz * t)]);
    this.sel = i + 1;
    this.apply(pts);
  }

  appendPoint() {
    const pts = this.points().map((p) => p.slice());
    const [aw, az] = pts[pts.length - 2] || [0, 0];
    const [bw, bz] = pts[pts.length - 1];
    const len = Math.hypot(bw - aw, bz - az) || 1;
    const dz = bz > az ? (bz - az) / len : 1;
    pts.push([round(bw + (bw - aw) / len), round(bz + dz)]);
    this.sel = pts.length - 1;
    this.apply(pts);
  }

  deletePoint() {
    const pts = this.points().map((p) => p.slice());
    if (this.sel === null || this.sel === 0 || pts.length <= 2) return;
    pts.splice(this.sel, 1);
    this.sel = null;
    this.apply(pts);
  }

  apply(pts) {
    this.commit(this.draftWith(pts));
  }

  // §3.3: the same overhang (a horizontal segment outwards) at one height in every profile.
  insertOverhang() {
    const plan = this.plan;
    if (!plan) return;
    const width = Number(this.ohWidth.value);
    if (!(width > 0)) {
      this.editor.fail({ title: 'Cannot insert the overhang', detail: 'its width must be more than 0 m' });
      return;
    }
    const pts = this.points();
    let h = this.sel !== null ? pts[this.sel]?.[1] : null;
    if (!(h > 0)) h = pts.find(([, z], i) => i > 0 && z > 0)?.[1]; // the first bend: the eave
    if (!(h > 0)) {
      this.editor.fail({ title: 'Cannot insert the overhang', detail: 'select a point above the ground to give its height' });
      return;
    }
    const draft = clone(plan);
    for (const [n, p] of Object.entries(draft.profiles)) {
      const next = withOverhang(profilePoints(p), h, width);
      if (!next) {
        this.editor.fail({ title: 'Cannot insert the overhang', detail: `profile ${n} has a horizontal segment at ${h} m already` });
        return;
      }
      draft.profiles[n] = withPoints(p, next);
    }
    this.ext.commitPlan(draft);
  }
}

function tagInput(testid, title) {
  const input = el('input.num', { type: 'number', step: '1', 'data-testid': testid, title });
  input.addEventListener('keydown', (e) => {
    if (e.key === 'Enter') {
      e.preventDefault();
      input.blur(); // commits through the change event
    }
  });
  return input;
}

// A typed priority tag: an integer, null for an empty segment field, undefined when unusable.
function tagValue(text, emptyIsNull) {
  const t = String(text).trim();
  if (t === '') return emptyIsNull ? null : 0;
  const v = Number(t);
  return Number.isInteger(v) ? v : undefined;
}
