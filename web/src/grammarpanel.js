// The grammar drawer under the viewport: the open model's grammar text with line numbers, edited
// in place and applied with "Apply" (a new model version). A syntax error marks its line; a
// grammar changed by someone else meanwhile is offered for reload instead of being overwritten.
import { el } from './dom.js';

export class GrammarPanel {
  constructor(editor, procedural, container) {
    this.editor = editor;
    this.procedural = procedural;
    this.container = container;
    this.base = null;      // version of the grammar the text was loaded from
    this.dirty = false;    // the person changed the text since
    this.errorLine = null; // line of the last refused edit
    this.errorText = '';
    this.conflict = false; // the last Apply met someone else's change (412)
    this.busy = false;

    this.gutter = el('pre.gutter', { 'aria-hidden': 'true' });
    this.text = el('textarea.grammar-text', {
      spellcheck: false,
      wrap: 'off',
      'aria-label': 'Grammar',
      'data-testid': 'grammar-text',
    });
    this.text.setAttribute('autocomplete', 'off');
    this.text.setAttribute('autocapitalize', 'off');
    this.text.addEventListener('input', () => {
      this.dirty = this.text.value !== (this.editor.grammar?.text ?? '');
      this.renderGutter();
      this.renderState();
    });
    this.text.addEventListener('scroll', () => {
      this.gutter.scrollTop = this.text.scrollTop;
    });
    this.text.addEventListener('keydown', (e) => {
      if ((e.ctrlKey || e.metaKey) && e.key === 'Enter') {
        e.preventDefault();
        this.apply();
      }
    });

    this.status = el('span.grammar-status', { 'data-testid': 'grammar-status' });
    this.applyButton = el('button.primary', { type: 'button', 'data-testid': 'grammar-apply', title: 'Apply (Ctrl+Enter)' }, 'Apply');
    this.applyButton.addEventListener('click', () => this.apply());
    this.reloadButton = el('button', { type: 'button', 'data-testid': 'grammar-reload' }, 'Revert');
    this.reloadButton.addEventListener('click', () => this.reload());

    container.append(
      el('h2', {}, 'Grammar'),
      el('div.code', {}, this.gutter, this.text),
      el('div.grammar-bar', {}, this.status, el('span.spacer'), this.reloadButton, this.applyButton),
    );

    const s = editor.signals;
    s.modelOpened.add(() => {
      this.dirty = false;
      this.errorLine = null;
      this.conflict = false;
    });
    s.grammarChanged.add((g) => this.received(g));
    s.roleChanged.add(() => this.renderState());
    this.received(editor.grammar);
  }

  // A grammar from the server: shown unless the person is editing, who is told instead.
  received(g) {
    this.container.hidden = !g;
    if (!g) {
      this.base = null;
      this.dirty = false;
      this.text.value = '';
      this.renderGutter();
      this.renderState();
      return;
    }
    if (!this.dirty) {
      this.show(g);
    } else if (g.version !== this.base) {
      this.renderState();
    }
  }

  show(g) {
    this.base = g.version;
    this.dirty = false;
    this.errorLine = null;
    this.conflict = false;
    const top = this.text.scrollTop;
    this.text.value = g.text;
    this.text.scrollTop = top;
    this.renderGutter();
    this.renderState();
  }

  // Back to the server's grammar, dropping the edit.
  reload() {
    const g = this.editor.grammar;
    if (!g) return;
    this.dirty = false;
    this.show(g);
  }

  async apply() {
    if (this.busy || !this.dirty || !this.editor.grammar || !this.editor.canEdit) return;
    this.busy = true;
    this.renderState();
    const sent = this.text.value;
    const r = await this.procedural.applyGrammar(sent, this.base);
    this.busy = false;
    if (r.ok) {
      // The new grammar arrives with the reload; until then the sent text stands.
      this.dirty = this.text.value !== sent;
      this.errorLine = null;
      this.conflict = false;
    } else if (r.conflict) {
      this.conflict = true;
      this.editor.fail({
        ...r.problem,
        title: 'Someone else changed this model',
        detail: 'Your grammar was not applied. Reload to see the current grammar (your edit is dropped).',
        action: { label: 'Reload grammar', run: () => this.reload() },
      });
    } else if (r.problem && Number.isInteger(r.problem.line)) {
      this.errorLine = r.problem.line;
      this.errorText = r.problem.detail || r.problem.title;
      this.markLine(r.problem.line, r.problem.column);
    }
    this.renderGutter();
    this.renderState();
  }

  // Puts the caret on the line (at the column when known) and selects the rest of the line.
  markLine(line, column) {
    const lines = this.text.value.split('\n');
    const l = Math.max(1, Math.min(line, lines.length));
    let start = 0;
    for (let i = 0; i < l - 1; i++) start += lines[i].length + 1;
    const end = start + lines[l - 1].length;
    const col = Number.isInteger(column) && column > 0 ? Math.min(start + column - 1, end) : start;
    this.text.focus();
    this.text.setSelectionRange(col === end ? start : col, end);
    const lh = parseFloat(getComputedStyle(this.text).lineHeight) || 16;
    this.text.scrollTop = Math.max(0, (l - 3) * lh);
    this.gutter.scrollTop = this.text.scrollTop;
  }

  renderGutter() {
    const n = this.text.value.split('\n').length;
    const out = [];
    for (let i = 1; i <= n; i++) {
      out.push(i === this.errorLine ? el('span.error-line', { 'data-testid': 'grammar-error-line' }, String(i)) : String(i), '\n');
    }
    this.gutter.replaceChildren(...out);
  }

  renderState() {
    const g = this.editor.grammar;
    const changedOnServer = this.dirty && g && g.version !== this.base;
    // viewers read the grammar; only editors change it
    const editable = this.editor.canEdit;
    this.text.readOnly = !editable;
    this.applyButton.hidden = !editable;
    this.reloadButton.hidden = !editable;
    this.applyButton.disabled = !this.dirty || this.busy;
    this.reloadButton.disabled = !this.dirty && !this.conflict;
    this.reloadButton.textContent = changedOnServer || this.conflict ? 'Reload' : 'Revert';
    this.container.classList.toggle('dirty', this.dirty);
    this.status.className = 'grammar-status';
    if (this.busy) {
      this.status.textContent = 'Applying…';
    } else if (this.conflict || changedOnServer) {
      this.status.textContent = 'Someone else changed the model — reload to see it.';
      this.status.classList.add('bad');
    } else if (this.errorLine !== null && this.dirty) {
      this.status.textContent = this.errorText;
      this.status.classList.add('bad');
    } else if (this.dirty) {
      this.status.textContent = 'Edited — Apply to derive a new version';
    } else if (g) {
      const bytes = new TextEncoder().encode(g.text).length;
      this.status.textContent = `v${g.version ?? '?'} · ${bytes.toLocaleString()} bytes`;
    } else {
      this.status.textContent = '';
    }
  }
}
