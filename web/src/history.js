// The open model's op log, newest first, and the note box.
import { el, timeAgo } from './dom.js';

const SHOWN = 200; // newest entries listed; older ones stay in the log

function summary(op) {
  switch (op?.kind) {
    case 'rename':
      return `→ “${op.name}”`;
    case 'note':
      return op.text.length > 80 ? `${op.text.slice(0, 79)}…` : op.text;
    case 'proceduralize':
      return `${count(op.rules, 'rule')} · ${count(op.terminals, 'terminal')} · ${count(op.patterns, 'pattern')}`;
    case 'grammar':
      return typeof op.bytes === 'number' ? `grammar edited (${count(op.bytes, 'byte')})` : 'grammar edited';
    default:
      return '';
  }
}

function count(n, what) {
  if (typeof n !== 'number') return `? ${what}s`;
  return `${n.toLocaleString()} ${what}${n === 1 ? '' : 's'}`;
}

export class HistoryPanel {
  constructor(editor, session, container) {
    this.editor = editor;
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
    this.render();
  }

  render() {
    const ed = this.editor;
    this.form.hidden = !ed.model;
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
        ),
      ),
      older > 0 ? el('li.empty', {}, `${older} older edits not shown`) : '',
    );
  }
}
