// archgram live editing latency: two clients in the room of a proceduralized demo building;
// A commits resize ops (each solved, rebuilt without re-proceduralizing and stored) and sends
// drag previews (solved with the kept factorization, never stored); prints op→ack,
// op→broadcast (to B) and preview→room (to B) times. Then the same committed ops on the
// generated 20k- and 200k-triangle buildings of bench/edit (written by `build/bench/edit
// --write-obj`), the tree served after them, and split, remove, paste and join there. Target: an op reaches
// the other clients ≤ 50 ms after it is sent at 200k.
// Prints figures; not a test.
import fs from 'node:fs';
import os from 'node:os';
import { performance } from 'node:perf_hooks';
import { execFileSync } from 'node:child_process';
import path from 'node:path';
import { DAEMON, http, importModel, removeDir, sleep, startDaemon, waitJob, WsClient } from '../tests/integration/harness.js';

// `node bench/edit_ws.js [--sizes 20k,200k] [--no-demo]` runs a part of it (to profile one size)
const argv = process.argv.slice(2);
const sizesArg = argv.indexOf('--sizes');
const SIZES = sizesArg >= 0 ? argv[sizesArg + 1].split(',') : ['20k', '200k'];
const DEMO = !argv.includes('--no-demo');
const OPS = 60;
const PREVIEWS = 200;

function summary(ms) {
  const s = [...ms].sort((a, b) => a - b);
  const q = (p) => s[Math.min(s.length - 1, Math.floor(p * s.length))];
  return `median ${q(0.5).toFixed(2)} ms, p95 ${q(0.95).toFixed(2)} ms, max ${s.at(-1).toFixed(2)} ms (n=${s.length})`;
}

if (!fs.existsSync(DAEMON)) {
  console.log(`bench/edit_ws.js: ${DAEMON} is missing (make build/archgramd); skipped`);
  process.exit(0);
}

// archgramd's CPU time so far (user + system, ms), from /proc: the op's cost apart from what
// else the machine runs (the wall times above depend on the load of a shared machine).
function daemonCpuMs() {
  try {
    const f = fs.readFileSync(`/proc/${d.proc.pid}/stat`, 'utf8').split(') ')[1].split(' ');
    return (Number(f[11]) + Number(f[12])) * 10; // fields 14 and 15, at 100 ticks/s
  } catch {
    return NaN;
  }
}

// Committed resize ops on a model: the root alternately 1.25x wider and back (global), then a
// window alternately 0.2 m taller and back (global: every window of its rule follows).
async function committedOps(model, A, B, version, what) {
  const toAck = [];
  const toPeer = [];
  let cpu = 0;
  for (let i = 0; i < OPS; i++) {
    const cid = `edit-${model.id}-${i}`;
    const t = (await http(d, 'GET', `/api/v1/models/${model.id}/tree`, { timeout: 60000 })).json;
    let node = 'root';
    let box = [...t.nodes.find((n) => n.id === t.root).box];
    if (i < OPS / 2) {
      box[3] = box[0] + (box[3] - box[0]) * (i % 2 ? 1 / 1.25 : 1.25);
    } else {
      const w = t.nodes.find((n) => n.visible && n.box[3] - n.box[0] < 2 && n.box[5] - n.box[2] < 3 && n.box[3] - n.box[0] > 0.3) ??
        t.nodes.find((n) => n.visible);
      node = w.id;
      box = [...w.box];
      box[5] += i % 2 ? -0.2 : 0.2;
    }
    const ack = A.next((m) => (m.type === 'ack' || m.type === 'nack') && m.cid === cid, 60000);
    const seen = B.next((m) => m.type === 'op' && m.cid === cid, 60000);
    const c0 = daemonCpuMs();
    const ts = performance.now();
    A.send({ type: 'op', base: version, cid, op: { kind: 'resize', node, box, mode: 'global' } });
    const [a] = await Promise.all([
      ack.then((m) => { toAck.push(performance.now() - ts); return m; }),
      seen.then(() => { toPeer.push(performance.now() - ts); }),
    ]);
    cpu += daemonCpuMs() - c0;
    if (a.type !== 'ack') throw new Error(`op ${i} on ${what} refused: ${JSON.stringify(a)}`);
    version = a.version;
    A.all.length = 0;
    B.all.length = 0;
  }
  console.log(`edit ws ${what}: op→ack ${summary(toAck)}`);
  console.log(`edit ws ${what}: op→broadcast ${summary(toPeer)}   (target ≤ 50 ms at 200k)`);
  console.log(`edit ws ${what}: archgramd CPU per op ${(cpu / OPS).toFixed(1)} ms (user + system, ` +
    `all threads, from op sent to ack and broadcast received; load average ${os.loadavg()[0].toFixed(2)})`);
}

// Committed split, remove, paste and join ops on a model, each on other windows of the tree
// read once before them all (they keep node ids, so those ids stay valid): op→ack and
// op→broadcast per kind.
const STRUCTURAL = 10;
async function structuralOps(model, A, B, version, what) {
  const t = (await http(d, 'GET', `/api/v1/models/${model.id}/tree`, { timeout: 60000 })).json;
  const wins = t.nodes.filter((n) => n.visible && n.children.length === 0 && n.box[3] - n.box[0] < 2 &&
    n.box[5] - n.box[2] < 3 && n.box[3] - n.box[0] > 0.3 && n.box[4] - n.box[1] < 1);
  if (wins.length < 6 * STRUCTURAL) { console.log(`edit ws ${what}: ${wins.length} windows; structural ops skipped`); return version; }
  const kinds = {
    split: (i) => { const w = wins[i]; return { kind: 'split', node: w.id, axis: 'x', at: 0.5 * (w.box[0] + w.box[3]) }; },
    remove: (i) => ({ kind: 'remove', nodes: [wins[STRUCTURAL + i].id] }),
    paste: (i) => ({ kind: 'paste', source: [wins[2 * STRUCTURAL + i].id], target: wins[3 * STRUCTURAL + i].id, placement: 'replace', fit: 'derive' }),
    join: (i) => ({ kind: 'join', nodes: [wins[4 * STRUCTURAL + 2 * i].id, wins[4 * STRUCTURAL + 2 * i + 1].id] }),
  };
  for (const [name, make] of Object.entries(kinds)) {
    const toAck = [];
    const toPeer = [];
    let cpu = 0;
    for (let i = 0; i < STRUCTURAL; i++) {
      const cid = `${name}-${model.id}-${i}`;
      const ack = A.next((m) => (m.type === 'ack' || m.type === 'nack') && m.cid === cid, 60000);
      const seen = B.next((m) => m.type === 'op' && m.cid === cid, 60000);
      const c0 = daemonCpuMs();
      const ts = performance.now();
      A.send({ type: 'op', base: version, cid, op: make(i) });
      const [a] = await Promise.all([
        ack.then((m) => { toAck.push(performance.now() - ts); return m; }),
        seen.then(() => { toPeer.push(performance.now() - ts); }),
      ]);
      cpu += daemonCpuMs() - c0;
      if (a.type !== 'ack') throw new Error(`${name} ${i} on ${what} refused: ${JSON.stringify(a)}`);
      version = a.version;
      A.all.length = 0;
      B.all.length = 0;
    }
    console.log(`edit ws ${what}: ${name} op→ack ${summary(toAck)}; op→broadcast ${summary(toPeer)}; ` +
      `archgramd CPU per op ${(cpu / STRUCTURAL).toFixed(1)} ms`);
  }
  return version;
}

const d = await startDaemon({ args: ['--demo'] });
let A;
let B;
try {
  // the demo's first building, once its proceduralize job has run
  let model;
  if (DEMO) {
    for (const t0 = Date.now(); Date.now() - t0 < 60000; await sleep(100)) {
      model = (await http(d, 'GET', '/api/v1/models/1')).json;
      if (model && model.proceduralized) break;
    }
    if (!model || !model.proceduralized) throw new Error('the demo building was not proceduralized');
    const tree = (await http(d, 'GET', `/api/v1/models/${model.id}/tree`)).json;
    console.log(`edit ws: model "${model.name}", ${tree.nodes.length} tree nodes, ${model.stats.triangles} triangles`);

    A = await WsClient.open(d.wsUrl);
    B = await WsClient.open(d.wsUrl);
    let version = (await A.request({ type: 'hello', model: model.id, user: 'a' }, 'welcome')).version;
    await B.request({ type: 'hello', model: model.id, user: 'b' }, 'welcome');
    await A.next('join');

    // drag previews: root stretched by a varying amount, one at a time (the server keeps 30/s
    // per connection, so they are spaced 34 ms apart)
    const box0 = tree.nodes.find((n) => n.id === tree.root).box;
    const toRoom = [];
    for (let i = 0; i < PREVIEWS; i++) {
      const box = [...box0];
      box[3] = box0[0] + (box0[3] - box0[0]) * (1 + 0.3 * ((i % 20) / 20));
      const seen = B.next((m) => m.type === 'preview', 10000);
      const ts = performance.now();
      A.send({ type: 'preview', model: model.id, base: version, op: { kind: 'resize', node: 'root', box, mode: 'global' } });
      await seen;
      toRoom.push(performance.now() - ts);
      B.all.length = 0;
      await sleep(34);
    }
    A.send({ type: 'preview.end' });

    console.log(`edit ws preview→room:   ${summary(toRoom)}`);
    await committedOps(model, A, B, version, 'demo building');
  }

  // An op stores its tree bare (app/model_kept.h): the first GET …/tree after it prints the
  // served tree from the edit model, and every later reader of that version shares the print.
  async function treeAfterOps(m, label) {
    const times = [];
    let bytes = 0;
    for (let i = 0; i < 2; i++) {
      const t0 = performance.now();
      const r = await http(d, 'GET', `/api/v1/models/${m.id}/tree`);
      times.push(performance.now() - t0);
      if (r.status !== 200) throw new Error(`GET tree: ${r.status} ${r.text}`);
      bytes = r.text.length;
    }
    console.log(`edit ws ${label}: GET …/tree after the ops ${times[0].toFixed(1)} ms (printed from the edit model), again ${times[1].toFixed(1)} ms (${(bytes / 1e6).toFixed(1)} MB)`);
  }

  // the generated buildings, uploaded z-up and proceduralized
  const bench = path.join(path.dirname(DAEMON), 'bench', 'edit');
  for (const size of SIZES) {
    if (!fs.existsSync(bench)) {
      console.log(`edit ws: ${bench} is missing (make build/bench/edit); generated buildings skipped`);
      break;
    }
    const file = path.join(d.dir, `gen${size}.obj`);
    execFileSync(bench, ['--write-obj', size, file]);
    const m = await importModel(d, fs.readFileSync(file), { name: `generated ${size}`, up: 'z' });
    const r = await http(d, 'POST', `/api/v1/models/${m.id}/proceduralize`, {});
    const job = await waitJob(d, r.json.id, { timeout: 300000, interval: 200 });
    if (job.status !== 'succeeded') throw new Error(`proceduralize ${size}: ${JSON.stringify(job)}`);
    const g = (await http(d, 'GET', `/api/v1/models/${m.id}`)).json;
    const GA = await WsClient.open(d.wsUrl);
    const GB = await WsClient.open(d.wsUrl);
    try {
      const v = (await GA.request({ type: 'hello', model: g.id, user: 'a' }, 'welcome')).version;
      await GB.request({ type: 'hello', model: g.id, user: 'b' }, 'welcome');
      await committedOps(g, GA, GB, v, `generated ${size} (${g.stats.triangles} triangles)`);
      await treeAfterOps(g, `generated ${size}`);
      const now = (await http(d, 'GET', `/api/v1/models/${g.id}`)).json.version;
      await structuralOps(g, GA, GB, now, `generated ${size}`);
    } finally {
      await GA.close();
      await GB.close();
    }
  }
} finally {
  if (A) await A.close();
  if (B) await B.close();
  await d.stop();
  removeDir(d.dir);
}
