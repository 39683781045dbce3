// Extrusion models (kind "extrusion"): their building descriptions, the building being
// edited, live previews while someone drags, and the plan/profile ops that commit an edit.
// The plan editor, the profile editor and the city view only talk to this object.
import * as THREE from 'three';
import { GLTFLoader } from 'three/examples/jsm/loaders/GLTFLoader.js';
import { Signal } from './signal.js';
import { followJob } from './jobs.js';

const PREVIEW_INTERVAL_MS = 100; // at most ~10 preview requests a second
export const STYLES = ['hip', 'gable', 'mansard', 'overhang', 'flat'];
const EDIT_OPS = new Set(['plan', 'profile']);

export const clone = (x) => (x === undefined ? undefined : JSON.parse(JSON.stringify(x)));

// A loop as {points, profiles} whatever form the description used ([[x, y], …] or an object).
export function loopOf(plan, i) {
  const l = plan.loops[i];
  const points = Array.isArray(l) ? l : l.points;
  const fallback = plan.default_profile ?? Object.keys(plan.profiles || {})[0] ?? null;
  const profiles = !Array.isArray(l) && Array.isArray(l.profiles) ? l.profiles : points.map(() => fallback);
  return { points, profiles };
}

// The description with every loop in object form, so edits can change per-edge profiles.
export function normalizePlan(plan) {
  const p = clone(plan);
  p.loops = (p.loops || []).map((_, i) => {
    const { points, profiles } = loopOf(plan, i);
    return { points: clone(points), profiles: profiles.slice() };
  });
  return p;
}

// A profile's points whichever form it is written in.
export function profilePoints(profile) {
  return Array.isArray(profile) ? profile : profile?.points || [];
}

export function withPoints(profile, points) {
  return Array.isArray(profile) ? points : { ...profile, points };
}

export class Extrusion {
  constructor(editor, api, live, session, viewport) {
    this.editor = editor;
    this.api = api;
    this.live = live;
    this.session = session;
    this.viewport = viewport;
    this.signals = {
      docChanged: new Signal(),      // the model's descriptions were (re)read
      buildingChanged: new Signal(), // another building is being edited
      draftChanged: new Signal(),    // the edited building's description changed (drag, revert)
      previewChanged: new Signal(),  // {state: 'busy'|'ok'|'failed', problem?}
    };
    this.doc = null;       // GET …/plan as read
    this.batch = false;
    this.buildings = [];   // [{id, plan, status, reason, triangles, component}]
    this.current = null;   // index of the edited building
    this.draft = null;     // its description as being edited (normalized)
    this.version = null;   // model version the descriptions belong to
    this.token = 0;
    this.dragging = false;
    this.previews = 0;     // preview requests made (shown as a data attribute for tests)
    this.preview = { timer: 0, inflight: false, queued: null, last: 0, object: null, hidden: [] };

    const s = editor.signals;
    s.modelOpened.add((model) => this.opened(model));
    s.modelChanged.add((model) => this.changed(model));
    s.selectionChanged.add((sel) => this.picked(sel));
  }

  get active() {
    return this.editor.model?.kind === 'extrusion';
  }

  // --- loading ------------------------------------------------------------------------------
  opened(model) {
    this.token++;
    this.clearPreview();
    this.doc = null;
    this.buildings = [];
    this.current = null;
    this.draft = null;
    this.version = null;
    this.seen = model?.version ?? 0;
    this.stale = false;
    if (model?.kind === 'extrusion') this.reload();
    else {
      this.signals.docChanged.dispatch(null);
      this.signals.buildingChanged.dispatch(null);
    }
  }

  // A plan or profile op (anyone's) changed the geometry: read descriptions and mesh again.
  changed(model) {
    if (!this.active || this.version === null || model.version <= this.seen) return;
    this.seen = model.version;
    const entry = this.editor.ops.get(model.version);
    if (entry && !EDIT_OPS.has(entry.op?.kind)) return; // a rename or a note: nothing to redraw
    if (this.dragging) {
      this.stale = true; // picked up on release
      return;
    }
    this.refresh();
  }

  // Reads descriptions and mesh again; the preview stays up until the new mesh is shown.
  refresh() {
    const ed = this.editor;
    if (!ed.model) return Promise.resolve();
    const model = ed.model;
    this.stale = false;
    this.refreshing = Promise.all([this.reload(), this.viewport.load(model, { keepCamera: true })]).then(() => {
      if (ed.model === model && !this.dragging) this.clearPreview();
    });
    return this.refreshing;
  }

  async reload() {
    const ed = this.editor;
    const id = ed.model?.id;
    if (id == null) return;
    const token = ++this.token;
    let doc;
    try {
      doc = await this.api.getPlan(id);
    } catch (err) {
      if (token === this.token) ed.fail(err);
      return;
    }
    if (token !== this.token || ed.model?.id !== id) return;
    this.doc = doc;
    this.batch = Array.isArray(doc.buildings);
    this.buildings = this.batch
      ? doc.buildings
      : [{ id: ed.model.name, plan: doc, status: 'ok', reason: null, component: 0 }];
    this.version = ed.model.version;
    this.signals.docChanged.dispatch(doc);
    let pick = this.current;
    if (pick === null || pick >= this.buildings.length) pick = this.batch ? null : 0;
    this.setBuilding(pick, { force: true });
  }

  // --- the edited building --------------------------------------------------------------------
  setBuilding(index, { force = false } = {}) {
    if (!force && index === this.current) return;
    if (index !== this.current) this.clearPreview();
    this.current = index;
    const b = index === null ? null : this.buildings[index];
    this.draft = b?.plan ? normalizePlan(b.plan) : null;
    this.signals.buildingChanged.dispatch(b ? { index, building: b } : null);
    this.signals.draftChanged.dispatch(this.draft);
  }

  get building() {
    return this.current === null ? null : this.buildings[this.current];
  }

  buildingOfComponent(component) {
    const i = this.buildings.findIndex((b) => b.component === component);
    return i < 0 ? null : i;
  }

  // A building picked in the 3D view becomes the edited one.
  picked(sel) {
    if (!this.active || !sel || typeof sel.component !== 'number') return;
    const i = this.buildingOfComponent(sel.component);
    if (i !== null) this.setBuilding(i);
  }

  // Selects building i in the 3D view too (the city report and lists call this).
  focus(index) {
    this.setBuilding(index);
    const c = this.buildings[index]?.component;
    this.editor.select(typeof c === 'number' ? { component: c, group: this.buildings[index].id } : null);
  }

  // --- drafts, previews, commits --------------------------------------------------------------
  // An edit in progress: redraw the editors and preview it in 3D.
  edit(draft) {
    this.draft = draft;
    this.dragging = true;
    this.signals.draftChanged.dispatch(draft);
    this.requestPreview();
  }

  // Back to the stored description (an edit refused or abandoned).
  revert() {
    this.dragging = false;
    this.clearPreview();
    if (this.stale) this.refresh();
    const b = this.building;
    this.draft = b?.plan ? normalizePlan(b.plan) : null;
    this.signals.draftChanged.dispatch(this.draft);
  }

  requestPreview() {
    const p = this.preview;
    p.queued = { index: this.current, plan: clone(this.draft), token: this.token };
    if (p.inflight || p.timer) return;
    const wait = Math.max(0, p.last + PREVIEW_INTERVAL_MS - Date.now());
    p.timer = setTimeout(() => {
      p.timer = 0;
      this.runPreview();
    }, wait);
  }

  async runPreview() {
    const p = this.preview;
    const job = p.queued;
    p.queued = null;
    if (!job) return;
    p.inflight = true;
    p.last = Date.now();
    this.previews++;
    this.signals.previewChanged.dispatch({ state: 'busy' });
    try {
      const buffer = await this.api.previewExtrusion(job.plan);
      if (job.token === this.token && job.index === this.current && this.dragging) {
        const gltf = await new GLTFLoader().parseAsync(buffer, '');
        if (job.token === this.token && job.index === this.current && this.dragging) {
          this.showPreview(job.index, gltf.scene);
          this.signals.previewChanged.dispatch({ state: 'ok' });
        }
      }
    } catch (err) {
      if (job.token === this.token) this.signals.previewChanged.dispatch({ state: 'failed', problem: err.problem || { title: err.message } });
    } finally {
      p.inflight = false;
      if (p.queued) this.requestPreview();
    }
  }

  // Draws `scene` in place of building i's meshes in the 3D view.
  showPreview(index, scene) {
    const vp = this.viewport;
    this.dropPreviewObject();
    const c = this.buildings[index]?.component;
    const meshes = typeof c === 'number' ? vp.byComponent.get(c) || [] : [];
    const colour = meshes[0]?.userData.baseColour || new THREE.Color(0x4f7cac);
    for (const m of meshes) {
      if (m.visible) {
        m.visible = false;
        this.preview.hidden.push(m);
      }
    }
    scene.traverse((o) => {
      if (!o.isMesh) return;
      for (const m of [].concat(o.material)) m.dispose();
      o.material = new THREE.MeshStandardMaterial({ color: colour, roughness: 0.85, metalness: 0, side: THREE.DoubleSide });
    });
    scene.userData.preview = true;
    this.preview.object = scene;
    vp.scene.add(scene);
    vp.container.dataset.extrudePreview = String(this.previews);
    vp.requestRender();
  }

  dropPreviewObject() {
    const o = this.preview.object;
    if (!o) return;
    this.viewport.scene.remove(o);
    o.traverse((x) => {
      if (x.isMesh) {
        x.geometry.dispose();
        for (const m of [].concat(x.material)) m.dispose();
      }
    });
    this.preview.object = null;
  }

  clearPreview() {
    const p = this.preview;
    clearTimeout(p.timer);
    p.timer = 0;
    p.queued = null;
    this.dropPreviewObject();
    for (const m of p.hidden) m.visible = true;
    p.hidden = [];
    delete this.viewport.container.dataset.extrudePreview;
    this.viewport.requestRender();
    this.signals.previewChanged.dispatch(null);
  }

  // The drag is over: send the edited building as a plan op (it reaches everyone in the room).
  async commitPlan(draft = this.draft) {
    return this.sendOp({ kind: 'plan', building: this.current, plan: draft });
  }

  // A profile replaced in every building whose description has it.
  async commitProfile(name, profile) {
    return this.sendOp({ kind: 'profile', name, profile });
  }

  async sendOp(op) {
    const ed = this.editor;
    this.dragging = false;
    const p = this.preview;
    clearTimeout(p.timer);
    p.timer = 0;
    p.queued = null;
    try {
      await this.live.sendOp(op);
    } catch (err) {
      if (!err.problem || !this.live.open) ed.fail(err); // a nack was already shown
      this.revert();
      return false;
    }
    // The op arrived as modelChanged already (and started a refresh); show its result.
    if (this.seen < (ed.model?.version ?? 0) || this.stale) await this.refresh();
    else await this.refreshing;
    return true;
  }

  // --- new models from footprints or a plan -------------------------------------------------------
  async upload(file, style) {
    const ed = this.editor;
    const name = file.name.replace(/\.[^.]*$/, '') || file.name;
    ed.setJob({ status: 'uploading', progress: 0, stage: 'upload', name: file.name });
    let job;
    try {
      job = await this.api.uploadExtrusion(file, { name, style });
    } catch (err) {
      ed.setJob({ status: 'failed', progress: 0, stage: 'upload', name: file.name });
      ed.fail(err);
      return null;
    }
    ed.setJob({ ...job, name: file.name });
    const done = await followJob(ed, this.api, this.live, job, (j) => ed.setJob({ ...j, name: file.name }));
    ed.setJob({ ...done, name: file.name });
    if (done.status !== 'succeeded') {
      ed.fail(done.error || { title: `Extrusion ${done.status}`, detail: file.name });
      return done;
    }
    this.lastReport = done.result?.report ?? null;
    const id = done.result?.model;
    await this.session.loadModels();
    if (id != null) await this.session.open(id);
    return done;
  }
}
