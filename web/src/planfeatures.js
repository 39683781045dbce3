// The plan edits panel of the edited building: the step tool (natural or forced, height,
// width, depth, profile; the step is placed by clicking an edge in the plan editor), "Add
// offset", and one row per step and per offset event. Typing in a row's field previews the
// change; leaving the field (or Enter) commits it as a plan op, Escape goes back. An offset
// event's "leave edges out" button makes clicks on plan edges take them out of the event.
// Also the plan's rule for collinear neighbours whose priority tags are equal.
import { el } from './dom.js';
import { clone, parsePoints, pointsText, profilePoints, resizeForced, stepKind, withItem, withoutItem } from './plandoc.js';

const num = (attrs) => el('input.num', { type: 'number', step: '0.1', ...attrs });

export class PlanFeatures {
  constructor(editor, container) {
    this.editor = editor;
    this.ext = editor.extrusion;
    const ext = this.ext;
    this.typing = false; // a field is being edited: the rows are not redrawn under the caret
    this.container = container;

    const tool = ext.stepTool;
    this.stepBtn = el('button', { type: 'button', 'data-testid': 'step-mode', title: 'Click an edge of the plan to place a step there' }, 'Add step');
    this.stepBtn.addEventListener('click', () => ext.setTool('step'));
    this.kind = el(
      'select',
      { 'data-testid': 'new-step-kind', title: 'Natural: a rectangle grown out of (or into) the plan at its height; forced: a polygon united with the plan as it is there' },
      el('option', { value: 'natural' }, 'natural'),
      el('option', { value: 'forced' }, 'forced'),
    );
    this.height = num({ min: '0.1', value: String(tool.height), 'data-testid': 'new-step-height', title: 'Height of the step (m)' });
    this.width = num({ min: '0.01', value: String(tool.width), 'data-testid': 'new-step-width', title: 'Width along the edge (m)' });
    this.depth = num({ value: String(tool.depth), 'data-testid': 'new-step-depth', title: 'Depth (m): natural, > 0 outwards and < 0 a recess; forced, the square’s extent across the edge' });
    this.profile = el('select', { 'data-testid': 'new-step-profile', title: 'Profile of the step’s new edges' });
    const settings = () => {
      ext.setStepTool({
        kind: this.kind.value,
        height: Number(this.height.value),
        width: Number(this.width.value),
        depth: Number(this.depth.value),
        profile: this.profile.value || null,
      });
    };
    for (const c of [this.kind, this.height, this.width, this.depth, this.profile]) c.addEventListener('input', settings);
    for (const c of [this.kind, this.profile]) c.addEventListener('change', settings);
    this.offsetBtn = el('button', { type: 'button', 'data-testid': 'add-offset', title: 'Add an offset event: at its height every edge moves out (or in) in one step' }, 'Add offset');
    this.offsetBtn.addEventListener('click', () => this.addOffset());
    this.scheme = el(
      'select',
      { 'data-testid': 'priority-scheme', title: 'Where collinear neighbours with equal priority tags meet, keep the plane that encloses the most (max volume) or the least (min volume)' },
      el('option', { value: 'max_volume' }, 'ties: max volume'),
      el('option', { value: 'min_volume' }, 'ties: min volume'),
    );
    this.scheme.addEventListener('change', () => this.setScheme(this.scheme.value));
    this.list = el('ul.plan-features', { 'data-testid': 'plan-features' });
    this.body = el('div.plan-edits',
      {},
      el('div.edit-row', {}, this.stepBtn, this.kind, this.profile),
      el('div.edit-row', {},
        el('label', {}, 'at ', this.height, ' m'),
        el('label', {}, 'w ', this.width),
        el('label', {}, 'd ', this.depth)),
      el('div.edit-row', {}, this.offsetBtn, this.scheme),
      this.list);
    container.append(el('h2', {}, 'Plan edits'), this.body);
    container.hidden = true;

    const s = ext.signals;
    s.docChanged.add(() => this.render());
    s.draftChanged.add(() => this.render());
    s.toolChanged.add(() => this.renderMarks());
    s.featureChanged.add(() => this.renderMarks());
    this.render();
  }

  get plan() {
    return this.ext.draft;
  }

  // An offset event at the eave (the lowest bend of the profiles), half a metre out; its
  // height is moved up where a profile, another event or a step has that height already.
  addOffset() {
    const plan = this.plan;
    if (!plan) return;
    const profiles = Object.values(plan.profiles || {}).map(profilePoints);
    const bends = profiles.flatMap((pts) => pts.slice(1, -1).map((p) => p[1])).filter((z) => z > 0);
    let height = bends.length ? Math.min(...bends) : 3;
    const taken = (h) =>
      profiles.some((pts) => pts.some((p, i) => i + 1 < pts.length && p[1] === h && pts[i + 1][1] === h)) ||
      (plan.offsets || []).some((o) => o.height === h) ||
      (plan.steps || []).some((st) => st.height === h);
    while (taken(height)) height += 0.5;
    const index = plan.offsets?.length ?? 0;
    this.commit(withItem(plan, 'offsets', index, { height, outside: 0.5 }), { kind: 'offset', index });
  }

  setScheme(scheme) {
    const draft = clone(this.plan);
    if (scheme === 'min_volume') draft.priority = scheme;
    else delete draft.priority; // max_volume is the default
    this.commit(draft);
  }

  // Commits a changed description as a plan op; `feature` (when given) is selected with it.
  commit(draft, feature) {
    this.ext.setDraft(draft);
    if (feature !== undefined) this.ext.selectFeature(feature);
    this.ext.commitPlan(draft);
  }

  // --- rows -----------------------------------------------------------------------------------
  render() {
    const ext = this.ext;
    const plan = this.plan;
    this.container.hidden = !ext.active || !ext.doc;
    const names = Object.keys(plan?.profiles || {});
    for (const c of [this.stepBtn, this.kind, this.height, this.width, this.depth, this.profile, this.offsetBtn, this.scheme]) c.disabled = !plan;
    this.scheme.value = plan?.priority === 'min_volume' ? 'min_volume' : 'max_volume';
    const chosen = ext.stepTool.profile;
    this.profile.replaceChildren(...names.map((n) => el('option', { value: n }, n)));
    this.profile.value = names.includes(chosen) ? chosen : names[names.length - 1] ?? '';
    ext.setStepTool({ profile: this.profile.value || null });
    if (this.typing) return; // the row being typed in stays as it is
    const f = ext.feature;
    if (f && !plan?.[f.kind === 'step' ? 'steps' : 'offsets']?.[f.index]) ext.selectFeature(null);
    this.list.replaceChildren(
      ...(plan?.steps || []).map((st, i) => this.stepRow(st, i, names)),
      ...(plan?.offsets || []).map((o, i) => this.offsetRow(o, i, names)),
    );
    if (plan && !this.list.children.length) this.list.append(el('li.empty', {}, 'No steps or offset events'));
    this.renderMarks();
  }

  // What is selected and which tool is on, without redrawing the rows (a press on a row's
  // button selects the row and must still reach the button).
  renderMarks() {
    const { tool, feature } = this.ext;
    this.stepBtn.classList.toggle('on', tool === 'step');
    for (const li of this.list.querySelectorAll('li.plan-feature')) {
      const on = li.dataset.kind === feature?.kind && Number(li.dataset.index) === feature?.index;
      li.classList.toggle('selected', on);
      li.querySelector('[data-testid="offset-edges"]')?.classList.toggle('on', on && tool === 'offset');
    }
  }

  rowOf(kind, index, testid, lines) {
    const li = el('li.plan-feature', { 'data-testid': testid, dataset: { index, kind } }, ...lines.map((l) => el('div.feature-line', {}, ...l)));
    li.addEventListener('pointerdown', () => this.ext.selectFeature({ kind, index }));
    return li;
  }

  stepRow(st, i, names) {
    const kind = stepKind(st);
    const where = typeof st.edge === 'number'
      ? `edge ${st.edge}${(st.loop ?? 0) ? ` of loop ${st.loop}` : ''} at ${typeof st.relative === 'number' ? `${Math.round(st.relative * 100)}%` : `${st.absolute} m`}`
      : 'in plan coordinates';
    const lines = [[
      el('span.feature-kind', { title: st.name ?? '' }, `${kind} step`),
      el('span.feature-where', {}, where),
      el('span.spacer'),
      this.removeButton('step-remove', 'steps', i),
    ], [
      el('label', {}, 'at ', this.field('step-height', st.height, (v) => (v > 0 ? { height: v } : null), 'steps', i), ' m'),
      this.choice('step-profile', st.profile, names, null, (v) => ({ profile: v }), 'steps', i),
    ]];
    if (kind === 'natural') {
      lines.push([
        el('label', {}, 'w ', this.field('step-width', st.width, (v) => (v >= 0.002 ? { width: v } : null), 'steps', i)),
        el('label', {}, 'd ', this.field('step-depth', st.depth, (v) => (Math.abs(v) >= 0.002 ? { depth: v } : null), 'steps', i)),
      ]);
    } else {
      if (isCentredRectangle(st.points)) {
        const w = st.points[1][0] - st.points[0][0];
        const d = st.points[2][1] - st.points[1][1];
        lines.push([
          el('label', {}, 'w ', this.field('step-width', w, (v) => (v >= 0.002 ? resizeForced(st, v, d) : null), 'steps', i)),
          el('label', {}, 'd ', this.field('step-depth', d, (v) => (v >= 0.002 ? resizeForced(st, w, v) : null), 'steps', i)),
        ]);
      }
      lines.push([el('label.wide', {}, 'corners ', this.field('step-points', pointsText(st.points), (text) => {
        const points = parsePoints(text);
        return points ? { points } : null;
      }, 'steps', i, { text: true }))]);
    }
    return this.rowOf('step', i, 'step-row', lines);
  }

  offsetRow(o, i, names) {
    const left = (o.edges || []).filter((e) => e.disabled).length;
    const edgesBtn = el('button', {
      type: 'button',
      'data-testid': 'offset-edges',
      title: 'Click edges of the plan to leave them out of this offset event (a gable end); again to put them back',
    }, left ? `${left} edge${left === 1 ? '' : 's'} left out` : 'leave edges out');
    edgesBtn.addEventListener('click', () => {
      const ext = this.ext;
      const on = ext.tool === 'offset' && ext.feature?.kind === 'offset' && ext.feature.index === i;
      ext.selectFeature({ kind: 'offset', index: i });
      ext.setTool(on ? null : 'offset');
    });
    return this.rowOf('offset', i, 'offset-row', [[
      el('span.feature-kind', {}, 'offset event'),
      el('span.spacer'),
      this.removeButton('offset-remove', 'offsets', i),
    ], [
      el('label', {}, 'at ', this.field('offset-height', o.height, (v) => (v > 0 ? { height: v } : null), 'offsets', i), ' m'),
      el('label', {}, 'out ', this.field('offset-outside', o.outside ?? 0, (v) => (Number.isFinite(v) ? { outside: v } : null), 'offsets', i), ' m'),
    ], [
      el('label', {}, 'then ', this.choice('offset-profile', o.profile ?? '', names, 'own', (v) => ({ profile: v || null }), 'offsets', i)),
      el('label', {}, 'side ', this.choice('offset-side', o.side ?? '', names, 'none', (v) => ({ side: v || null }), 'offsets', i)),
    ], [edgesBtn]]);
  }

  // A field of item i of `key`. fields(value) gives the changed members, or null when the
  // value is not usable (nothing is previewed or committed then).
  field(testid, value, fields, key, i, { text = false } = {}) {
    const input = text
      ? el('input.text', { type: 'text', value: String(value ?? ''), 'data-testid': testid, spellcheck: false })
      : num({ value: String(value ?? ''), 'data-testid': testid });
    const changed = () => {
      const v = fields(text ? input.value : input.value.trim() === '' ? NaN : Number(input.value));
      return v && this.plan?.[key]?.[i] ? withItem(this.plan, key, i, v) : null;
    };
    input.addEventListener('input', () => {
      const draft = changed();
      if (!draft) return;
      this.typing = true;
      this.ext.edit(draft);
    });
    input.addEventListener('change', () => {
      this.typing = false;
      const draft = changed();
      if (draft) this.commit(draft);
      else this.ext.revert();
    });
    input.addEventListener('blur', () => {
      if (!this.typing) return;
      this.typing = false; // left as it was after a preview
      this.ext.revert();
    });
    input.addEventListener('keydown', (e) => {
      if (e.key === 'Enter') {
        e.preventDefault();
        input.blur(); // change, then commit
      } else if (e.key === 'Escape') {
        this.typing = false;
        input.value = String(value ?? '');
        this.ext.revert();
      }
    });
    return input;
  }

  // A choice of profile (with an empty option named `none` when the member may be left out).
  choice(testid, value, names, none, fields, key, i) {
    const sel = el(
      'select',
      { 'data-testid': testid },
      ...(none ? [el('option', { value: '' }, `(${none})`)] : []),
      ...names.map((n) => el('option', { value: n }, n)),
    );
    sel.value = value ?? '';
    sel.addEventListener('change', () => this.commit(withItem(this.plan, key, i, fields(sel.value))));
    return sel;
  }

  removeButton(testid, key, i) {
    const b = el('button.remove', { type: 'button', 'data-testid': testid, title: 'Remove' }, '×');
    b.addEventListener('click', () => this.commit(withoutItem(this.plan, key, i), null));
    return b;
  }
}

// The rectangle centred on its anchor that the step tool makes for a forced step.
function isCentredRectangle(points) {
  if (!Array.isArray(points) || points.length !== 4) return false;
  const [a, b, c, d] = points;
  return a[0] === -b[0] && a[0] === d[0] && b[0] === c[0] && a[1] === b[1] && c[1] === d[1] && a[1] === -c[1] && b[0] > a[0] && c[1] > b[1];
}
