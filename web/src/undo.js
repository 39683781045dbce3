// Undo and redo: Ctrl+Z and Ctrl+Shift+Z (or Ctrl+Y), and two buttons. Each is an op the
// server turns into the inverse of this person's last edit (or of their last undo): a
// `restore` of the version before it (after it), appended to the log like any other edit, so
// everyone in the room sees it and each person undoes only their own edits.
import { el } from './dom.js';
import { isTyping } from './edittools.js';
import { OP, UNDOABLE } from './opkinds.js';

// 'undo', 'redo' or 'edit': the server logs an undo as {kind: 'restore', undoes: K}; our own
// entry keeps the op we sent.
function step(op) {
  if (op.kind === OP.undo || (op.kind === OP.restore && op.undoes != null)) return 'undo';
  if (op.kind === OP.redo || (op.kind === OP.restore && op.redoes != null)) return 'redo';
  return 'edit';
}

export class Undo {
  constructor(editor, container) {
    this.editor = editor;
    this.busy = false;
    this.undoBtn = el('button', { type: 'button', 'data-testid': 'undo', title: 'Undo your last edit (Ctrl+Z)', onclick: () => this.undo() }, '↶ Undo');
    this.redoBtn = el('button', { type: 'button', 'data-testid': 'redo', title: 'Redo (Ctrl+Shift+Z)', onclick: () => this.redo() }, '↷ Redo');
    container.append(this.undoBtn, this.redoBtn);
    window.addEventListener('keydown', (e) => {
      if (isTyping(e.target) || !(e.ctrlKey || e.metaKey) || e.altKey) return;
      const k = e.key.toLowerCase();
      if (k === 'z' && !e.shiftKey) {
        e.preventDefault();
        if (!this.undoBtn.disabled) this.undo();
      } else if ((k === 'z' && e.shiftKey) || k === 'y') {
        e.preventDefault();
        if (!this.redoBtn.disabled) this.redo();
      }
    });
    const s = editor.signals;
    s.historyChanged.add(() => this.render());
    s.modelOpened.add(() => this.render());
    s.modelChanged.add(() => this.render());
    this.render();
  }

  undo() {
    return this.send(OP.undo);
  }

  redo() {
    return this.send(OP.redo);
  }

  async send(kind) {
    const ed = this.editor;
    if (!ed.model || this.busy) return null;
    this.busy = true;
    this.render();
    try {
      return await ed.execute({ kind });
    } finally {
      this.busy = false;
      this.render();
    }
  }

  // Undo is offered once this person has an edit in the log, redo while their latest steps
  // are undos not yet redone; the server decides exactly what each undoes (and refuses with a
  // problem when there is nothing left).
  render() {
    const ed = this.editor;
    const mine = ed.model ? ed.history().filter((e) => e.author === ed.user && UNDOABLE.has(e.op?.kind)) : [];
    let undone = 0;
    for (let i = mine.length - 1; i >= 0; i--) {
      const kind = step(mine[i].op);
      if (kind === 'undo') undone += 1;
      else if (kind === 'redo') undone -= 1;
      else break;
    }
    this.undoBtn.disabled = !ed.model || this.busy || !mine.some((e) => step(e.op) === 'edit');
    this.redoBtn.disabled = !ed.model || this.busy || undone <= 0;
  }
}
