// Starts a real archgramd on a free loopback port with a temporary database for a test.
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
    if (r.ok) return handle(port, dir, r);
    last = r.reason;
    if (!r.inUse) break;
  }
  await rm(dir, { recursive: true, force: true });
  throw new Error(`archgramd did not start: ${last}`);
}
