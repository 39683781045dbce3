// Shared helpers for the service integration tests: start a real archgramd on free
// loopback ports with a temp database, talk REST and websocket to it, inspect the
// database file with the sqlite3 command-line tool. Every wait has a timeout.
//
// Signing in happens here, in one place: the first start of a database prints the admin's
// token, which is kept per database file (a restart reuses it), and every request a test
// makes carries an API token — of the account the test names (X-Archgram-User on REST, "user"
// in a websocket hello: names the server itself ignores now), else of the account "api". These
// accounts are admins, made on first use, so the tests keep their authors and see every model.
// A test about accounts passes its own token (`token:` on http, `{ token }` on WsClient.open,
// an Authorization header of its own), or `token: null` for none.
import assert from 'node:assert/strict';
import { spawn, spawnSync } from 'node:child_process';
import fs from 'node:fs';
import net from 'node:net';
import os from 'node:os';
import path from 'node:path';
import { fileURLToPath } from 'node:url';
import WebSocket from 'ws';

export const REPO = path.resolve(path.dirname(fileURLToPath(import.meta.url)), '..', '..');
// ARCHGRAMD overrides the binary (e.g. a sanitizer build kept outside the checkout).
export const DAEMON = process.env.ARCHGRAMD ? path.resolve(process.env.ARCHGRAMD) : path.join(REPO, 'build', 'archgramd');
export const DATA = path.join(REPO, 'tests', 'data', 'http');
export const PROBLEM = 'urn:archgram:problem:';

export const sleep = (ms) => new Promise((r) => setTimeout(r, ms));

// Deterministic pseudo-random numbers (mulberry32).
export function rng(seed) {
  let a = seed >>> 0;
  return () => {
    a = (a + 0x6d2b79f5) >>> 0;
    let t = a;
    t = Math.imul(t ^ (t >>> 15), t | 1);
    t ^= t + Math.imul(t ^ (t >>> 7), t | 61);
    return ((t ^ (t >>> 14)) >>> 0) / 4294967296;
  };
}


export function fixture(name) {
  return fs.readFileSync(path.join(DATA, name));
}

export function tempDir() {
  return fs.mkdtempSync(path.join(os.tmpdir(), 'archgram-it-'));
}

export function removeDir(dir) {
  if (dir) fs.rmSync(dir, { recursive: true, force: true });
}

// Two distinct free loopback ports: bind both to port 0 at once, then release them.
export async function freePorts(n = 2) {
  const servers = [];
  try {
    for (let i = 0; i < n; i++) {
      const s = net.createServer();
      await new Promise((resolve, reject) => {
        s.once('error', reject);
        s.listen(0, '127.0.0.1', resolve);
      });
      servers.push(s);
    }
    return servers.map((s) => s.address().port);
  } finally {
    await Promise.all(servers.map((s) => new Promise((r) => s.close(r))));
  }
}

// --- accounts ------------------------------------------------------------------------------

export const DEFAULT_USER = 'api';
const accountsByDb = new Map(); // database path -> { admin, tokens: Map(name -> Promise<token>) }
const daemonsByPort = new Map(); // HTTP port and websocket URL -> Daemon

function accountsOf(db) {
  if (!accountsByDb.has(db)) accountsByDb.set(db, { admin: null, tokens: new Map() });
  return accountsByDb.get(db);
}

// The first-start line of archgramd: "... http://host:port/#token=<token>".
export function printedToken(out) {
  const m = /#token=([A-Za-z0-9._~+-]+)/.exec(out);
  return m ? m[1] : null;
}

function headerOf(headers, name) {
  const k = Object.keys(headers).find((h) => h.toLowerCase() === name);
  return k === undefined ? undefined : headers[k];
}

// Children still alive when the test process exits are killed, so a failed test never
// leaves a daemon behind.
const live = new Set();
process.on('exit', () => {
  for (const p of live) {
    try { p.kill('SIGKILL'); } catch { /* already gone */ }
  }
});

function withTimeout(promise, ms, what) {
  let timer;
  return Promise.race([
    promise.finally(() => clearTimeout(timer)),
    new Promise((_, reject) => {
      timer = setTimeout(() => reject(new Error(`timeout after ${ms} ms: ${what}`)), ms);
    }),
  ]);
}

class Daemon {
  constructor(proc, opts) {
    this.proc = proc;
    this.port = opts.port;
    this.wsPort = opts.wsPort;
    this.db = opts.db;
    this.dir = opts.dir;
    this.base = `http://127.0.0.1:${opts.port}`;
    this.wsUrl = `ws://127.0.0.1:${opts.wsPort}/`;
    this.out = '';
    this.err = '';
    this.exit = new Promise((resolve) => {
      proc.on('exit', (code, signal) => {
        live.delete(proc);
        resolve({ code, signal });
      });
    });
    this.exited = false;
    this.exit.then(() => { this.exited = true; });
    proc.stdout.setEncoding('utf8');
    proc.stderr.setEncoding('utf8');
    proc.stdout.on('data', (s) => { this.out += s; });
    proc.stderr.on('data', (s) => { this.err += s; });
  }

  // Resolves once stdout has the "listening on" line; rejects with the captured output
  // when the daemon exits first or the line does not come within `ms`.
  ready(ms) {
    return new Promise((resolve, reject) => {
      const check = () => {
        if (/listening on/.test(this.out)) { cleanup(); resolve(); }
      };
      const onExit = ({ code, signal }) => {
        cleanup();
        reject(Object.assign(new Error(
          `archgramd exited (code ${code}, signal ${signal}) before listening\n` +
          `stdout:\n${this.out}\nstderr:\n${this.err}`), { exitedEarly: true }));
      };
      const timer = setTimeout(() => {
        cleanup();
        reject(new Error(`archgramd did not print "listening on" within ${ms} ms\n` +
          `stdout:\n${this.out}\nstderr:\n${this.err}`));
      }, ms);
      const cleanup = () => {
        clearTimeout(timer);
        this.proc.stdout.off('data', check);
      };
      this.proc.stdout.on('data', check);
      this.exit.then(onExit);
      check();
    });
  }

  // SIGTERM, then the daemon must exit with code 0 within `ms`.
  async stop(ms = 5000) {
    if (this.exited) {
      const r = await this.exit;
      assert.fail(`archgramd had already exited (code ${r.code}, signal ${r.signal})\nstderr:\n${this.err}`);
    }
    const t0 = Date.now();
    this.proc.kill('SIGTERM');
    let r;
    try {
      r = await withTimeout(this.exit, ms, 'archgramd exit after SIGTERM');
    } catch (e) {
      this.proc.kill('SIGKILL');
      await this.exit;
      throw new Error(`${e.message}\nstderr:\n${this.err}`);
    }
    assert.equal(r.signal, null, `archgramd killed by ${r.signal}\nstderr:\n${this.err}`);
    assert.equal(r.code, 0, `archgramd exit code ${r.code}\nstderr:\n${this.err}`);
    // A sanitizer build (ARCHGRAMD=...) reports undefined behaviour without failing the exit.
    assert.doesNotMatch(this.err, /runtime error:|(ERROR|WARNING): (Address|Leak|Thread)Sanitizer/,
      `sanitizer report from archgramd:\n${this.err}`);
    return { ...r, ms: Date.now() - t0 };
  }

  // For after() hooks: make sure the process is gone without asserting anything.
  async kill() {
    if (this.exited) return;
    this.proc.kill('SIGKILL');
    await withTimeout(this.exit, 5000, 'archgramd exit after SIGKILL').catch(() => {});
  }

  url(p) {
    return this.base + p;
  }

  // The admin token of this database: printed by its first start, kept for its restarts.
  adminToken() {
    const accounts = accountsOf(this.db);
    const printed = printedToken(this.out);
    if (printed) accounts.admin = printed;
    if (!accounts.admin) throw new Error(`no admin token for ${this.db}: archgramd printed none\n${this.out}`);
    return accounts.admin;
  }

  // A token of the admin account `name`, made on first use.
  tokenFor(name = DEFAULT_USER) {
    const accounts = accountsOf(this.db);
    if (!accounts.tokens.has(name)) {
      const made = this.makeAccount(name).catch((e) => {
        accounts.tokens.delete(name);
        throw e;
      });
      accounts.tokens.set(name, made);
    }
    return accounts.tokens.get(name);
  }

  async makeAccount(name, role = 'admin') {
    const admin = this.adminToken();
    const post = (p, body) => fetch(this.url(p), {
      method: 'POST',
      headers: { Authorization: `Bearer ${admin}`, 'Content-Type': 'application/json' },
      body: JSON.stringify(body),
      signal: AbortSignal.timeout(10000),
    });
    let res = await post('/api/v1/users', { name, role, label: 'tests' });
    if (res.status === 409) res = await post(`/api/v1/users/${name}/tokens`, { label: 'tests' });
    const text = await res.text();
    if (res.status !== 201) throw new Error(`cannot sign in as ${name}: ${res.status} ${text}`);
    return JSON.parse(text).token;
  }
}

// Start archgramd. opts: dir (temp dir to use; created when absent), db (defaults to
// <dir>/t.db), args (extra command-line arguments). Retries with new ports when the
// chosen ones were taken in the meantime.
export async function startDaemon(opts = {}) {
  if (!fs.existsSync(DAEMON)) {
    throw new Error(`${DAEMON} is missing: run make build/archgramd`);
  }
  const dir = opts.dir ?? tempDir();
  const db = opts.db ?? path.join(dir, 't.db');
  let lastError;
  for (let attempt = 0; attempt < 5; attempt++) {
    const [port, wsPort] = await freePorts(2);
    const argv = ['--port', String(port), '--bind', '127.0.0.1', '--ws-port', String(wsPort),
      '--db', db, ...(opts.args ?? [])];
    const proc = spawn(DAEMON, argv, { stdio: ['ignore', 'pipe', 'pipe'], cwd: dir });
    live.add(proc);
    const d = new Daemon(proc, { port, wsPort, db, dir });
    try {
      await d.ready(10000);
      if (opts.signIn !== false) d.adminToken();
      daemonsByPort.set(port, d);
      daemonsByPort.set(d.wsUrl, d);
      return d;
    } catch (e) {
      lastError = e;
      await d.kill();
      if (!(e.exitedEarly && /in use|EADDRINUSE|bind|listen/i.test(d.err + d.out))) break;
    }
  }
  if (!opts.dir) removeDir(dir);
  throw lastError;
}

// --- REST ---------------------------------------------------------------------------------

// fetch with a timeout; returns { status, headers, body (Buffer), text, json }.
// json is the parsed body when it parses, else undefined. Signs in as the X-Archgram-User the
// headers name (else "api") unless they carry an Authorization or `token` is given (null: none).
export async function http(d, method, p, { body, headers = {}, timeout = 15000, token } = {}) {
  const init = { method, headers: { ...headers }, signal: AbortSignal.timeout(timeout) };
  if (token !== null && headerOf(headers, 'authorization') === undefined) {
    const t = token ?? await d.tokenFor(headerOf(headers, 'x-archgram-user') ?? DEFAULT_USER);
    init.headers.Authorization = `Bearer ${t}`;
  }
  if (body !== undefined) {
    init.body = (typeof body === 'object' && !(body instanceof Uint8Array) &&
      !(body instanceof FormData) && !(body instanceof Blob) && !(body instanceof ReadableStream))
      ? JSON.stringify(body) : body;
    if (init.body instanceof ReadableStream) init.duplex = 'half';
    if (typeof body === 'object' && init.body !== body && !init.headers['Content-Type']) {
      init.headers['Content-Type'] = 'application/json';
    }
  }
  const res = await fetch(d.url(p), init);
  const buf = Buffer.from(await res.arrayBuffer());
  const text = buf.toString('utf8');
  let json;
  try { json = JSON.parse(text); } catch { json = undefined; }
  return { status: res.status, headers: res.headers, body: buf, text, json };
}

// The response must be an RFC 9457 problem of the given HTTP status and slug.
export function assertProblem(res, status, slug, what = '') {
  const ctx = `${what} → ${res.status} ${res.headers.get('content-type')} ${res.text.slice(0, 400)}`;
  assert.equal(res.status, status, ctx);
  assert.match(res.headers.get('content-type') ?? '', /^application\/problem\+json\b/, ctx);
  assert.ok(res.json && typeof res.json === 'object', `problem body is not JSON: ${ctx}`);
  assert.equal(res.json.status, status, ctx);
  if (slug) assert.equal(res.json.type, PROBLEM + slug, ctx);
  assert.equal(typeof res.json.title, 'string', ctx);
  assert.equal(typeof res.json.detail, 'string', ctx);
}

// POST a raw file to /api/v1/models; asserts 202 + Location and returns the job object.
export async function upload(d, body, { name = 'test', format = 'obj', up, headers = {} } = {}) {
  const q = new URLSearchParams({ name, format });
  if (up) q.set('up', up);
  const res = await http(d, 'POST', `/api/v1/models?${q}`, {
    body, headers: { 'Content-Type': 'application/octet-stream', ...headers }, timeout: 120000,
  });
  assert.equal(res.status, 202, `upload → ${res.status} ${res.text.slice(0, 400)}`);
  assert.ok(res.json && Number.isInteger(res.json.id), `job object: ${res.text}`);
  assert.equal(res.headers.get('location'), `/api/v1/jobs/${res.json.id}`);
  return res.json;
}

const TERMINAL = new Set(['succeeded', 'failed', 'cancelled']);

// Poll a job until it reaches a terminal status.
export async function waitJob(d, id, { timeout = 30000, interval = 25 } = {}) {
  const t0 = Date.now();
  for (;;) {
    const res = await http(d, 'GET', `/api/v1/jobs/${id}`);
    assert.equal(res.status, 200, `GET job ${id} → ${res.status} ${res.text}`);
    if (TERMINAL.has(res.json.status)) return res.json;
    if (Date.now() - t0 > timeout) {
      assert.fail(`job ${id} still ${res.json.status} after ${timeout} ms: ${res.text}`);
    }
    await sleep(interval);
  }
}

// Upload, wait, require success; returns the model object.
export async function importModel(d, body, opts = {}) {
  const job = await upload(d, body, opts);
  const done = await waitJob(d, job.id);
  assert.equal(done.status, 'succeeded', `import job: ${JSON.stringify(done)}`);
  const res = await http(d, 'GET', done.result.href);
  assert.equal(res.status, 200, res.text);
  return res.json;
}

// All models, following next_page_token.
export async function listModels(d, pageSize = 200) {
  const items = [];
  let token = null;
  for (let i = 0; i < 1000; i++) {
    const q = new URLSearchParams({ page_size: String(pageSize) });
    if (token) q.set('page_token', token);
    const res = await http(d, 'GET', `/api/v1/models?${q}`);
    assert.equal(res.status, 200, res.text);
    items.push(...res.json.items);
    token = res.json.next_page_token;
    if (token === null) return items;
  }
  assert.fail('next_page_token never became null');
}

// A hand-written HTTP/1.1 exchange over a raw socket, for what fetch hides: bodies without
// Content-Length, servers that answer before reading the body. `chunks` are written in
// order (each a Buffer/string); returns { status, headers (lower-case keys), body }.
// A head without an Authorization header gets the token of "api" of the daemon on that port.
export async function rawRequest(port, head, chunks = [], opts = {}) {
  const d = daemonsByPort.get(port);
  if (d && !/\r\nauthorization:/i.test(head)) {
    const line = head.indexOf('\r\n');
    head = `${head.slice(0, line)}\r\nAuthorization: Bearer ${await d.tokenFor()}${head.slice(line)}`;
  }
  return rawExchange(port, head, chunks, opts);
}

function rawExchange(port, head, chunks, { timeout = 10000 } = {}) {
  return new Promise((resolve, reject) => {
    const sock = net.connect(port, '127.0.0.1');
    const got = [];
    let done = false;
    const finish = (err) => {
      if (done) return;
      done = true;
      clearTimeout(timer);
      sock.destroy();
      const buf = Buffer.concat(got);
      const parsed = parseResponse(buf);
      if (parsed) resolve(parsed);
      else reject(err ?? new Error(`no complete HTTP response: ${JSON.stringify(buf.toString('latin1').slice(0, 300))}`));
    };
    const timer = setTimeout(() => finish(new Error(`raw request timed out after ${timeout} ms`)), timeout);
    sock.on('data', (b) => {
      got.push(b);
      const parsed = parseResponse(Buffer.concat(got));
      if (parsed && parsed.complete) finish();
    });
    sock.on('end', () => finish());
    sock.on('close', () => finish());
    // A server that answers early may reset the connection while we still write.
    sock.on('error', (e) => finish(e));
    sock.on('connect', () => {
      sock.write(head);
      for (const c of chunks) {
        if (sock.destroyed) break;
        sock.write(c);
      }
    });
  });
}

function parseResponse(buf) {
  const end = buf.indexOf('\r\n\r\n');
  if (end < 0) return null;
  const lines = buf.subarray(0, end).toString('latin1').split('\r\n');
  const m = /^HTTP\/1\.[01] (\d{3})/.exec(lines[0]);
  if (!m) return null;
  const headers = {};
  for (const l of lines.slice(1)) {
    const i = l.indexOf(':');
    if (i > 0) headers[l.slice(0, i).trim().toLowerCase()] = l.slice(i + 1).trim();
  }
  let rest = buf.subarray(end + 4);
  let body = rest;
  let complete = false;
  if (headers['content-length'] !== undefined) {
    const n = Number(headers['content-length']);
    complete = rest.length >= n;
    body = rest.subarray(0, n);
  } else if (/chunked/i.test(headers['transfer-encoding'] ?? '')) {
    const parts = [];
    for (;;) {
      const e = rest.indexOf('\r\n');
      if (e < 0) break;
      const n = parseInt(rest.subarray(0, e).toString('latin1'), 16);
      if (Number.isNaN(n)) break;
      if (n === 0) { complete = true; break; }
      if (rest.length < e + 2 + n + 2) break;
      parts.push(rest.subarray(e + 2, e + 2 + n));
      rest = rest.subarray(e + 2 + n + 2);
    }
    body = Buffer.concat(parts);
  }
  const text = body.toString('utf8');
  let json;
  try { json = JSON.parse(text); } catch { json = undefined; }
  return { status: Number(m[1]), headers, body, text, json, complete };
}

// --- websocket ----------------------------------------------------------------------------

// A websocket client that buffers every message; next() takes the first buffered or
// future message matching a predicate. It signs in on the handshake (Authorization: Bearer)
// as "api"; a hello naming another user reconnects as that user first (see the top).
export class WsClient {
  static async open(url, { protocol = 'archgram', timeout = 5000, token, headers = {}, origin } = {}) {
    const d = daemonsByPort.get(url);
    const user = token === undefined && d ? DEFAULT_USER : null;
    const t = token === undefined ? (d ? await d.tokenFor(user) : null) : token;
    const connect = () => WsClient.socket(url, { protocol, timeout, token: t, headers, origin });
    const c = new WsClient(await connect());
    c.daemon = user ? d : null; // only clients the harness signed in follow hello's user
    c.user = user;
    c.connectOptions = { url, protocol, timeout, headers, origin };
    return c;
  }

  static socket(url, { protocol, timeout, token, headers, origin }) {
    return new Promise((resolve, reject) => {
      const options = { headers: { ...headers } };
      if (token) options.headers.Authorization = `Bearer ${token}`;
      if (origin) options.origin = origin;
      const ws = protocol ? new WebSocket(url, protocol, options) : new WebSocket(url, options);
      const timer = setTimeout(() => {
        ws.terminate();
        reject(new Error(`websocket ${url} did not open within ${timeout} ms`));
      }, timeout);
      ws.once('open', () => { clearTimeout(timer); resolve(ws); });
      ws.once('unexpected-response', (req, res) => {
        clearTimeout(timer);
        ws.terminate();
        reject(Object.assign(new Error(`websocket ${url} refused: HTTP ${res.statusCode}`), { status: res.statusCode }));
      });
      ws.once('error', (e) => { clearTimeout(timer); reject(e); });
    });
  }

  constructor(ws) {
    this.inbox = [];
    this.waiters = [];
    this.all = [];
    this.sending = Promise.resolve();
    this.attach(ws);
  }

  attach(ws) {
    this.ws = ws;
    this.closed = new Promise((resolve) => ws.once('close', (code, reason) => resolve({ code, reason: String(reason) })));
    ws.on('error', () => {}); // surfaced through close and timeouts
    ws.on('message', (data, isBinary) => {
      if (this.ws !== ws) return;
      let msg;
      try { msg = JSON.parse(data.toString('utf8')); } catch { msg = { type: '<non-json>', raw: data.toString('utf8'), isBinary }; }
      this.all.push(msg);
      const w = this.waiters.find((x) => x.pred(msg));
      if (w) {
        this.waiters.splice(this.waiters.indexOf(w), 1);
        clearTimeout(w.timer);
        w.resolve(msg);
      } else {
        this.inbox.push(msg);
      }
    });
  }

  // Messages go out in order; a hello naming a user other than the one signed in first
  // reconnects with that user's token.
  send(msg) {
    const user = msg && typeof msg === 'object' && !Buffer.isBuffer(msg) && msg.type === 'hello' &&
      typeof msg.user === 'string' ? msg.user : null;
    this.sending = this.sending.then(async () => {
      if (user && this.daemon && user !== this.user) {
        const old = this.ws;
        old.close();
        this.attach(await WsClient.socket(this.connectOptions.url, { ...this.connectOptions, token: await this.daemon.tokenFor(user) }));
        this.user = user;
      }
      this.ws.send(typeof msg === 'string' || Buffer.isBuffer(msg) ? msg : JSON.stringify(msg));
    }).catch((e) => { this.sendError = e; });
  }

  // The next message with the given predicate (a function, or a type string).
  next(pred, timeout = 5000, what) {
    const p = typeof pred === 'string' ? (m) => m.type === pred : pred;
    const i = this.inbox.findIndex(p);
    if (i >= 0) return Promise.resolve(this.inbox.splice(i, 1)[0]);
    return new Promise((resolve, reject) => {
      const w = { pred: p, resolve };
      this.waiters.push(w);
      w.timer = setTimeout(() => {
        const k = this.waiters.indexOf(w);
        if (k < 0) return;
        this.waiters.splice(k, 1);
        reject(new Error(`websocket: no ${what ?? (typeof pred === 'string' ? pred : 'matching')} message within ${timeout} ms; ` +
          `received: ${JSON.stringify(this.all).slice(-1500)}`));
      }, timeout);
    });
  }

  // Send, then await the reply matching pred.
  request(msg, pred, timeout = 5000, what) {
    const r = this.next(pred, timeout, what);
    this.send(msg);
    return r;
  }

  // Fails when a matching message arrives (or is buffered) within `ms`.
  async none(pred, ms = 300, what = 'message') {
    const p = typeof pred === 'string' ? (m) => m.type === pred : pred;
    await sleep(ms);
    const hit = this.inbox.find(p);
    assert.equal(hit, undefined, `unexpected ${what}: ${JSON.stringify(hit)}`);
  }

  // Drop buffered messages (e.g. presence noise) before a new exchange.
  drain() {
    this.inbox.length = 0;
  }

  async close(timeout = 3000) {
    await this.sending;
    if (this.ws.readyState === WebSocket.CLOSED) return;
    this.ws.close();
    await withTimeout(this.closed, timeout, 'websocket close').catch(() => this.ws.terminate());
  }
}

// --- database -----------------------------------------------------------------------------

// Run one SQL statement with the sqlite3 CLI on a database file (the daemon must be
// stopped); returns the rows as arrays of strings.
export function sql(db, statement) {
  const r = spawnSync('sqlite3', ['-batch', '-separator', '\t', db, statement], { encoding: 'utf8', timeout: 10000 });
  if (r.error) throw r.error;
  assert.equal(r.status, 0, `sqlite3 ${statement}: ${r.stderr}`);
  return r.stdout.split('\n').filter((l) => l.length).map((l) => l.split('\t'));
}

// --- mesh files ---------------------------------------------------------------------------

// Parse a GLB container: header, JSON chunk, BIN chunk.
export function parseGlb(buf) {
  assert.ok(buf.length >= 20, `GLB too short: ${buf.length}`);
  const magic = buf.subarray(0, 4).toString('latin1');
  const version = buf.readUInt32LE(4);
  const length = buf.readUInt32LE(8);
  const jsonLen = buf.readUInt32LE(12);
  const jsonType = buf.readUInt32LE(16);
  const json = JSON.parse(buf.subarray(20, 20 + jsonLen).toString('utf8'));
  let bin = null;
  const at = 20 + jsonLen;
  if (buf.length >= at + 8) {
    const binLen = buf.readUInt32LE(at);
    const binType = buf.readUInt32LE(at + 4);
    if (binType === 0x004e4942) bin = buf.subarray(at + 8, at + 8 + binLen);
  }
  return { magic, version, length, jsonLen, jsonType, json, bin };
}

// A flat grid OBJ of about `bytes` bytes, written straight to a file (no huge strings).
export function writeGridObj(file, bytes) {
  // ~26 bytes per vertex line + ~34 per quad line, one quad per vertex.
  const n = Math.max(2, Math.ceil(Math.sqrt(bytes / 60)));
  const fd = fs.openSync(file, 'w');
  try {
    let s = '# generated grid\ng grid\n';
    for (let j = 0; j < n; j++) {
      for (let i = 0; i < n; i++) {
        s += `v ${(i * 0.1).toFixed(3)} ${(j * 0.1).toFixed(3)} ${((i * j) % 7 * 0.01).toFixed(3)}\n`;
      }
      if (s.length > 1 << 20) { fs.writeSync(fd, s); s = ''; }
    }
    for (let j = 0; j + 1 < n; j++) {
      for (let i = 0; i + 1 < n; i++) {
        const a = j * n + i + 1;
        s += `f ${a} ${a + 1} ${a + n + 1} ${a + n}\n`;
      }
      if (s.length > 1 << 20) { fs.writeSync(fd, s); s = ''; }
    }
    fs.writeSync(fd, s);
  } finally {
    fs.closeSync(fd);
  }
  return { vertices: n * n, triangles: 2 * (n - 1) * (n - 1) };
}

// A facade (y-up OBJ text): a wall slab (wall = [width, height], 0.3 m thick) and a cols × rows
// grid of identical boxed windows in front of it, a group each; the building the
// proceduralization and editing tests start from.
export function facadeObj(cols = 6, rows = 4, wall = [15, 13]) {
  const v = [];
  const f = [];
  const box = (name, x0, y0, z0, x1, y1, z1) => {
    f.push(`g ${name}`);
    const b = v.length + 1;
    for (const z of [z0, z1]) for (const y of [y0, y1]) for (const x of [x0, x1]) v.push(`v ${x} ${y} ${z}`);
    for (const q of [[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]]) {
      f.push(`f ${q.map((i) => b + i).join(' ')}`);
    }
  };
  box('wall', 0, 0, 0, wall[0], wall[1], 0.3);
  for (let j = 0; j < rows; j++) {
    for (let i = 0; i < cols; i++) {
      box(`window_${j}_${i}`, 1 + 2.5 * i, 1 + 3.2 * j, 0.3, 2.3 + 2.5 * i, 2.86 + 3.2 * j, 0.5);
    }
  }
  return `${v.join('\n')}\n${f.join('\n')}\n`;
}

// A wall (z-up OBJ text) with a grid of windows set into it, the parts library's building: a
// window is a casing holding four frame bars of width `frame`, a glass pane and `mullions`
// mullions, every piece its own group; `front` is the window's front face (0.1: set into the
// 0.3 m wall, hidden by its face; below 0: standing proud of it, in view from the front).
// `origin` moves the whole wall (a georeferenced model far from 0).
// Returns the text and each window's box (slots).
export function windowWallObj({ cols, rows, ww, wh, frame, mullions, front = 0.1, origin = [0, 0, 0] }) {
  const out = [];
  let nv = 0, n = 0;
  const at = (p, a) => p + origin[a];
  const box = (a, b) => {
    out.push(`g piece_${n++}`);
    for (let i = 0; i < 8; i++) out.push(`v ${at(i & 1 ? b[0] : a[0], 0)} ${at(i & 2 ? b[1] : a[1], 1)} ${at(i & 4 ? b[2] : a[2], 2)}`);
    const faces = [[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]];
    for (const [p, q, r, s] of faces) out.push(`f ${nv + p + 1} ${nv + q + 1} ${nv + r + 1}`, `f ${nv + p + 1} ${nv + r + 1} ${nv + s + 1}`);
    nv += 8;
  };
  const W = 1.8 + (cols - 1) * (ww + 1) + ww, H = 1 + rows * (wh + 1.2);
  box([0, 0, 0], [W, 0.3, H]);
  const slots = [];
  for (let j = 0; j < rows; j++) {
    for (let i = 0; i < cols; i++) {
      const u = 0.9 + i * (ww + 1), w = 1 + j * (wh + 1.2), v0 = front, v1 = front + 0.16;
      box([u, v0, w], [u + ww, v1, w + wh]);
      box([u, v0, w], [u + ww, v1, w + frame]);
      box([u, v0, w + wh - frame], [u + ww, v1, w + wh]);
      box([u, v0, w + frame], [u + frame, v1, w + wh - frame]);
      box([u + ww - frame, v0, w + frame], [u + ww, v1, w + wh - frame]);
      box([u + frame, v0 + 0.07, w + frame], [u + ww - frame, v0 + 0.08, w + wh - frame]);
      for (let k = 0; k < mullions; k++) {
        const c = u + frame + (ww - 2 * frame) * (k + 1) / (mullions + 1);
        box([c - 0.025, v0 + 0.03, w + frame], [c + 0.025, v0 + 0.13, w + wh - frame]);
      }
      slots.push([u, v0, w, u + ww, v1, w + wh].map((x, k) => at(x, k % 3)));
    }
  }
  return { obj: out.join('\n') + '\n', slots };
}

// A windowWallObj wall imported z-up and proceduralized (the job asserted to succeed):
// { id, slots }.
export async function proceduralizedWall(d, opt, name) {
  const { obj, slots } = windowWallObj(opt);
  const m = await importModel(d, Buffer.from(obj), { name, up: 'z' });
  const r = await http(d, 'POST', `/api/v1/models/${m.id}/proceduralize`, {});
  if (r.status !== 202) throw new Error(`proceduralize: ${r.status} ${r.text}`);
  const job = await waitJob(d, r.json.id, { timeout: 60000 });
  if (job.status !== 'succeeded') throw new Error(`proceduralize job: ${JSON.stringify(job)}`);
  return { id: m.id, slots };
}
