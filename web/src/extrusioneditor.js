// The extrusion sub-editor, owned by the Editor: the open extrusion model's building
// descriptions, the building being edited, its draft while someone drags, and the plan and
// profile ops that commit an edit. The plan editor, the profile editor and the city view read
// this state and listen to its signals; the Extrusion service (extrusion.js) loads the
// descriptions and draws the live previews it asks for.
import { OP } from './opkinds.js';
import { Signal } from './signal.js';
import { normalizePlan } from './plandoc.js';

export class ExtrusionEditor {
  constructor(editor) {
    this.editor = editor;
    this.signals = {
      docChanged: new Signal(),      // the model's descriptions were (re)read (doc or null)
      buildingChanged: new Signal(), // another building is being edited ({index, building} or null)
      draftChanged: new Signal(),    // the edited building's description changed (draft or null)
      draftEdited: new Signal(),     // an edit in progress (a drag): preview the draft
      editEnded: new Signal(),       // {reverted}: no more previews for the edit that was in progress
      committed: new Signal(),       // version: a plan or profile op of ours was applied
      previewChanged: new Signal(),  // {state: 'busy'|'ok'|'failed', problem?} or null
      toolChanged: new Signal(),     // what a click on a plan edge does (tool or null)
      featureChanged: new Signal(),  // the selected step or offset event ({kind, index} or null)
    };
    this.clear();
    this.previews = 0;     // preview requests made (shown as a data attribute for tests)
    this.preview = null;   // the last preview state
    // What the step tool places: natural (a rectangle grown out of or into the plan) or
    // forced (a polygon united with the plan), at a height, its size, its edges' profile.
    this.stepTool = { kind: 'natural', height: 3.5, width: 2, depth: 1, profile: null };
    editor.signals.selectionChanged.add((sel) => this.picked(sel));
  }

  get active() {
    return this.editor.model?.kind === 'extrusion';
  }

  // --- the descriptions -----------------------------------------------------------------------
  // Nothing loaded (another model was opened).
  reset() {
    this.clear();
    this.signals.docChanged.dispatch(null);
    this.signals.buildingChanged.dispatch(null);
  }

  clear() {
    this.doc = null;       // GET …/plan as read
    this.batch = false;
    this.buildings = [];   // [{id, plan, status, reason, triangles, component}]
    this.current = null;   // index of the edited building
    this.draft = null;     // its description as being edited (normalized)
    this.version = null;   // model version the descriptions belong to
    this.dragging = false; // an edit is in progress (previews, not yet committed)
    // A click on a plan edge: null selects it; 'anchor', 'step' place one there; 'offset'
    // leaves the edge out of the selected offset event (or puts it back).
    this.tool = null;
    this.feature = null;   // {kind: 'step'|'offset', index}: the step or offset event selected
  }

  // The descriptions of model version `version` as GET …/plan gave them.
  setDoc(doc, version) {
    this.doc = doc;
    this.batch = Array.isArray(doc.buildings);
    this.buildings = this.batch
      ? doc.buildings
      : [{ id: this.editor.model?.name, plan: doc, status: 'ok', reason: null, component: 0 }];
    this.version = version;
    this.signals.docChanged.dispatch(doc);
    let pick = this.current;
    if (pick === null || pick >= this.buildings.length) pick = this.batch ? null : 0;
    this.setBuilding(pick, { force: true });
  }

  // --- the edited building --------------------------------------------------------------------
  setBuilding(index, { force = false } = {}) {
    if (!force && index === this.current) return;
    if (index !== this.current) {
      // tools and selected features belong to the building they were chosen on
      this.tool = null;
      this.feature = null;
    }
    this.current = index;
    const b = index === null ? null : this.buildings[index];
    this.draft = b?.plan ? normalizePlan(b.plan) : null;
    this.signals.buildingChanged.dispatch(b ? { index, building: b } : null);
    this.signals.draftChanged.dispatch(this.draft);
  }

  // Another tool for clicks on plan edges; the same one again goes back to selecting.
  setTool(tool) {
    const next = tool === this.tool ? null : tool;
    if (next === this.tool) return;
    this.tool = next;
    this.signals.toolChanged.dispatch(next);
  }

  // The step tool's settings (read when a step is placed; nothing is drawn from them).
  setStepTool(fields) {
    this.stepTool = { ...this.stepTool, ...fields };
  }

  selectFeature(feature) {
    const f = feature ?? null;
    if (f?.kind === this.feature?.kind && f?.index === this.feature?.index) return;
    this.feature = f;
    if (this.tool === 'offset' && f?.kind !== 'offset') this.setTool(null);
    this.signals.featureChanged.dispatch(f);
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

  // Edits building i and selects it in the 3D view too (the city report and lists call this).
  focus(index) {
    this.setBuilding(index);
    const c = this.buildings[index]?.component;
    this.editor.selected.set(typeof c === 'number' ? { component: c, group: this.buildings[index].id } : null);
  }

  // --- drafts, previews, commits --------------------------------------------------------------
  // An edit in progress: redraw the editors and preview it in 3D.
  edit(draft) {
    this.draft = draft;
    this.dragging = true;
    this.signals.draftChanged.dispatch(draft);
    this.signals.draftEdited.dispatch(draft);
  }

  // Back to the stored description (an edit refused or abandoned).
  revert() {
    this.dragging = false;
    this.signals.editEnded.dispatch({ reverted: true });
    const b = this.building;
    this.draft = b?.plan ? normalizePlan(b.plan) : null;
    this.signals.draftChanged.dispatch(this.draft);
  }

  setPreview(state) {
    if (state?.state === 'busy') this.previews += 1;
    this.preview = state;
    this.signals.previewChanged.dispatch(state);
  }

  // Shows a changed description at once (an edit about to be committed).
  setDraft(draft) {
    if (draft === this.draft) return;
    this.draft = draft;
    this.signals.draftChanged.dispatch(draft);
  }

  // The edited building's description as a plan op (it reaches everyone in the room).
  commitPlan(draft = this.draft) {
    this.setDraft(draft);
    return this.commit({ kind: OP.plan, building: this.current, plan: draft });
  }

  // A profile replaced in every building whose description has it.
  commitProfile(name, profile) {
    return this.commit({ kind: OP.profile, name, profile });
  }

  // Resolves true once the op is applied; a refused op puts the stored description back.
  async commit(op) {
    this.dragging = false;
    this.signals.editEnded.dispatch({ reverted: false });
    const version = await this.editor.execute(op);
    if (version === null) {
      this.revert();
      return false;
    }
    this.signals.committed.dispatch(version);
    return true;
  }
}
