// The split-tree panel: the Proceduralize button and its job's stages, the label legend, the
// expandable tree of nodes and the selected node's details. Selecting a node selects its
// geometry; a component picked in the viewport is revealed here (both through the editor).
import { isCloud } from './cloud.js';
import { el } from './dom.js';
import { boxSize, nodeTitle } from './splittree.js';

const STAGES = ['segment', 'label', 'tree', 'rules', 'patterns', 'export', 'verify'];
// a point cloud's pipeline (server/app/cloud_pipeline.c)
const CLOUD_STAGES = ['segment', 'repeat', 'absorb', 'consensus', 'tree', 'grammar', 'verify'];
const OPEN_DEPTH = 2; // levels shown expanded when a tree arrives
const MAX_CHILDREN = 500; // children listed under one node; the rest are summarised

export class SplitTreePanel {
  constructor(editor, procedural, container) {
    this.editor = editor;
    this.procedural = procedural;
    this.expanded = new Set();
    this.rows = new Map(); // node id -> row element of the current rendering

    this.run = el('button.primary', { type: 'button', 'data-testid': 'proceduralize' }, 'Proceduralize');
    this.run.addEventListener('click', () => procedural.run());
    this.cancel = el('button', { type: 'button', 'data-testid': 'proc-cancel', hidden: true }, 'Cancel');
    this.cancel.addEventListener('click', () => procedural.cancel());

    this.bar = el('div.bar-fill');
    this.stages = el('ol.stages');
    this.jobText = el('div.job-text');
    this.job = el('div.job', { 'data-testid': 'proc-job', hidden: true }, el('div.bar', {}, this.bar), this.stages, this.jobText);

    this.legend = el('ul.legend', { 'data-testid': 'label-legend' });
    this.empty = el('div.empty', {}, '');
    this.list = el('ul.tree', { 'data-testid': 'split-tree', role: 'tree' });
    this.details = el('dl.node-details', { 'data-testid': 'node-details' });

    container.append(
      el('h2', {}, 'Split tree'),
      el('div.proc-actions', {}, this.run, this.cancel),
      this.job,
      this.legend,
      this.empty,
      this.list,
      this.details,
    );

    const s = editor.signals;
    s.modelOpened.add(() => this.renderActions());
    s.roleChanged.add(() => this.renderActions());
    s.modelChanged.add(() => this.renderActions());
    s.procJobChanged.add(() => {
      this.renderJob();
      this.renderActions();
    });
    s.treeChanged.add((tree) => {
      this.expanded.clear();
      if (tree) this.expandTo(tree.root, OPEN_DEPTH);
      this.render();
    });
    s.selectionChanged.add(() => this.reveal());
    this.renderActions();
    this.renderJob();
    this.render();
  }

  renderActions() {
    const ed = this.editor;
    const running = this.procedural.running;
    this.run.disabled = !ed.model || running;
    this.run.hidden = !ed.model || !ed.canEdit;
    this.run.textContent = ed.model?.proceduralized ? 'Proceduralize again' : 'Proceduralize';
    this.cancel.hidden = !running || !ed.procJob?.id;
  }

  renderJob() {
    const job = this.editor.procJob;
    if (!job) {
      this.job.hidden = true;
      return;
    }
    this.job.hidden = false;
    const done = ['succeeded', 'failed', 'cancelled'].includes(job.status);
    const p = Math.max(0, Math.min(1, job.progress ?? 0));
    this.bar.style.width = `${Math.round((job.status === 'succeeded' ? 1 : p) * 100)}%`;
    this.job.className = `job ${job.status}`;
    this.job.dataset.status = job.status;
    this.job.dataset.stage = job.stage ?? '';
    const stages = isCloud(this.editor.model) ? CLOUD_STAGES : STAGES;
    const at = stages.indexOf(job.stage);
    this.stages.replaceChildren(
      ...stages.map((name, i) => {
        let state = 'pending'; // a stage not reached yet
        if (job.status === 'succeeded' || i < at) state = 'done';
        else if (i === at) state = done ? job.status : 'now';
        return el('li', { className: `stage ${state}`, dataset: { stage: name } }, name);
      }),
    );
    const pct = done ? '' : ` ${Math.round(p * 100)}%`;
    this.jobText.textContent = `proceduralize — ${job.status}${job.stage ? ` · ${job.stage}` : ''}${pct}`;
  }

  // --- the tree -----------------------------------------------------------------------------
  expandTo(id, depth) {
    const tree = this.editor.tree;
    const n = tree?.node(id);
    if (!n || depth <= 0 || !n.children?.length) return;
    this.expanded.add(id);
    for (const c of n.children) this.expandTo(c, depth - 1);
  }

  render() {
    const ed = this.editor;
    const tree = ed.tree;
    this.rows.clear();
    this.legend.replaceChildren(
      ...(tree?.labels || []).map((l) =>
        el(
          'li.chip',
          { dataset: { label: l.label }, title: `${l.count} instance${l.count === 1 ? '' : 's'} of ${l.label}` },
          el('span.swatch', { style: `background:${l.color}` }),
          `${l.label} ×${l.count}`,
        ),
      ),
    );
    this.legend.hidden = !tree;
    if (!tree) {
      this.list.replaceChildren();
      this.list.hidden = true;
      this.empty.hidden = !ed.model;
      this.empty.textContent = ed.model ? 'Not proceduralized yet.' : '';
      this.renderDetails();
      return;
    }
    this.empty.hidden = true;
    this.list.hidden = false;
    this.list.replaceChildren(this.item(tree.root, 0));
    this.mark();
    this.renderDetails();
  }

  item(id, depth) {
    const tree = this.editor.tree;
    const n = tree.node(id);
    if (!n) return el('li.node.missing', {}, `node ${id} missing`);
    const kids = n.children || [];
    const open = this.expanded.has(id);
    const toggle = el(
      'button.toggle',
      { type: 'button', tabIndex: -1, 'aria-label': open ? 'Collapse' : 'Expand', hidden: !kids.length },
      open ? '▾' : '▸',
    );
    toggle.addEventListener('click', (e) => {
      e.stopPropagation();
      if (this.expanded.has(id)) this.expanded.delete(id);
      else this.expanded.add(id);
      this.render();
    });
    const colour = n.label ? tree.colourOf(n.label) : null;
    const row = el(
      'div.row',
      {
        tabIndex: 0,
        role: 'treeitem',
        'data-testid': 'tree-node',
        dataset: { node: id, kind: n.kind },
        style: `padding-left:${depth * 12 + 2}px`,
        title: `node ${id}`,
        // Shift+click adds to the selection (join, copy, remove work on several nodes)
        onclick: (e) => (e.shiftKey ? this.editor.selected.toggle(id) : this.editor.selected.node(id)),
        onkeydown: (e) => this.key(e, id),
      },
      kids.length ? toggle : el('span.toggle-space'),
      el(`span.kind.${n.kind}`, {}, nodeTitle(n)),
      n.label ? el('span.node-label', { style: colour ? `border-color:${colour}` : null }, n.label) : '',
      kids.length ? el('span.count', {}, String(kids.length)) : '',
    );
    if (open) row.setAttribute('aria-expanded', 'true');
    else if (kids.length) row.setAttribute('aria-expanded', 'false');
    this.rows.set(id, row);
    const li = el('li.node', {}, row);
    if (open && kids.length) {
      const shown = kids.slice(0, MAX_CHILDREN).map((c) => this.item(c, depth + 1));
      if (kids.length > MAX_CHILDREN) {
        shown.push(el('li.empty', { style: `padding-left:${(depth + 1) * 12 + 14}px` }, `${kids.length - MAX_CHILDREN} more`));
      }
      li.append(el('ul', { role: 'group' }, shown));
    }
    return li;
  }

  key(e, id) {
    const n = this.editor.tree?.node(id);
    if (!n) return;
    if (e.key === 'Enter' || e.key === ' ') {
      e.preventDefault();
      this.editor.selected.node(id);
    } else if (e.key === 'ArrowRight' && n.children?.length && !this.expanded.has(id)) {
      this.expanded.add(id);
      this.render();
      this.rows.get(id)?.focus();
    } else if (e.key === 'ArrowLeft' && this.expanded.has(id)) {
      this.expanded.delete(id);
      this.render();
      this.rows.get(id)?.focus();
    }
  }

  selectedNode() {
    const sel = this.editor.selection;
    return sel && sel.node !== undefined && sel.node !== null ? sel.node : null;
  }

  // Marks the selected nodes' rows.
  mark() {
    const ids = new Set(this.editor.selected.nodeIds());
    for (const [nid, row] of this.rows) {
      const on = ids.has(nid);
      row.classList.toggle('selected', on);
      row.setAttribute('aria-selected', on ? 'true' : 'false');
    }
  }

  // A new selection: open the way to its node, mark it and scroll it into view.
  reveal() {
    const tree = this.editor.tree;
    const id = this.selectedNode();
    if (tree && id !== null && tree.node(id)) {
      const hidden = tree.ancestors(id).filter((a) => !this.expanded.has(a));
      if (hidden.length || !this.rows.has(id)) {
        for (const a of hidden) this.expanded.add(a);
        this.render();
      }
      this.mark();
      this.rows.get(id)?.scrollIntoView({ block: 'nearest' });
    } else {
      this.mark();
    }
    this.renderDetails();
  }

  renderDetails() {
    const tree = this.editor.tree;
    const id = this.selectedNode();
    const n = tree && id !== null ? tree.node(id) : null;
    if (!n) {
      this.details.replaceChildren();
      this.details.hidden = true;
      return;
    }
    this.details.hidden = false;
    const rows = [
      ['node', `${n.id} · ${n.kind}${n.visible ? ' · visible' : ''}`],
      ['rule', n.rule ?? '—'],
      ['label', n.label ?? '—'],
      ['size', boxSize(n.box)],
    ];
    if (n.terminal) rows.push(['terminal', n.terminal]);
    if (typeof n.component === 'number') rows.push(['component', String(n.component)]);
    if (n.pattern) {
      const p = n.pattern;
      if (p.counts) rows.push(['pattern', p.counts.join(' × ')]);
      if (p.step) rows.push(['step', `${p.step.map((v) => Number(v).toFixed(2)).join(', ')} m`]);
      if (p.vectors) rows.push(['vectors', String(p.vectors.length)]);
    }
    const applied = n.rule ? tree.rules.find((r) => r.name === n.rule) : null;
    if (applied) rows.push(['applied', `${applied.instances}×`]);
    this.details.replaceChildren(
      ...rows.flatMap(([k, v]) => [el('dt', {}, k), el('dd', { dataset: { field: k } }, v)]),
    );
  }
}
