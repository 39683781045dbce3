// The open point cloud model, as the editor's sub-editor: how its points are coloured (by
// segment or by label), how many of them to show (the budget of GET …/points.glb), the
// segment picked, the tool a box drag in the view makes (an ROI to segment again, a template
// on the picked segment), which points are drawn once the cloud is proceduralized (the ones its
// grammar derives, edited like a mesh model, or the uploaded ones, refined by boxes), and what
// the points on screen said of themselves (points.glb's node extras, or derivedpoints.js).
// Ops go through editor.execute like every other; the segment job through Api.segment.
import { OP } from './opkinds.js';
import { Signal } from './signal.js';

export const COLOUR_MODES = ['segment', 'label'];
export const DEFAULT_BUDGET = 1000000;
export const MAX_BUDGET = 100000000; // what the server takes (api_points.c)
// 'procTemplate': a box the next proceduralize takes as a template (§3.2), kept in the client
export const TOOLS = ['roi', 'template', 'procTemplate'];
const MAX_PROC_TEMPLATES = 64; // what POST …/proceduralize takes
export const VIEWS = ['derived', 'input'];

export const isCloud = (model) => model?.kind === 'pointcloud';

export class CloudEditor {
  constructor(editor) {
    this.editor = editor;
    this.signals = {
      colourChanged: new Signal(),  // mode
      budgetChanged: new Signal(),  // budget
      segmentChanged: new Signal(), // segment id (or null)
      toolChanged: new Signal(),    // tool (or null)
      infoChanged: new Signal(),    // info (or null)
      viewChanged: new Signal(),    // view
      procTemplatesChanged: new Signal(), // the template boxes for the next proceduralize
    };
    this.colourBy = 'segment';
    this.budget = DEFAULT_BUDGET;
    this.segment = null;
    this.tool = null;
    this.view = 'derived'; // of a proceduralized cloud; an unproceduralized one has only its input
    this.procTemplates = []; // boxes in the cloud's coordinates (the offset added)
    // {model, points, shown, budget, offset, segmented, segments, segment_ids, labels} of what
    // is on screen (ids below segment_ids may be in use)
    this.info = null;
    editor.signals.modelOpened.add(() => this.reset());
    // ROI refinement and template marking keep every segment's id (a segment they empty is
    // gone, its id unused); a new segmentation numbers afresh: a picked id would name another
    editor.signals.pointsChanged.add((model, kind) => {
      if (kind !== OP.segment_roi && kind !== OP.mark_template) this.setSegment(null);
    });
  }

  get active() {
    return isCloud(this.editor.model);
  }

  reset() {
    this.setSegment(null);
    this.setTool(null);
    this.setInfo(null);
    this.view = 'derived';
    this.clearProcTemplates();
  }

  // A template box for the next proceduralize, in model coordinates (those of the uploaded
  // points drawn, local to the cloud's offset); kept in the cloud's coordinates, as the
  // proceduralize job takes them.
  addProcTemplate(box) {
    const o = this.info?.offset ?? [0, 0, 0];
    if (this.procTemplates.length >= MAX_PROC_TEMPLATES) {
      this.editor.fail({ title: 'Too many template boxes', detail: `proceduralize takes at most ${MAX_PROC_TEMPLATES}` });
      return;
    }
    this.procTemplates.push(box.map((v, k) => v + o[k % 3]));
    this.signals.procTemplatesChanged.dispatch(this.procTemplates);
  }

  clearProcTemplates() {
    if (!this.procTemplates.length) return;
    this.procTemplates = [];
    this.signals.procTemplatesChanged.dispatch(this.procTemplates);
  }

  // The options of POST …/proceduralize for the open cloud: its template boxes, when marked
  // (then only their copies are repetitions: no automatic search beside them).
  procOptions() {
    return this.procTemplates.length ? { templates: this.procTemplates.map((b) => b.slice()), auto: false } : {};
  }

  // Whether `model` is drawn as the points its grammar derives (a proceduralized cloud, unless
  // the person asked for the uploaded points).
  showsDerived(model = this.editor.model) {
    return isCloud(model) && !!model.proceduralized && this.view === 'derived';
  }

  setView(view) {
    if (!VIEWS.includes(view) || view === this.view) return;
    this.view = view;
    this.setTool(null); // ROI and template boxes refine the uploaded points only
    this.signals.viewChanged.dispatch(view);
  }

  setColourBy(mode) {
    if (!COLOUR_MODES.includes(mode) || mode === this.colourBy) return;
    this.colourBy = mode;
    this.signals.colourChanged.dispatch(mode);
  }

  // A budget the server takes (1 … MAX_BUDGET); anything else is told and ignored.
  setBudget(value) {
    const n = Number(value);
    if (!Number.isInteger(n) || n < 1 || n > MAX_BUDGET) {
      this.editor.fail({ title: 'Not a point budget', detail: `${value}: a whole number of points from 1 to ${MAX_BUDGET}` });
      this.signals.budgetChanged.dispatch(this.budget); // the control shows the budget in force
      return;
    }
    if (n === this.budget) return;
    this.budget = n;
    this.signals.budgetChanged.dispatch(n);
  }

  setSegment(segment) {
    const s = Number.isInteger(segment) && segment >= 0 ? segment : null;
    if (s === this.segment) return;
    this.segment = s;
    this.signals.segmentChanged.dispatch(s);
  }

  setTool(tool) {
    const t = TOOLS.includes(tool) ? tool : null;
    if (t === this.tool) return;
    this.tool = t;
    this.signals.toolChanged.dispatch(t);
  }

  setInfo(info) {
    this.info = info;
    // a segment id of the previous segmentation means nothing in a new one
    if (!info?.segmented || (this.segment !== null && this.segment >= (info.segment_ids ?? info.segments ?? 0))) this.setSegment(null);
    this.signals.infoChanged.dispatch(info);
  }

  // --- ops ------------------------------------------------------------------------------------
  // box: [x0, y0, z0, x1, y1, z1] in model coordinates. Resolve with the new version or null.
  segmentRoi(box) {
    return this.editor.execute({ kind: OP.segment_roi, box });
  }

  markTemplate(box) {
    if (this.segment === null) {
      this.editor.fail({ title: 'No segment picked', detail: 'click a point of the segment the template is in first' });
      return Promise.resolve(null);
    }
    return this.editor.execute({ kind: OP.mark_template, segment: this.segment, box });
  }
}
