// The open point cloud model, as the editor's sub-editor: how its points are coloured (by
// segment or by label), how many of them to show (the budget of GET …/points.glb), the
// segment picked, the tool a box drag in the view makes (an ROI to segment again, a template
// on the picked segment), and what the last points.glb said of itself (its node's extras).
// Ops go through editor.execute like every other; the segment job through Api.segment.
import { OP } from './opkinds.js';
import { Signal } from './signal.js';

export const COLOUR_MODES = ['segment', 'label'];
export const DEFAULT_BUDGET = 1000000;
export const MAX_BUDGET = 100000000; // what the server takes (api_points.c)
export const TOOLS = ['roi', 'template'];

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
    };
    this.colourBy = 'segment';
    this.budget = DEFAULT_BUDGET;
    this.segment = null;
    this.tool = null;
    // {model, points, shown, budget, offset, segmented, segments, labels} of what is on screen
    this.info = null;
    editor.signals.modelOpened.add(() => this.reset());
    // segments are renumbered by every segmentation: a picked id would name another segment
    editor.signals.pointsChanged.add(() => this.setSegment(null));
  }

  get active() {
    return isCloud(this.editor.model);
  }

  reset() {
    this.setSegment(null);
    this.setTool(null);
    this.setInfo(null);
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
    if (!info?.segmented || (this.segment !== null && this.segment >= (info.segments ?? 0))) this.setSegment(null);
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
