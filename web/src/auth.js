// Signing in: the API token this browser uses, from a sign-in link (…/#token=<token>, read
// once and taken out of the address bar), from what was kept in this browser, or pasted into
// the sign-in form. The token is the person's account; the server tells its name and role
// (GET /api/v1/me) and every request and the websocket carry it. A token the server refuses
// (revoked, or a new database) brings the form back.
import { el } from './dom.js';

const TOKEN_KEY = 'archgram.token';
// Without accounts (archgramd --no-auth) changes still need an Authorization header.
const NO_AUTH_TOKEN = 'local';

function stored() {
  try {
    return localStorage.getItem(TOKEN_KEY) || null;
  } catch {
    return null; // storage disabled: sign in on every visit
  }
}

function keep(token) {
  try {
    if (token) localStorage.setItem(TOKEN_KEY, token);
    else localStorage.removeItem(TOKEN_KEY);
  } catch {
    // storage disabled: the token lasts for this visit
  }
}

// A token handed over in the address: …#token=agt_… (possibly with &model=N after it).
function fromLink() {
  const m = /(?:^#|&)token=([A-Za-z0-9._~+-]+)/.exec(location.hash);
  if (!m) return null;
  const rest = location.hash.replace(m[0], '').replace(/^#&?/, '');
  history.replaceState(null, '', `${location.pathname}${location.search}${rest ? `#${rest}` : ''}`);
  return m[1];
}

export class Auth {
  constructor(editor, api, container) {
    this.editor = editor;
    this.api = api;
    this.token = null;
    this.signedIn = false;
    this.waiting = null; // resolves the form when a token works
    api.useAuth(this);

    this.input = el('input.signin-token', {
      type: 'password',
      placeholder: 'agt_…',
      autocomplete: 'off',
      spellcheck: false,
      'aria-label': 'API token',
      'data-testid': 'signin-token',
    });
    this.message = el('p.signin-message', { 'data-testid': 'signin-message' });
    this.form = el(
      'form.signin-form',
      {},
      el('h2', {}, 'Sign in to archgram'),
      el('p.signin-help', {}, 'Paste your API token, or open the sign-in link archgramd printed on its first start. ',
        'An admin makes accounts and tokens (archgramd --create-user NAME).'),
      this.input,
      this.message,
      el('button.primary', { type: 'submit', 'data-testid': 'signin-submit' }, 'Sign in'),
    );
    this.form.addEventListener('submit', (e) => {
      e.preventDefault();
      this.tryToken(this.input.value.trim());
    });
    this.overlay = el('div.signin', { 'data-testid': 'signin', hidden: true }, this.form);
    container.append(this.overlay);
  }

  // Resolves once signed in (the account is in editor.account).
  async start() {
    const health = await this.api.getHealth().catch(() => null);
    if (health && health.auth === false) {
      this.token = NO_AUTH_TOKEN;
      return this.load(NO_AUTH_TOKEN);
    }
    const candidates = [fromLink(), stored()].filter(Boolean);
    for (const token of candidates) {
      if (await this.load(token).catch(() => false)) return true;
    }
    return this.ask(candidates.length ? 'That token is not valid here any more: sign in again.' : '');
  }

  // Tries token against the server; keeps it and sets the account when it works.
  async load(token) {
    this.token = token;
    this.signedIn = false;
    try {
      const me = await this.api.getMe();
      if (token !== NO_AUTH_TOKEN) keep(token);
      this.editor.setAccount(me);
      this.signedIn = true;
      return true;
    } catch (err) {
      this.token = null;
      if (err.status === 401) return false;
      throw err;
    }
  }

  ask(message) {
    this.message.textContent = message || '';
    this.overlay.hidden = false;
    this.input.focus();
    return new Promise((resolve) => {
      this.waiting = resolve;
    });
  }

  async tryToken(token) {
    if (!token) {
      this.message.textContent = 'Paste a token first.';
      return;
    }
    let ok = false;
    try {
      ok = await this.load(token);
    } catch (err) {
      this.message.textContent = err.message;
      return;
    }
    if (!ok) {
      this.message.textContent = 'archgramd does not know this token.';
      return;
    }
    this.input.value = '';
    this.overlay.hidden = true;
    const resolve = this.waiting;
    this.waiting = null;
    if (resolve) resolve(true);
    else location.reload(); // signed in again after a refusal: start over with the new account
  }

  // The server refused our token mid-visit (revoked): ask again.
  refused() {
    if (!this.signedIn || this.token === NO_AUTH_TOKEN || !this.overlay.hidden) return;
    this.signedIn = false;
    keep(null);
    this.token = null;
    this.ask('archgramd no longer accepts your token: sign in again.');
  }

  signOut() {
    keep(null);
    this.token = null;
    location.hash = '';
    location.reload();
  }
}
