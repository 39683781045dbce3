// archgram import through the service: upload the largest OBJ in ../shared/data and time
// POST → job succeeded. Prints figures; not a test.
import fs from 'node:fs';
import path from 'node:path';
import { performance } from 'node:perf_hooks';
import {
  DAEMON, http, removeDir, REPO, sleep, startDaemon,
} from '../tests/integration/harness.js';

const SHARED = path.join(REPO, '..', 'shared', 'data');

function largestObj(dir) {
  let best = null;
  const walk = (d) => {
    for (const e of fs.readdirSync(d, { withFileTypes: true })) {
      const p = path.join(d, e.name);
      if (e.isDirectory()) walk(p);
      else if (/\.obj$/i.test(e.name)) {
        const size = fs.statSync(p).size;
        if (!best || size > best.size) best = { path: p, size };
      }
    }
  };
  walk(dir);
  return best;
}

// Peak resident memory of a process, from /proc (Linux).
function peakRssKiB(pid) {
  try {
    const m = /VmHWM:\s+(\d+) kB/.exec(fs.readFileSync(`/proc/${pid}/status`, 'utf8'));
    return m ? Number(m[1]) : null;
  } catch { return null; }
}

if (!fs.existsSync(SHARED)) {
  console.log(`bench/import_service.js: ${SHARED} is absent; skipped`);
  process.exit(0);
}
if (!fs.existsSync(DAEMON)) {
  console.log(`bench/import_service.js: ${DAEMON} is missing (make build/archgramd); skipped`);
  process.exit(0);
}
const file = largestObj(SHARED);
if (!file) {
  console.log(`bench/import_service.js: no .obj under ${SHARED}; skipped`);
  process.exit(0);
}

const body = fs.readFileSync(file.path);
const d = await startDaemon();
try {
  const t0 = performance.now();
  const r = await http(d, 'POST', `/api/v1/models?name=${encodeURIComponent(path.basename(file.path))}&format=obj`, {
    body, headers: { 'Content-Type': 'application/octet-stream' }, timeout: 300000,
  });
  const tAccepted = performance.now();
  if (r.status !== 202) throw new Error(`upload → ${r.status} ${r.text}`);
  let job = r.json;
  while (!['succeeded', 'failed', 'cancelled'].includes(job.status)) {
    if (performance.now() - t0 > 300000) throw new Error(`job ${job.id} still ${job.status} after 300 s`);
    await sleep(5);
    job = (await http(d, 'GET', `/api/v1/jobs/${job.id}`)).json;
  }
  const tDone = performance.now();
  if (job.status !== 'succeeded') throw new Error(`import ${job.status}: ${JSON.stringify(job.error)}`);
  const model = (await http(d, 'GET', job.result.href)).json;
  const tg = performance.now();
  const glb = await http(d, 'GET', model.mesh);
  const tGlb = performance.now();
  const rel = path.relative(path.join(REPO, '..'), file.path);
  console.log(`import service: ${rel} (${(file.size / 1e6).toFixed(2)} MB): ` +
    `${model.stats.vertices} vertices, ${model.stats.triangles} triangles, ${model.stats.components} components`);
  console.log(`import service: POST → 202 ${((tAccepted - t0) / 1000).toFixed(3)} s; ` +
    `POST → job succeeded ${((tDone - t0) / 1000).toFixed(3)} s (polled every 5 ms)`);
  console.log(`import service: first GET mesh.glb ${((tGlb - tg) / 1000).toFixed(3)} s, ${glb.body.length} bytes`);
  const peak = peakRssKiB(d.proc.pid);
  if (peak !== null) console.log(`import service: archgramd peak RSS ${(peak / 1024).toFixed(1)} MiB`);
} finally {
  await d.stop();
  removeDir(d.dir);
}
