// The extrusion service: reads the open extrusion model's building descriptions into the
// extrusion sub-editor (editor.extrusion), reads them and the mesh again after a plan or
// profile op (anyone's), and draws live previews of a draft in the viewport's preview layer
// in place of the edited building.
import * as THREE from 'three';
import { GLTFLoader } from 'three/examples/jsm/loaders/GLTFLoader.js';
import { EXTRUSION } from './opkinds.js';
import { clone } from './plandoc.js';

const PREVIEW_INTERVAL_MS = 100; // at most ~10 preview requests a second

export class Extrusion {
  constructor(editor, api, viewport) {
    this.editor = editor;
    this.ext = editor.extrusion;
    this.api = api;
    this.viewport = viewport;
    this.token = 0;
    this.seen = 0;        // the latest model version whose change was looked at
    this.stale = false;   // an op arrived during an edit: read everything again afterwards
    this.refreshing = null;
    this.preview = { timer: 0, inflight: false, queued: null, last: 0, object: null };

    const s = editor.signals;
    s.modelOpened.add((model) => this.opened(model));
    s.modelChanged.add((model) => this.changed(model));
    const x = this.ext.signals;
    this.shownBuilding = null;
    x.buildingChanged.add(() => {
      // Another building: the preview of the last one goes.
      if (this.ext.current !== this.shownBuilding) this.clearPreview();
      this.shownBuilding = this.ext.current;
    });
    x.draftEdited.add(() => this.requestPreview());
    x.editEnded.add(({ reverted }) => this.editEnded(reverted));
    x.committed.add(() => {
      // The op arrived as modelChanged already (and started a refresh) unless it was missed.
      if (this.seen < (editor.model?.version ?? 0) || this.stale) this.refresh();
    });
  }

  // --- loading ------------------------------------------------------------------------------
  opened(model) {
    this.token++;
    this.clearPreview();
    this.ext.reset();
    this.seen = model?.version ?? 0;
    this.stale = false;
    if (model?.kind === 'extrusion') this.reload();
  }

  // A plan or profile op (anyone's) changed the geometry: read descriptions and mesh again.
  changed(model) {
    const ext = this.ext;
    if (!ext.active || ext.version === null || model.version <= this.seen) return;
    this.seen = model.version;
    const entry = this.editor.ops.get(model.version);
    if (entry && !EXTRUSION.has(entry.op?.kind)) return; // a rename or a note: nothing to redraw
    if (ext.dragging) {
      this.stale = true; // picked up when the edit ends
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
      if (ed.model === model && !this.ext.dragging) this.clearPreview();
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
    this.ext.setDoc(doc, ed.model.version);
  }

  editEnded(reverted) {
    const p = this.preview;
    clearTimeout(p.timer);
    p.timer = 0;
    p.queued = null;
    if (!reverted) return;
    this.clearPreview();
    if (this.stale) this.refresh();
  }

  // --- previews -------------------------------------------------------------------------------
  requestPreview() {
    const p = this.preview;
    p.queued = { index: this.ext.current, plan: clone(this.ext.draft), token: this.token };
    if (p.inflight || p.timer) return;
    const wait = Math.max(0, p.last + PREVIEW_INTERVAL_MS - Date.now());
    p.timer = setTimeout(() => {
      p.timer = 0;
      this.runPreview();
    }, wait);
  }

  async runPreview() {
    const p = this.preview;
    const ext = this.ext;
    const job = p.queued;
    p.queued = null;
    if (!job) return;
    p.inflight = true;
    p.last = Date.now();
    ext.setPreview({ state: 'busy' });
    const current = () => job.token === this.token && job.index === ext.current && ext.dragging;
    try {
      const buffer = await this.api.previewExtrusion(job.plan);
      if (current()) {
        const gltf = await new GLTFLoader().parseAsync(buffer, '');
        if (current()) {
          this.showPreview(job.index, gltf.scene);
          ext.setPreview({ state: 'ok' });
        }
      }
    } catch (err) {
      if (job.token === this.token) ext.setPreview({ state: 'failed', problem: err.problem || { title: err.message } });
    } finally {
      p.inflight = false;
      if (p.queued) this.requestPreview();
    }
  }

  // Draws `scene` in place of building i's meshes.
  showPreview(index, scene) {
    const { model, preview } = this.viewport.layers;
    this.dropPreviewObject();
    const c = this.ext.buildings[index]?.component;
    const meshes = typeof c === 'number' ? model.meshes(c) : [];
    const colour = meshes[0]?.userData.baseColour || new THREE.Color(0x4f7cac);
    if (typeof c === 'number') model.hide([c]);
    scene.traverse((o) => {
      if (!o.isMesh) return;
      for (const m of [].concat(o.material)) m.dispose();
      o.material = new THREE.MeshStandardMaterial({ color: colour, roughness: 0.85, metalness: 0, side: THREE.DoubleSide });
    });
    this.preview.object = preview.add(scene);
    this.viewport.mark('extrudePreview', this.ext.previews);
  }

  dropPreviewObject() {
    this.viewport.layers.preview.remove(this.preview.object);
    this.preview.object = null;
  }

  clearPreview() {
    const p = this.preview;
    clearTimeout(p.timer);
    p.timer = 0;
    p.queued = null;
    this.dropPreviewObject();
    this.viewport.layers.model.unhide();
    this.viewport.mark('extrudePreview', null);
    this.ext.setPreview(null);
  }
}
