// Starts a real archgramd on a free loopback port with a temporary database for a test.
//
// Signing in happens here, in one place: the first start prints the admin's token; a page
// signs in (browser.js: openPage) and a request of the test process to a daemon started here
// carries a token (fetch is wrapped) — of the account the test names (openPage's user, an
// X-Archgram-User header: names the server itself ignores now), else of "api". These accounts
// are admins, made on first use, so the tests keep their people and see every model. A request
// with an Authorization header of its own is left alone.
import { spawn } from 'node:child_process';
import { existsSync } from 'node:fs';
import { mkdtemp, rm } from 'node:fs/promises';
import net from 'node:net';
import os from 'node:os';
import path from 'node:path';
import { fileURLToPath } from 'node:url';

export const ROOT = fileURLToPath(new URL('../..', import.meta.url));
// ARCHGRAMD points the tests at another build of the daemon (e.g. a sanitizer build).
const BINARY = process.env.ARCHGRAMD || path.join(ROOT, 'build', 'archgramd');
const WEB = path.join(ROOT, 'build', 'web');
const START_TIMEOUT_MS = 15000;
export const DEFAULT_USER = 'api';

const realFetch = globalThis.fetch;
const running = new Set(); // handles of started daemons
let latest = null; // the daemon pages sign in to

// The first-start line of archgramd: "... http://host:port/#token=<token>".
export const printedToken = (out) => /#token=([A-Za-z0-9._~+-]+)/.exec(out)?.[1] ?? null;

globalThis.fetch = async (input, init = {}) => {
  const url = typeof input === 'string' ? input : input instanceof URL ? input.href : input.url;
  const d = [...running].find((x) => url.startsWith(x.url));
  const headers = new Headers(init.headers || (typeof input === 'object' && input.headers) || {});
  if (!d || headers.has('authorization')) return realFetch(input, init);
  headers.set('Authorization', `Bearer ${await d.tokenFor(headers.get('x-archgram-user') ?? DEFAULT_USER)}`);
  return realFetch(input, { ...init, headers });
};

// The daemon the last startDaemon started (openPage signs its pages in there).
export function currentDaemon() {
  if (!latest) throw new Error('no archgramd started yet');
  return latest;
}

function bindable(port) {
  return new Promise((resolve) => {
    const s = net.createServer();
    s.once('error', () => resolve(false));
    s.listen(port, '127.0.0.1', () => s.close(() => resolve(true)));
  });
}

// A port P the system just handed out, with P+1 free too (the websocket port).
async function freePortPair() {
  for (let i = 0; i < 20; i++) {
    const port = await new Promise((resolve, reject) => {
      const s = net.createServer();
      s.once('error', reject);
      s.listen(0, '127.0.0.1', () => {
        const p = s.address().port;
        s.close(() => resolve(p));
      });
    });
    if (port < 65535 && (await bindable(port + 1))) return port;
  }
  throw new Error('no free pair of loopback ports');
}

function launch(port, db) {
  const args = ['--port', String(port), '--ws-port', String(port + 1), '--bind', '127.0.0.1', '--db', db, '--web', WEB];
  const child = spawn(BINARY, args, { stdio: ['ignore', 'pipe', 'pipe'] });
  let out = '';
  let err = '';
  return new Promise((resolve) => {
    const timer = setTimeout(() => {
      child.kill('SIGKILL');
      resolve({ ok: false, reason: `no "listening on" line within ${START_TIMEOUT_MS} ms\n${out}${err}` });
    }, START_TIMEOUT_MS);
    child.stdout.on('data', (d) => {
      out += d;
      if (out.includes('listening on')) {
        clearTimeout(timer);
        resolve({ ok: true, child, log: () => out + err });
      }
    });
    child.stderr.on('data', (d) => {
      err += d;
    });
    child.on('error', (e) => {
      clearTimeout(timer);
      resolve({ ok: false, reason: e.message });
    });
    child.on('exit', (code, signal) => {
      clearTimeout(timer);
      resolve({ ok: false, inUse: /in use|EADDRINUSE|bind/i.test(out + err), reason: `exited (${code ?? signal})\n${out}${err}` });
    });
  });
}

// A handle on a running daemon; restart() brings it back on the same ports and database.
function handle(port, dir, first) {
  let r = first;
  const admin = printedToken(first.log());
  if (!admin) throw new Error(`archgramd printed no admin token on its first start:\n${first.log()}`);
  const tokens = new Map(); // account name -> Promise<token>
  const makeAccount = async (name, role = 'admin') => {
    const post = (p, body) => realFetch(`http://127.0.0.1:${port}${p}`, {
      method: 'POST',
      headers: { Authorization: `Bearer ${admin}`, 'Content-Type': 'application/json' },
      body: JSON.stringify(body),
    });
    let res = await post('/api/v1/users', { name, role, label: 'tests' });
    if (res.status === 409) res = await post(`/api/v1/users/${name}/tokens`, { label: 'tests' });
    const text = await res.text();
    if (res.status !== 201) throw new Error(`cannot sign in as ${name}: ${res.status} ${text}`);
    return JSON.parse(text).token;
  };
  const stopProcess = async () => {
    const { child } = r;
    if (child.exitCode === null && child.signalCode === null) {
      const exited = new Promise((resolve) => child.once('exit', resolve));
      child.kill('SIGTERM');
      const killer = setTimeout(() => child.kill('SIGKILL'), 5000);
      await exited;
      clearTimeout(killer);
    }
  };
  return {
    url: `http://127.0.0.1:${port}/`,
    port,
    dir,
    log: () => r.log(),
    stopProcess,
    adminToken: admin,
    makeAccount,
    // A token of the admin account `name`, made on first use.
    tokenFor(name = DEFAULT_USER) {
      if (!tokens.has(name)) {
        tokens.set(name, makeAccount(name).catch((e) => {
          tokens.delete(name);
          throw e;
        }));
      }
      return tokens.get(name);
    },
    async restart() {
      await stopProcess();
      let last = '';
      for (let attempt = 0; attempt < 20; attempt++) {
        const next = await launch(port, path.join(dir, 't.db'));
        if (next.ok) {
          r = next;
          return;
        }
        last = next.reason;
        if (!next.inUse) break;
        await new Promise((res) => setTimeout(res, 250));
      }
      throw new Error(`archgramd did not restart: ${last}`);
    },
    async stop() {
      running.delete(this);
      if (latest === this) latest = null;
      await stopProcess();
      await rm(dir, { recursive: true, force: true });
    },
  };
}

export async function startDaemon() {
  if (!existsSync(BINARY)) throw new Error(`${BINARY} is missing: run \`make build/archgramd web\``);
  if (!existsSync(path.join(WEB, 'app.js'))) throw new Error(`${WEB}/app.js is missing: run \`make web\``);
  const dir = await mkdtemp(path.join(os.tmpdir(), 'archgram-browser-'));
  let last = '';
  for (let attempt = 0; attempt < 5; attempt++) {
    const port = await freePortPair();
    const r = await launch(port, path.join(dir, 't.db'));
    if (r.ok) {
      const h = handle(port, dir, r);
      running.add(h);
      latest = h;
      return h;
    }
    last = r.reason;
    if (!r.inUse) break;
  }
  await rm(dir, { recursive: true, force: true });
  throw new Error(`archgramd did not start: ${last}`);
}
