// The top bar: the open model's editable name and version, the live state and the user name.
import { el } from './dom.js';

export class Toolbar {
  constructor(editor, session, container) {
    this.editor = editor;
    this.session = session;

    this.title = el('h1.model-name', {
      'data-testid': 'model-name',
      title: 'Click to rename',
      spellcheck: false,
    });
    this.title.addEventListener('keydown', (e) => {
      if (e.key === 'Enter') {
        e.preventDefault();
        this.title.blur();
      } else if (e.key === 'Escape') {
        this.editing = false;
        this.render();
        this.title.blur();
      }
    });
    this.title.addEventListener('focus', () => {
      this.editing = true;
    });
    this.title.addEventListener('blur', () => {
      if (!this.editing) return;
      this.editing = false;
      session.rename(this.title.textContent.replace(/\s+/g, ' '));
    });
    this.version = el('span.badge.version', { 'data-testid': 'model-version', title: 'Model version' });
    this.conn = el('span.conn', { 'data-testid': 'connection' });
    this.user = el('input.user', {
      type: 'text',
      value: editor.user,
      maxLength: 64,
      'aria-label': 'Your name',
      title: 'Your name, as others in the room see it',
      'data-testid': 'user-name',
    });
    this.user.addEventListener('change', () => {
      editor.setUser(this.user.value);
      this.user.value = editor.user;
    });

    container.append(
      el('div.brand', {}, el('span.logo', {}, '◆'), 'archgram'),
      el('div.title-wrap', {}, this.title, this.version),
      el('div.spacer'),
      this.conn,
      el('label.user-label', {}, 'You', this.user),
    );

    const s = editor.signals;
    s.modelOpened.add(() => this.render());
    s.modelChanged.add(() => this.render());
    s.connectionChanged.add(() => this.renderConnection());
    s.userChanged.add((u) => {
      this.user.value = u;
    });
    this.render();
    this.renderConnection();
  }

  render() {
    const m = this.editor.model;
    if (!m) {
      this.title.textContent = 'No model open';
      this.title.contentEditable = 'false';
      this.title.classList.add('empty');
      this.version.textContent = '';
      this.version.hidden = true;
      return;
    }
    this.title.classList.remove('empty');
    this.title.contentEditable = 'plaintext-only';
    if (!this.editing) this.title.textContent = m.name;
    this.version.hidden = false;
    this.version.textContent = `v${m.version}`;
  }

  renderConnection() {
    const state = this.editor.connection;
    const text = { offline: 'offline', connecting: 'connecting…', online: 'live', lost: 'reconnecting…' }[state];
    this.conn.textContent = text || state;
    this.conn.className = `conn ${state}`;
  }
}
