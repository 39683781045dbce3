// The top bar: the open model's editable name, version and the person's role on it (and the
// share dialog), the live state, and the signed-in account (with signing out).
import { el } from './dom.js';

export class Toolbar {
  constructor(editor, session, container, { auth, share } = {}) {
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
    this.role = el('span.badge.role', { 'data-testid': 'model-role', title: 'Your role on this model' });
    this.share = el('button.share-open', { type: 'button', 'data-testid': 'share', title: 'Who may use this model' }, 'Share');
    this.share.addEventListener('click', () => share?.open());
    this.conn = el('span.conn', { 'data-testid': 'connection' });
    this.user = el('span.account', { 'data-testid': 'user-name', title: 'The account you are signed in with' });
    this.accountRole = el('span.badge', { 'data-testid': 'account-role' });
    this.signOut = el('button.sign-out', { type: 'button', 'data-testid': 'sign-out', title: 'Forget the token in this browser' }, 'Sign out');
    this.signOut.addEventListener('click', () => auth?.signOut());

    container.append(
      el('div.brand', {}, el('span.logo', {}, '◆'), 'archgram'),
      el('div.title-wrap', {}, this.title, this.version, this.role, this.share),
      el('div.spacer'),
      this.conn,
      el('div.user-label', {}, 'You', this.user, this.accountRole, this.signOut),
    );

    const s = editor.signals;
    s.modelOpened.add(() => this.render());
    s.modelChanged.add(() => this.render());
    s.roleChanged.add(() => this.render());
    s.connectionChanged.add(() => this.renderConnection());
    s.accountChanged.add(() => this.renderAccount());
    this.render();
    this.renderConnection();
    this.renderAccount();
  }

  render() {
    const m = this.editor.model;
    this.share.hidden = !m;
    this.role.hidden = !m || !this.editor.role;
    if (!m) {
      this.title.textContent = 'No model open';
      this.title.contentEditable = 'false';
      this.title.classList.add('empty');
      this.version.textContent = '';
      this.version.hidden = true;
      return;
    }
    const editable = this.editor.canEdit;
    this.title.classList.remove('empty');
    this.title.contentEditable = editable ? 'plaintext-only' : 'false';
    this.title.title = editable ? 'Click to rename' : 'Read only';
    if (!this.editing) this.title.textContent = m.name;
    this.version.hidden = false;
    this.version.textContent = `v${m.version}`;
    this.role.textContent = this.editor.role || '';
    this.role.dataset.role = this.editor.role || '';
  }

  renderAccount() {
    const a = this.editor.account;
    this.user.textContent = a?.name ?? '';
    this.accountRole.textContent = a?.role ?? '';
    this.accountRole.hidden = !a || a.role === 'editor';
    this.signOut.hidden = !a || a.auth === false;
  }

  renderConnection() {
    const state = this.editor.connection;
    const text = { offline: 'offline', connecting: 'connecting…', online: 'live', lost: 'reconnecting…' }[state];
    this.conn.textContent = text || state;
    this.conn.className = `conn ${state}`;
  }
}
