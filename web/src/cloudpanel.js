// The point cloud panel, shown while a point cloud model is open: how many points are drawn
// of how many, colour by segment or label, the point budget, the segment job, the picked
// segment, and the ROI and template box tools (editors only).
import { COLOUR_MODES, isCloud } from './cloud.js';
import { el } from './dom.js';
import { finished, followJob } from './jobs.js';

const BUDGETS = [10000, 100000, 300000, 1000000, 3000000];

export class CloudPanel {
  constructor(editor, api, live, container) {
    this.editor = editor;
    this.api = api;
    this.live = live;
    this.cloud = editor.cloud;
    this.container = container;
    this.job = null;

    this.shown = el('div.cloud-shown', { 'data-testid': 'cloud-shown' });
    this.figures = el('div.cloud-figures', { 'data-testid': 'cloud-figures' });
    this.colour = el(
      'select',
      { 'data-testid': 'cloud-colour', title: 'Colour the points by', 'aria-label': 'Colour by' },
      ...COLOUR_MODES.map((m) => el('option', { value: m }, `colour: ${m}`)),
    );
    this.colour.addEventListener('change', () => this.cloud.setColourBy(this.colour.value));
    this.budget = el('input.num', {
      type: 'number', min: 1, step: 1, 'data-testid': 'cloud-budget', title: 'Point budget: how many points to draw',
      'aria-label': 'Point budget', list: 'cloud-budgets',
    });
    const presets = el('datalist', { id: 'cloud-budgets' }, ...BUDGETS.map((b) => el('option', { value: b })));
    this.budget.addEventListener('change', () => this.cloud.setBudget(this.budget.value));
    this.segmentBtn = el('button', { type: 'button', 'data-testid': 'cloud-segment', title: 'Segment the cloud into planes and clusters (a job)' }, 'Segment');
    this.segmentBtn.addEventListener('click', () => this.runSegment());
    this.roiBtn = el('button', { type: 'button', 'data-testid': 'cloud-roi', title: 'Drag a box: the points in it are segmented again, finer' }, 'ROI box');
    this.roiBtn.addEventListener('click', () => this.cloud.setTool(this.cloud.tool === 'roi' ? null : 'roi'));
    this.templateBtn = el('button', { type: 'button', 'data-testid': 'cloud-template', title: 'Drag a box on the picked segment: a template, its copies labelled with it' }, 'Template box');
    this.templateBtn.addEventListener('click', () => this.cloud.setTool(this.cloud.tool === 'template' ? null : 'template'));
    this.picked = el('div.picked', { 'data-testid': 'cloud-picked' });
    this.jobText = el('div.job-text', { 'data-testid': 'cloud-job' });

    container.append(
      el('h2', {}, 'Point cloud'),
      this.shown,
      this.figures,
      el('div.proc-actions', {}, this.colour, this.budget, presets),
      el('div.proc-actions', {}, this.segmentBtn, this.roiBtn, this.templateBtn),
      this.picked,
      this.jobText,
    );
    container.hidden = true;

    const s = editor.signals;
    s.modelOpened.add(() => {
      this.job = null;
      this.render();
    });
    s.modelChanged.add(() => this.render());
    s.roleChanged.add(() => this.render());
    s.pointsChanged.add(() => this.refreshFigures());
    const c = this.cloud.signals;
    for (const sig of [c.colourChanged, c.budgetChanged, c.segmentChanged, c.toolChanged, c.infoChanged]) sig.add(() => this.render());
    this.render();
  }

  render() {
    const ed = this.editor;
    const cloud = this.cloud;
    this.container.hidden = !isCloud(ed.model);
    if (this.container.hidden) return;
    const info = cloud.info;
    const fmt = (n) => (typeof n === 'number' ? n.toLocaleString('en') : '–');
    const total = info?.points ?? ed.model.stats?.points;
    this.shown.textContent = info ? `${fmt(info.drawn)} of ${fmt(total)} points drawn` : 'Loading points…';
    this.shown.dataset.drawn = String(info?.drawn ?? 0);
    const segmented = !!(info?.segmented ?? ed.model.stats?.segmented);
    this.figures.textContent = segmented
      ? `${fmt(info?.segments ?? ed.model.stats?.segments)} segments · ${fmt(info?.labels ?? ed.model.stats?.labels)} labels`
      : 'not segmented';
    this.colour.value = cloud.colourBy;
    if (document.activeElement !== this.budget) this.budget.value = String(cloud.budget);
    const edit = ed.canEdit;
    const running = !!this.job && !finished(this.job);
    this.segmentBtn.hidden = !edit;
    this.roiBtn.hidden = !edit;
    this.templateBtn.hidden = !edit;
    this.segmentBtn.disabled = running;
    this.roiBtn.disabled = !segmented;
    this.templateBtn.disabled = !segmented || cloud.segment === null;
    this.roiBtn.classList.toggle('on', cloud.tool === 'roi');
    this.templateBtn.classList.toggle('on', cloud.tool === 'template');
    this.picked.textContent = cloud.segment === null
      ? (segmented ? 'Click a point to pick its segment' : '')
      : `segment ${cloud.segment}`;
    this.picked.classList.toggle('none', cloud.segment === null);
    const j = this.job;
    this.jobText.textContent = j ? `segment: ${j.status}${j.stage ? ` · ${j.stage}` : ''}${finished(j) ? '' : ` ${Math.round((j.progress ?? 0) * 100)} %`}` : '';
    if (j) this.jobText.dataset.status = j.status;
    else delete this.jobText.dataset.status;
  }

  // The model's figures (segments, labels) after its segmentation changed.
  async refreshFigures() {
    const ed = this.editor;
    const id = ed.model?.id;
    if (id == null) return;
    try {
      const fresh = await this.api.getModel(id);
      if (ed.model?.id === id) ed.updateModel(fresh);
    } catch (err) {
      ed.fail(err);
    }
  }

  // Starts the segment job on the version on screen and follows it; its segment op (over the
  // websocket, or read from the op log) makes the view load the segmented points.
  async runSegment() {
    const ed = this.editor;
    if (!ed.model || !ed.canEdit) return;
    const { id, version } = ed.model;
    const mine = () => ed.model?.id === id;
    const show = (j) => {
      if (!mine()) return;
      this.job = j;
      this.render();
    };
    show({ status: 'queued', progress: 0, stage: null });
    let job;
    try {
      job = await this.api.segment(id, version);
    } catch (err) {
      show({ status: 'failed', progress: 0, stage: null });
      ed.fail(err);
      return;
    }
    show(job);
    const done = await followJob(ed, this.api, this.live, job, show);
    show(done);
    if (!mine()) return;
    if (done.status === 'succeeded') {
      try {
        const page = await this.api.getOps(id, ed.model.version);
        if (mine()) this.live.applyOps(page.items || []);
      } catch (err) {
        ed.fail(err);
      }
    } else if (done.status === 'failed') {
      ed.fail(done.error || { title: 'Segmentation failed', detail: ed.model.name });
    }
  }
}
