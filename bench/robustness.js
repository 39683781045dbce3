// archgram under abuse and load, figures only (not a test):
//   - a new client's GET /api/v1/health beside 2,000 partial requests (slowloris) held open
//     from 40 loopback addresses;
//   - GET /api/v1/health while 8 extrusion previews of an 838-corner plan run;
//   - how long archgramd takes to stop after SIGTERM while a long edit runs.
// Needs about 2,100 file descriptors (ulimit -n).
import fs from 'node:fs';
import net from 'node:net';
import { performance } from 'node:perf_hooks';
import {
  DAEMON, http, removeDir, sleep, startDaemon, waitJob,
} from '../tests/integration/harness.js';

if (!fs.existsSync(DAEMON)) {
  console.log(`bench/robustness.js: ${DAEMON} is missing (make build/archgramd); skipped`);
  process.exit(0);
}

const ms = (t) => `${t.toFixed(1)} ms`;
function summary(v) {
  const s = [...v].sort((a, b) => a - b);
  return `median ${ms(s[Math.floor(s.length / 2)])}, max ${ms(s.at(-1))}`;
}

function rawHealth(port, localAddress) {
  return new Promise((resolve, reject) => {
    const t0 = performance.now();
    const s = net.connect({ port, host: '127.0.0.1', localAddress }, () => {
      s.write('GET /api/v1/health HTTP/1.1\r\nHost: x\r\nConnection: close\r\n\r\n');
    });
    let got = '';
    s.on('data', (b) => { got += b; });
    s.on('end', () => (got.startsWith('HTTP/1.1 200') ? resolve(performance.now() - t0) : reject(new Error(got.slice(0, 80)))));
    s.on('error', reject);
  });
}

async function slowloris() {
  const d = await startDaemon({ args: ['--no-web', '--rate-rest', '0', '--header-timeout', '10'] });
  const sockets = [];
  try {
    for (let a = 10; a < 50; a++) {
      await Promise.all([...Array(50).keys()].map(() => new Promise((resolve) => {
        const s = net.connect({ port: d.port, host: '127.0.0.1', localAddress: `127.0.0.${a}` });
        s.on('error', () => {});
        s.on('connect', () => { s.write('GET /api/v1/health HTTP/1.1\r\nHost: x\r\n'); resolve(); });
        setTimeout(resolve, 3000);
        sockets.push(s);
      })));
    }
    const trickle = setInterval(() => { for (const s of sockets) if (!s.destroyed) s.write('X'); }, 1000);
    await sleep(500);
    const held = (await http(d, 'GET', '/api/v1/health')).json.http.connections;
    const t = [];
    for (let i = 0; i < 20; i++) t.push(await rawHealth(d.port, '127.0.0.2'));
    clearInterval(trickle);
    console.log(`slowloris: ${sockets.length} partial requests sent, ${held} held by the server; ` +
      `a new client's health: ${summary(t)}`);
  } finally {
    for (const s of sockets) s.destroy();
    await d.stop(10000);
    removeDir(d.dir);
  }
}

function plan838() {
  const pts = [];
  let seed = 7;
  const rnd = () => { seed = (seed * 1103515245 + 12345) % 2147483648; return seed / 2147483648; };
  for (let i = 0; i < 838; i++) {
    const a = (2 * Math.PI * i) / 838;
    const r = 40 + 3 * Math.sin(17 * a) + 1.5 * Math.sin(41 * a) + (rnd() - 0.5) * 0.6;
    pts.push([+(r * Math.cos(a)).toFixed(4), +(r * Math.sin(a)).toFixed(4)]);
  }
  return { profiles: { hip: { points: [[0, 0], [0, 6], [1, 7]] } }, default_profile: 'hip', loops: [{ points: pts }] };
}

async function previews() {
  const d = await startDaemon({ args: ['--no-web', '--rate-rest', '0'] });
  try {
    const body = JSON.stringify(plan838());
    let done = false;
    const t = [];
    const probe = (async () => {
      while (!done) {
        const t0 = performance.now();
        await http(d, 'GET', '/api/v1/health');
        t.push(performance.now() - t0);
        await sleep(10);
      }
    })();
    const t0 = performance.now();
    await Promise.all([...Array(8).keys()].map(() => http(d, 'POST', '/api/v1/extrusions/preview', {
      body, headers: { 'Content-Type': 'application/json' }, timeout: 300000,
    })));
    const all = performance.now() - t0;
    done = true;
    await probe;
    console.log(`previews: 8 of an 838-corner plan in ${ms(all)}; health meanwhile (${t.length} requests): ${summary(t)}`);
  } finally {
    await d.stop();
    removeDir(d.dir);
  }
}

async function sigterm() {
  const d = await startDaemon({ args: ['--no-web', '--demo'] });
  try {
    for (let i = 1; i <= 3; i++) await waitJob(d, i, { timeout: 60000 });
    const resize = async (scale) => {
      const v = (await http(d, 'GET', '/api/v1/models/2')).json.version;
      return http(d, 'POST', '/api/v1/models/2/ops', {
        body: { op: { kind: 'resize', node: 'root', scale } }, headers: { 'If-Match': `"${v}"` }, timeout: 300000,
      });
    };
    for (const s of [[4, 1, 1], [8, 1, 1], [8, 1, 1]]) await resize(s);
    const t0 = performance.now();
    const long = resize([2, 2, 1]).catch(() => null);
    await sleep(300);
    const { ms: stop } = await d.stop(10000);
    await long;
    console.log(`sigterm: stopped ${ms(stop)} after SIGTERM, with an edit of ${ms(performance.now() - t0 - stop)} under way`);
  } finally {
    removeDir(d.dir);
  }
}

await slowloris();
await previews();
await sigterm();
