// The open model's op log, newest first, and the note box.
import { el, timeAgo } from './dom.js';
import { OP } from './opkinds.js';

const SHOWN = 200; // newest entries listed; older ones stay in the log

function summary(op) {
  switch (op?.kind) {
    case OP.rename:
      return `→ “${op.name}”`;
    case OP.note:
      return op.text.length > 80 ? `${op.text.slice(0, 79)}…` : op.text;
    case OP.proceduralize:
      return `${count(op.rules, 'rule')} · ${count(op.terminals, 'terminal')} · ${count(op.patterns, 'pattern')}`;
    case OP.grammar:
      return typeof op.bytes === 'number' ? `grammar edited (${count(op.bytes, 'byte')})` : 'grammar edited';
    case OP.resize:
      return `node ${op.node} ${op.scale ? `× ${op.scale.join(', ')}` : boxText(op.box)} · ${op.mode || 'global'}${reportText(op.report)}`;
    case OP.split:
      return `node ${op.node} at ${op.axis} = ${Number(op.at).toFixed(2)} m${reportText(op.report)}`;
    case OP.join:
    case OP.remove:
      return Array.isArray(op.nodes) ? `nodes ${op.nodes.join(', ')}` : '';
    case OP.paste:
      return `${Array.isArray(op.source) ? op.source.join(', ') : '?'} → ${op.target} · ${op.placement || 'insert'}, ${op.fit || 'fill'}`;
    case OP.undo:
    case OP.redo:
      return '';
    case OP.restore:
      if (op.undoes != null) return `undo of v${op.undoes}`;
      if (op.redoes != null) return `redo of v${op.redoes}`;
      return `back to v${op.version}`;
    case OP.plan:
      return `building ${op.building} · plan edited`;
    case OP.profile:
      return `profile “${op.name}” edited`;
    default:
      return '';
  }
}

// What the server's solve did: splits and joins, and its time.
function reportText(r) {
  if (!r || typeof r !== 'object') return '';
  const parts = [];
  if (r.splits) parts.push(count(r.splits, 'split'));
  if (r.joins) parts.push(count(r.joins, 'join'));
  if (typeof r.solve_ms === 'number' && r.equations) parts.push(`${r.equations} eq. in ${r.solve_ms.toFixed(1)} ms`);
  return parts.length ? ` · ${parts.join(', ')}` : '';
}

function boxText(box) {
  if (!Array.isArray(box) || box.length !== 6) return '';
  return `→ ${[0, 1, 2].map((i) => (box[i + 3] - box[i]).toFixed(2)).join(' × ')} m`;
}

function count(n, what) {
  if (typeof n !== 'number') return `? ${what}s`;
  return `${n.toLocaleString()} ${what}${n === 1 ? '' : 's'}`;
}

export class HistoryPanel {
  constructor(editor, session, container) {
    this.editor = editor;
    this.session = session;
    this.list = el('ol.history', { 'data-testid': 'history' });
    this.input = el('input.note-input', {
      type: 'text',
      placeholder: 'Add a note…',
      maxLength: 4000,
      'data-testid': 'note-input',
    });
    this.form = el(
      'form.note',
      {},
      this.input,
      el('button', { type: 'submit', 'data-testid': 'note-send' }, 'Add'),
    );
    this.form.addEventListener('submit', async (e) => {
      e.preventDefault();
      if (await session.note(this.input.value)) this.input.value = '';
    });
    container.append(el('h2', {}, 'History'), this.form, this.list);
    editor.signals.historyChanged.add(() => this.render());
    editor.signals.modelOpened.add(() => this.render());
    editor.signals.modelChanged.add(() => this.render());
    editor.signals.roleChanged.add(() => this.render());
    this.render();
  }

  // Restoring an old version is an op too: it appends, so it can itself be undone.
  restore(version) {
    return this.editor.execute({ kind: OP.restore, version });
  }

  render() {
    const ed = this.editor;
    this.form.hidden = !ed.model || !ed.canEdit;
    const all = ed.history();
    const ops = all.slice(-SHOWN).reverse();
    if (!ed.model) {
      this.list.replaceChildren();
      return;
    }
    if (!ops.length) {
      this.list.replaceChildren(el('li.empty', {}, 'No edits yet'));
      return;
    }
    const older = all.length - ops.length;
    this.list.replaceChildren(
      ...ops.map((e) =>
        el(
          'li.op',
          { dataset: { version: e.version }, title: e.at || '' },
          el('span.op-version', {}, `v${e.version}`),
          el('span.op-author', {}, e.author || '?'),
          el('span.op-kind', {}, e.op?.kind || '?'),
          el('span.op-summary', {}, summary(e.op)),
          el('span.op-time', {}, e.at ? timeAgo(e.at) : ''),
          e.version < ed.model.version && ed.model.proceduralized && ed.canEdit
            ? el('button.op-restore', {
              type: 'button',
              title: `Make v${e.version} the current state again (a new edit)`,
              'data-testid': 'restore',
              onclick: () => this.restore(e.version),
            }, 'restore')
            : '',
        ),
      ),
      older > 0 ? el('li.empty', {}, `${older} older edits not shown`) : '',
    );
  }
}
