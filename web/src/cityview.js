// City view of an extrusion model: the 3D view fits the whole batch, buildings are coloured
// by height (or by their set of profiles, i.e. their roof style), a click picks one for the
// plan editor, and a report lists the footprints that failed (or are not watertight) with
// the reasons. Also the "new extrusion" upload: footprints (GeoJSON) or a plan, and a style.
import * as THREE from 'three';
import { el } from './dom.js';
import { STYLES } from './plandoc.js';

// Low → high: blue, teal, green, ochre, brick (all well away from the light background and
// from the yellow of a selection).
const RAMP = [0x4f7cac, 0x3d8a8a, 0x6a994e, 0xb07d2b, 0xa84f3f].map((c) => new THREE.Color(c));
const STYLE_PALETTE = [0xc4683f, 0x4f7cac, 0x6a994e, 0x9a6fa8, 0x3d8a8a, 0x8a6d5a, 0xa84f62, 0x5b6b7d];

function ramp(t) {
  const x = Math.min(1, Math.max(0, t)) * (RAMP.length - 1);
  const i = Math.min(RAMP.length - 2, Math.floor(x));
  return RAMP[i].clone().lerp(RAMP[i + 1], x - i);
}

// The style of a description: the profile names its edges use (a style file names them).
function styleKey(plan) {
  if (!plan) return '';
  const names = new Set();
  for (const l of plan.loops || []) {
    if (!Array.isArray(l) && Array.isArray(l.profiles)) l.profiles.forEach((p) => names.add(p));
    else if (plan.default_profile) names.add(plan.default_profile);
  }
  return [...names].sort().join('+');
}

export class CityView {
  constructor(editor, viewport, container) {
    this.editor = editor;
    this.ext = editor.extrusion;
    this.viewport = viewport;
    const ext = this.ext;
    this.mode = 'height';
    this.heights = null; // {root, byComponent: Map, min, max}

    this.summary = el('div.city-summary', { 'data-testid': 'city-summary' });
    this.colourBy = el(
      'select',
      { 'data-testid': 'city-colour', title: 'Colour the buildings by' },
      el('option', { value: 'height' }, 'colour: height'),
      el('option', { value: 'style' }, 'colour: style'),
      el('option', { value: 'none' }, 'colour: plain'),
    );
    this.colourBy.addEventListener('change', () => {
      this.mode = this.colourBy.value;
      this.recolour();
    });
    this.fitBtn = el('button', { type: 'button', 'data-testid': 'city-fit', title: 'Fit the whole city in the view' }, 'Fit city');
    this.fitBtn.addEventListener('click', () => viewport.frameGround());
    this.legend = el('div.city-legend', { 'data-testid': 'city-legend' });
    this.failed = el('ul.failed-list', { 'data-testid': 'extrude-report' });
    container.append(
      el('h2', {}, 'Extrusion'),
      this.summary,
      el('div.proc-actions', {}, this.colourBy, this.fitBtn),
      this.legend,
      this.failed,
    );
    container.hidden = true;
    this.container = container;

    // The viewport asks each mesh for a colour once it is shown (see Viewport.colourize).
    viewport.layers.model.tint = (mesh) => this.tint(mesh);
    ext.signals.docChanged.add(() => {
      this.render();
      this.recolour();
      this.fitOnce();
    });
    ext.signals.buildingChanged.add(() => this.renderSelected());
    viewport.signals.shown.add(() => this.fitOnce());
  }

  render() {
    const ext = this.ext;
    this.container.hidden = !ext.active || !ext.doc;
    if (this.container.hidden) return;
    const bs = ext.buildings;
    const failed = bs.filter((b) => b.status === 'failed');
    const leaky = bs.filter((b) => b.status === 'not_watertight');
    const fellBack = bs.filter((b) => b.fallback);
    const tris = bs.reduce((n, b) => n + (b.triangles || 0), 0);
    const style = ext.doc.style ? ` · style ${ext.doc.style}` : '';
    this.summary.textContent = ext.batch
      ? `${bs.length} footprint${bs.length === 1 ? '' : 's'} · ${bs.length - failed.length} built · ${failed.length} failed${fellBack.length ? ` · ${fellBack.length} fell back` : ''}${leaky.length ? ` · ${leaky.length} not watertight` : ''}${style}${tris ? ` · ${tris.toLocaleString()} triangles` : ''}`
      : 'one building';
    this.colourBy.hidden = !ext.batch;
    this.fitBtn.hidden = !ext.batch;
    this.legend.hidden = !ext.batch;
    const row = (b, i) => el(
      'li.failed',
      {
        'data-testid': b.status === 'failed' ? 'failed-footprint' : 'leaky-footprint',
        dataset: { building: i, id: b.id },
        tabIndex: 0,
        title: 'Open this footprint in the plan editor',
        onclick: () => ext.focus(i),
        onkeydown: (e) => e.key === 'Enter' && ext.focus(i),
      },
      el('span.failed-id', {}, String(b.id)),
      el('span.failed-status', {}, b.status === 'failed' ? 'failed' : b.fallback ? `fell back: ${b.fallback}` : 'not watertight'),
      el('div.failed-reason', {}, b.reason || ''),
    );
    const items = [];
    bs.forEach((b, i) => {
      if (b.status !== 'ok' || b.fallback) items.push(row(b, i));
    });
    this.failed.replaceChildren(...(items.length ? items : [el('li.empty', {}, ext.batch ? 'Every footprint was built.' : '')]));
    this.renderSelected();
  }

  renderSelected() {
    for (const li of this.failed.querySelectorAll('li.failed')) {
      li.classList.toggle('active', Number(li.dataset.building) === this.ext.current);
    }
  }

  // --- framing ------------------------------------------------------------------------------
  // Once per opened batch, as soon as both its descriptions and its mesh are there.
  fitOnce() {
    const ext = this.ext;
    const id = this.editor.model?.id;
    if (!ext.active || !ext.batch || id == null || this.fitted === id) return;
    if (this.viewport.shown?.model !== id) return; // the mesh's arrival calls again
    this.fitted = id;
    this.viewport.frameGround();
  }

  // --- colours ------------------------------------------------------------------------------
  recolour() {
    this.heights = null;
    this.viewport.colourize();
    this.renderLegend();
  }

  // Each component's top (the highest point of its meshes) in the loaded model.
  measure() {
    const layer = this.viewport.layers.model;
    if (this.heights && this.heights.root === layer.root) return this.heights;
    const byComponent = new Map();
    let min = Infinity;
    let max = -Infinity;
    let ground = Infinity;
    const box = new THREE.Box3();
    layer.root?.updateWorldMatrix(true, true);
    for (const [component, meshes] of layer.components()) {
      let top = -Infinity;
      for (const m of meshes) {
        box.setFromObject(m);
        top = Math.max(top, box.max.y);
        ground = Math.min(ground, box.min.y);
      }
      byComponent.set(component, top);
    }
    for (const [c, top] of byComponent) {
      byComponent.set(c, top - ground);
      min = Math.min(min, top - ground);
      max = Math.max(max, top - ground);
    }
    this.heights = { root: layer.root, byComponent, min, max };
    return this.heights;
  }

  tint(mesh) {
    const ext = this.ext;
    if (!ext.active || !ext.batch || this.mode === 'none' || !this.viewport.layers.model.root) return null;
    const c = mesh.userData.componentId;
    if (this.mode === 'height') {
      const h = this.measure();
      const top = h.byComponent.get(c);
      if (top === undefined) return null;
      return ramp(h.max > h.min ? (top - h.min) / (h.max - h.min) : 0.5);
    }
    const i = ext.buildingOfComponent(c);
    const key = i === null ? '' : styleKey(ext.buildings[i].plan);
    return new THREE.Color(STYLE_PALETTE[this.styleIndex(key) % STYLE_PALETTE.length]);
  }

  styleIndex(key) {
    const keys = [...new Set(this.ext.buildings.filter((b) => b.status !== 'failed').map((b) => styleKey(b.plan)))].sort();
    return Math.max(0, keys.indexOf(key));
  }

  renderLegend() {
    const ext = this.ext;
    if (!ext.active || !ext.batch || this.mode === 'none') {
      this.legend.replaceChildren();
      return;
    }
    const chip = (colour, text) => el('span.chip', {}, el('span.swatch', { style: `background:#${colour.getHexString()}` }), text);
    if (this.mode === 'height') {
      const h = this.viewport.layers.model.root ? this.measure() : null;
      if (!h || !Number.isFinite(h.min)) {
        this.legend.replaceChildren();
        return;
      }
      this.legend.replaceChildren(chip(ramp(0), `${h.min.toFixed(1)} m`), chip(ramp(0.5), '…'), chip(ramp(1), `${h.max.toFixed(1)} m`));
    } else {
      const keys = [...new Set(ext.buildings.filter((b) => b.status !== 'failed').map((b) => styleKey(b.plan)))].sort();
      this.legend.replaceChildren(...keys.map((k, i) => chip(new THREE.Color(STYLE_PALETTE[i % STYLE_PALETTE.length]), k || '—')));
    }
  }
}

// "New extrusion": a GeoJSON footprint file (or one plan JSON) and a style → the extrude job.
export class NewExtrusionPanel {
  constructor(editor, upload, container) {
    this.file = el('input', { type: 'file', 'data-testid': 'extrude-input', accept: '.geojson,.json' });
    this.style = el(
      'select.up',
      { 'data-testid': 'extrude-style', title: 'Roof style for footprints', 'aria-label': 'Style' },
      ...STYLES.map((s) => el('option', { value: s }, s)),
    );
    this.file.addEventListener('change', () => {
      const f = this.file.files[0];
      this.file.value = '';
      if (f) upload.extrusion(f, this.style.value);
    });
    const drop = el(
      'label.drop',
      { 'data-testid': 'extrude-drop' },
      this.file,
      el('span.drop-main', {}, 'New from footprints'),
      el('span.drop-sub', {}, 'GeoJSON footprints or a plan JSON'),
    );
    for (const type of ['dragenter', 'dragover']) {
      drop.addEventListener(type, (e) => {
        e.preventDefault();
        drop.classList.add('over');
      });
    }
    drop.addEventListener('dragleave', () => drop.classList.remove('over'));
    drop.addEventListener('drop', (e) => {
      e.preventDefault();
      drop.classList.remove('over');
      const f = e.dataTransfer?.files?.[0];
      if (f) upload.extrusion(f, this.style.value);
    });
    container.append(el('h2', {}, 'Extrude'), el('div.import', {}, drop, this.style));
    // viewer accounts make no models
    editor.signals.accountChanged.add((a) => {
      container.hidden = a?.role === 'viewer';
    });
  }
}
