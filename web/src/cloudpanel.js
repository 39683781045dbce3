// The point cloud panel, shown while a point cloud model is open: how many points are drawn
// of how many, colour by segment or label, the point budget, the segment job, the picked
// segment, and the ROI and template box tools (editors only). Once the cloud is proceduralized
// it chooses between the points its grammar derives (edited with the edit panel's tools) and
// the uploaded ones (refined with the boxes).
import { COLOUR_MODES, VIEWS, isCloud } from './cloud.js';
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
    const viewText = { derived: 'show: derived points', input: 'show: uploaded points' };
    this.view = el(
      'select',
      { 'data-testid': 'cloud-view', title: 'Which points to draw: those the grammar derives, or those uploaded', 'aria-label': 'Points shown' },
      ...VIEWS.map((v) => el('option', { value: v }, viewText[v])),
    );
    this.view.addEventListener('change', () => this.cloud.setView(this.view.value));
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
    this.procTemplateBtn = el('button', { type: 'button', 'data-testid': 'cloud-proc-template', title: 'Drag a box around one window (or other repeated element): Proceduralize finds its copies' }, 'Template for Proceduralize');
    this.procTemplateBtn.addEventListener('click', () => this.cloud.setTool(this.cloud.tool === 'procTemplate' ? null : 'procTemplate'));
    this.procTemplates = el('span.cloud-proc-templates', { 'data-testid': 'cloud-proc-templates' });
    this.clearTemplatesBtn = el('button', { type: 'button', 'data-testid': 'cloud-proc-templates-clear', title: 'Forget the template boxes' }, 'Clear');
    this.clearTemplatesBtn.addEventListener('click', () => this.cloud.clearProcTemplates());
    this.picked = el('div.picked', { 'data-testid': 'cloud-picked' });
    this.jobText = el('div.job-text', { 'data-testid': 'cloud-job' });

    container.append(
      el('h2', {}, 'Point cloud'),
      this.shown,
      this.figures,
      el('div.proc-actions', {}, this.colour, this.budget, presets),
      el('div.proc-actions', {}, this.view),
      el('div.proc-actions', {}, this.segmentBtn, this.roiBtn, this.templateBtn),
      el('div.proc-actions', {}, this.procTemplateBtn, this.procTemplates, this.clearTemplatesBtn),
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
    for (const sig of [c.colourChanged, c.budgetChanged, c.segmentChanged, c.toolChanged, c.infoChanged, c.viewChanged, c.procTemplatesChanged]) sig.add(() => this.render());
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
    const derived = !!info?.derived;
    this.shown.textContent = info ? `${fmt(info.drawn)} of ${fmt(total)} ${derived ? 'derived ' : ''}points drawn` : 'Loading points…';
    this.shown.dataset.of = derived ? 'derived' : 'input';
    this.shown.dataset.drawn = String(info?.drawn ?? 0);
    const segmented = !!(derived ? ed.model.stats?.segmented : info?.segmented ?? ed.model.stats?.segmented);
    this.figures.textContent = derived
      ? `${fmt(info.segments)} placements · ${fmt(info.labels)} terminals`
      : segmented
        ? `${fmt(info?.segments ?? ed.model.stats?.segments)} segments · ${fmt(info?.labels ?? ed.model.stats?.labels)} labels`
        : 'not segmented';
    this.view.hidden = !ed.model.proceduralized;
    this.view.value = cloud.view;
    this.colour.value = cloud.colourBy;
    if (document.activeElement !== this.budget) this.budget.value = String(cloud.budget);
    const edit = ed.canEdit;
    const running = !!this.job && !finished(this.job);
    this.segmentBtn.hidden = !edit;
    this.roiBtn.hidden = !edit;
    this.templateBtn.hidden = !edit;
    this.segmentBtn.disabled = running;
    // the boxes refine the uploaded points' segmentation
    this.roiBtn.disabled = !segmented || derived;
    this.templateBtn.disabled = !segmented || derived || cloud.segment === null;
    this.procTemplateBtn.hidden = !edit;
    this.procTemplateBtn.disabled = derived || !info;
    this.procTemplateBtn.classList.toggle('on', cloud.tool === 'procTemplate');
    const nt = cloud.procTemplates.length;
    this.procTemplates.textContent = nt ? `${nt} template box${nt === 1 ? '' : 'es'} for Proceduralize` : '';
    this.procTemplates.dataset.count = String(nt);
    this.clearTemplatesBtn.hidden = !edit || !nt;
    this.roiBtn.classList.toggle('on', cloud.tool === 'roi');
    this.templateBtn.classList.toggle('on', cloud.tool === 'template');
    this.picked.textContent = derived
      ? 'Click a point to select its node (Shift+click: several)'
      : cloud.segment === null
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
