// The inspector: the picked component and the open model's figures.
import { el } from './dom.js';

export class Inspector {
  constructor(editor, container) {
    this.editor = editor;
    this.picked = el('div.picked', { 'data-testid': 'picked-component' });
    this.stats = el('dl.stats');
    container.append(el('h2', {}, 'Inspector'), this.picked, this.stats);
    editor.signals.selectionChanged.add(() => this.renderPick());
    editor.signals.modelOpened.add(() => this.render());
    editor.signals.modelChanged.add(() => this.render());
    editor.signals.treeChanged.add(() => this.renderPick());
    this.render();
  }

  render() {
    this.renderPick();
    const m = this.editor.model;
    const st = m?.stats;
    if (!st) {
      this.stats.replaceChildren();
      return;
    }
    const fmt = (n) => (typeof n === 'number' ? n.toLocaleString() : '–');
    const size = st.bounds
      ? st.bounds.max.map((v, i) => (v - st.bounds.min[i]).toFixed(2)).join(' × ') + ' m'
      : '–';
    const rows = typeof st.points === 'number' ? [
      ['points', fmt(st.points)],
      ['properties', (st.properties || []).map((p) => p.name).join(', ') || '–'],
      ['segments', st.segmented ? fmt(st.segments) : 'not segmented'],
      ['size', size],
    ] : [
      ['vertices', fmt(st.vertices)],
      ['triangles', fmt(st.triangles)],
      ['components', fmt(st.components)],
      ['groups', fmt(st.groups)],
      ['size', size],
    ];
    this.stats.replaceChildren(...rows.flatMap(([k, v]) => [el('dt', {}, k), el('dd', {}, v)]));
  }

  renderPick() {
    const sel = this.editor.selection;
    if (!this.editor.model) {
      this.picked.textContent = '';
      this.picked.classList.add('none');
    } else if (!sel) {
      this.picked.textContent = 'Click the model to pick a component';
      this.picked.classList.add('none');
    } else if (Array.isArray(sel.components)) {
      // a split-tree node: its visible descendants
      const n = this.editor.tree?.node(sel.node);
      const what = n ? [n.kind, n.rule].filter(Boolean).join(' ') : 'node';
      const k = sel.components.length;
      this.picked.textContent = `node ${sel.node} · ${what} · ${k} component${k === 1 ? '' : 's'}`;
      this.picked.classList.remove('none');
    } else {
      const node = sel.node != null ? ` · node ${sel.node}` : '';
      this.picked.textContent = `component ${sel.component} · group ${sel.group ?? '—'}${node}`;
      this.picked.classList.remove('none');
    }
  }
}
