// archgram under abuse and load, figures only (not a test):
//   - a new client's GET /api/v1/health beside 2,000 partial requests (slowloris) held open
//     from 40 loopback addresses;
//   - GET /api/v1/health while 8 extrusion previews of an 838-corner plan run;
//   - how long archgramd takes to stop after SIGTERM while a long edit runs.
// Needs about 2,100 file descriptors (ulimit -n).
import fs from 'node:fs';
import { performance } from 'node:perf_hooks';
import {
  DAEMON, http, removeDir, sleep, startDaemon, waitJob,
} from '../tests/integration/harness.js';
import { healthFrom, partialRequest } from '../tests/integration/clients.js';
import { plan838 } from '../tests/integration/generated.js';

if (!fs.existsSync(DAEMON)) {
  console.log(`bench/robustness.js: ${DAEMON} is missing (make build/archgramd); skipped`);
  process.exit(0);
}

const ms = (t) => `${t.toFixed(1)} ms`;
function summary(v) {
  const s = [...v].sort((a, b) => a - b);
  return `median ${ms(s[Math.floor(s.length / 2)])}, max ${ms(s.at(-1))}`;
}


async function slowloris() {
  const d = await startDaemon({ args: ['--no-web', '--rate-rest', '0', '--header-timeout', '10'] });
  const sockets = [];
  try {
    for (let a = 10; a < 50; a++) {
      sockets.push(...await Promise.all([...Array(50).keys()].map(() => partialRequest(d.port, `127.0.0.${a}`))));
    }
    const trickle = setInterval(() => { for (const s of sockets) if (!s.destroyed) s.write('X'); }, 1000);
    await sleep(500);
    const held = (await http(d, 'GET', '/api/v1/health')).json.http.connections;
    const t = [];
    for (let i = 0; i < 20; i++) t.push((await healthFrom(d.port, '127.0.0.2')).ms);
    clearInterval(trickle);
    console.log(`slowloris: ${sockets.length} partial requests sent, ${held} held by the server; ` +
      `a new client's health: ${summary(t)}`);
  } finally {
    for (const s of sockets) s.destroy();
    await d.stop(10000);
    removeDir(d.dir);
  }
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
