// The share dialog of the open model: who may use it (each member's account and role), adding
// someone with a role, taking a role away, and the public-read flag (every account may look).
// Owners change it; everyone else sees it read only. The server keeps at least one owner and
// tells the model's room of every change, so the people affected see their new role at once.
import { el } from './dom.js';

const ROLES = ['viewer', 'editor', 'owner'];

export class ShareDialog {
  constructor(editor, api, container) {
    this.editor = editor;
    this.api = api;
    this.doc = null; // {model, public_read, items}

    this.title = el('h2');
    this.list = el('ul.share-members', { 'data-testid': 'share-members' });
    this.publicBox = el('input', { type: 'checkbox', 'data-testid': 'share-public' });
    this.publicBox.addEventListener('change', () => this.change(() => this.api.setPublicRead(this.id, this.publicBox.checked)));
    this.userInput = el('input.share-user', {
      type: 'text', placeholder: 'account name', maxLength: 64, spellcheck: false, 'data-testid': 'share-user', 'aria-label': 'Account to share with',
    });
    this.roleSel = el('select', { 'data-testid': 'share-role', 'aria-label': 'Role' }, ROLES.map((r) => el('option', { value: r, selected: r === 'editor' }, r)));
    this.addForm = el('form.share-add', {}, this.userInput, this.roleSel, el('button.primary', { type: 'submit', 'data-testid': 'share-add' }, 'Share'));
    this.addForm.addEventListener('submit', (e) => {
      e.preventDefault();
      const user = this.userInput.value.trim();
      if (!user) return;
      this.change(() => this.api.share(this.id, user, this.roleSel.value)).then((ok) => {
        if (ok) this.userInput.value = '';
      });
    });
    this.note = el('p.share-note');
    const close = el('button', { type: 'button', 'data-testid': 'share-close' }, 'Close');
    close.addEventListener('click', () => this.close());
    this.box = el(
      'div.share-box',
      { role: 'dialog', 'aria-modal': 'true' },
      this.title,
      this.list,
      el('label.share-public', {}, this.publicBox, 'Every account may view this model'),
      this.addForm,
      this.note,
      el('div.share-bar', {}, el('span.spacer'), close),
    );
    this.overlay = el('div.share', { 'data-testid': 'share-dialog', hidden: true }, this.box);
    this.overlay.addEventListener('keydown', (e) => {
      if (e.key === 'Escape') this.close();
    });
    container.append(this.overlay);

    editor.signals.modelOpened.add(() => this.close());
    editor.signals.roleChanged.add(() => this.render());
  }

  get id() {
    return this.editor.model?.id;
  }

  get owner() {
    return this.editor.role === 'owner';
  }

  async open() {
    if (!this.editor.model) return;
    this.doc = null;
    this.overlay.hidden = false;
    this.render();
    try {
      this.doc = await this.api.getMembers(this.id);
    } catch (err) {
      this.editor.fail(err);
    }
    this.render();
    if (this.owner) this.userInput.focus();
  }

  close() {
    this.overlay.hidden = true;
  }

  // Runs one change; the answer is the sharing as it is now. Resolves true when it worked.
  async change(call) {
    const model = this.id;
    try {
      const doc = await call();
      if (model === this.id) this.doc = doc;
      return true;
    } catch (err) {
      this.editor.fail(err);
      return false;
    } finally {
      this.render();
    }
  }

  render() {
    const m = this.editor.model;
    if (this.overlay.hidden || !m) return;
    const owner = this.owner;
    this.title.textContent = `Share “${m.name}”`;
    this.addForm.hidden = !owner;
    this.publicBox.disabled = !owner;
    this.note.textContent = owner
      ? 'Viewers look; editors also edit; owners also share and delete.'
      : `You are a ${this.editor.role} of this model: only its owners change who may use it.`;
    if (!this.doc) {
      this.list.replaceChildren(el('li.empty', {}, 'Loading…'));
      return;
    }
    this.publicBox.checked = !!this.doc.public_read;
    this.list.replaceChildren(...this.doc.items.map((it) => this.row(it, owner)));
  }

  row({ user, role }, owner) {
    const me = user === this.editor.user;
    const name = el('span.share-name', {}, user, me ? ' (you)' : '');
    if (!owner) return el('li.share-member', { dataset: { user } }, name, el('span.badge', {}, role));
    const sel = el('select', { 'aria-label': `Role of ${user}`, 'data-testid': 'share-member-role' }, ROLES.map((r) => el('option', { value: r, selected: r === role }, r)));
    sel.addEventListener('change', () => this.change(() => this.api.share(this.id, user, sel.value)));
    const remove = el('button', { type: 'button', title: `Take ${user}'s access away`, 'data-testid': 'share-remove' }, 'Remove');
    remove.addEventListener('click', () => this.change(() => this.api.unshare(this.id, user)));
    return el('li.share-member', { dataset: { user } }, name, sel, remove);
  }
}
