// archgram point clouds through the service: upload → stored model (POST → import job
// succeeded) and GET points.glb at a budget of 1,000,000 points, with archgramd's peak
// resident memory after each; for the AHN3 crop in ../shared/data (640,510 points, LAZ;
// skipped when absent) and a generated 2,000,000-point binary PLY (so the GLB really holds a
// million points). Prints figures; not a test.
import fs from 'node:fs';
import path from 'node:path';
import { performance } from 'node:perf_hooks';
import { DAEMON, http, removeDir, REPO, sleep, startDaemon } from '../tests/integration/harness.js';
import { boxCloud, plyBytes } from '../tests/integration/clouds.js';

const AHN3 = path.join(REPO, '..', 'shared', 'data', 'pointcloud_ahn3_delft', 'ahn3_cropped_1.laz');
const BUDGET = 1000000;
const GENERATED = 2000000;

// Peak resident memory of a process so far, from /proc (Linux).
function peakRssMiB(pid) {
  try {
    const m = /VmHWM:\s+(\d+) kB/.exec(fs.readFileSync(`/proc/${pid}/status`, 'utf8'));
    return m ? Number(m[1]) / 1024 : null;
  } catch { return null; }
}

const mib = (v) => (v === null ? '?' : `${v.toFixed(1)} MiB`);
const secs = (a, b) => `${((b - a) / 1000).toFixed(3)} s`;

async function run(d, what, body, format) {
  const t0 = performance.now();
  const r = await http(d, 'POST', `/api/v1/models?name=${encodeURIComponent(what)}&format=${format}`, {
    body, headers: { 'Content-Type': 'application/octet-stream' }, timeout: 600000,
  });
  if (r.status !== 202) throw new Error(`${what}: upload → ${r.status} ${r.text}`);
  let job = r.json;
  while (!['succeeded', 'failed', 'cancelled'].includes(job.status)) {
    if (performance.now() - t0 > 600000) throw new Error(`${what}: job ${job.id} still ${job.status} after 600 s`);
    await sleep(5);
    job = (await http(d, 'GET', `/api/v1/jobs/${job.id}`)).json;
  }
  const tStored = performance.now();
  if (job.status !== 'succeeded') throw new Error(`${what}: import ${job.status}: ${JSON.stringify(job.error)}`);
  const rssStored = peakRssMiB(d.proc.pid);
  const model = (await http(d, 'GET', job.result.href)).json;
  const tg = performance.now();
  const glb = await http(d, 'GET', `/api/v1/models/${model.id}/points.glb?budget=${BUDGET}`, { timeout: 600000 });
  const tGlb = performance.now();
  if (glb.status !== 200) throw new Error(`${what}: points.glb → ${glb.status} ${glb.text.slice(0, 300)}`);
  const again = await http(d, 'GET', `/api/v1/models/${model.id}/points.glb?budget=${BUDGET}`, {
    headers: { 'If-None-Match': glb.headers.get('etag') },
  });
  const tAgain = performance.now();
  const rssGlb = peakRssMiB(d.proc.pid);
  const shown = Math.min(BUDGET, model.stats.points);
  console.log(`points service: ${what} (${(body.length / 1e6).toFixed(2)} MB ${format}, ${model.stats.points} points): ` +
    `upload → stored model ${secs(t0, tStored)}, archgramd peak RSS ${mib(rssStored)}`);
  console.log(`points service: ${what}: points.glb?budget=${BUDGET} (${shown} points, ${(glb.body.length / 1e6).toFixed(1)} MB) ` +
    `${secs(tg, tGlb)}, peak RSS ${mib(rssGlb)}; again with If-None-Match → ${again.status} in ${secs(tGlb, tAgain)}`);
}

if (!fs.existsSync(DAEMON)) {
  console.log(`bench/points_service.js: ${DAEMON} is missing (make build/archgramd); skipped`);
  process.exit(0);
}

// A fresh daemon per cloud, so each peak RSS is that cloud's.
async function withDaemon(fn) {
  const d = await startDaemon();
  try {
    await fn(d);
  } finally {
    await d.stop();
    removeDir(d.dir);
  }
}

if (fs.existsSync(AHN3)) {
  await withDaemon((d) => run(d, 'AHN3 crop', fs.readFileSync(AHN3), 'laz'));
} else {
  console.log(`bench/points_service.js: ${path.relative(path.join(REPO, '..'), AHN3)} is absent; the AHN3 figure is skipped`);
}
const box = boxCloud(GENERATED, [84808, 447412, 3]);
const ply = plyBytes([['x', 'double', box.x], ['y', 'double', box.y], ['z', 'double', box.z], ['classification', 'uchar', box.cls]]);
await withDaemon((d) => run(d, `generated box, ${GENERATED} points`, ply, 'ply'));
