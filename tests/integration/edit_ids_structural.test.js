// Split, remove and paste keep node ids through the service: after a split of the wall every
// node keeps its id (the wall's own id names its lower half, the copy is appended) and a
// resize naming the wall by its old id applies to it; an op made before another person's
// split, remove or paste and naming a node the edit left alone is rebased with that same id;
// one naming a node the edit removed is nacked saying so; undo gives the tree back exactly.
import assert from 'node:assert/strict';
import { after, before, describe, it } from 'node:test';
import {
  http, importModel, removeDir, startDaemon, tempDir, waitJob, WsClient,
  facadeObj as sharedFacadeObj,
} from './harness.js';

const near = (a, b, eps = 1e-6) => Math.abs(a - b) <= eps;
const sameBox = (a, b, eps = 1e-6) => a.every((v, k) => near(v, b[k], eps));
const size = (b, a) => b[3 + a] - b[a];

describe('split, remove and paste keep node ids', () => {
  const dir = tempDir();
  let d;
  let model;
  const clients = [];

  const open = async (user) => {
    const c = await WsClient.open(d.wsUrl);
    clients.push(c);
    await c.request({ type: 'hello', model: model.id, user }, 'welcome');
    return c;
  };
  const tree = async () => {
    const r = await http(d, 'GET', `/api/v1/models/${model.id}/tree`);
    assert.equal(r.status, 200, r.text);
    return r.json;
  };
  const nodesText = (t) => JSON.stringify({ nodes: t.nodes, labels: t.labels, rules: t.rules });
  const reply = (cid) => (m) => (m.type === 'ack' || m.type === 'nack') && m.cid === cid;
  const wallOf = (t) => t.nodes.filter((n) => n.visible)
    .sort((a, b) => size(b.box, 0) * size(b.box, 2) - size(a.box, 0) * size(a.box, 2))[0];
  const windowsOf = (t) => { const w = wallOf(t); return t.nodes.filter((n) => n.visible && n.label !== w.label); };
  const below = (t, id) => { // ids of id's subtree
    const out = new Set([id]);
    const walk = (n) => { for (const c of t.nodes[n].children ?? []) { out.add(c); walk(c); } };
    walk(id);
    return out;
  };
  // every node of a that is not in `touched` has its id, kind, label and box in b
  const keptAlone = (a, b, touched, what) => {
    for (const n of a.nodes) {
      if (n.kind === 'dead' || touched.has(n.id) || n.kind === 'split' || n.kind === 'pattern') continue;
      const m = b.nodes[n.id];
      assert.ok(m && m.id === n.id, `${what}: node ${n.id} is gone from the numbering`);
      assert.equal(m.kind, n.kind, `${what}: node ${n.id} changed kind`);
      assert.equal(m.label, n.label, `${what}: node ${n.id} changed label`);
      assert.ok(sameBox(m.box, n.box), `${what}: node ${n.id} moved ${JSON.stringify([n.box, m.box])}`);
    }
  };
  const timed = async (c, msg) => {
    const t = performance.now();
    const r = await c.request(msg, reply(msg.cid), 60000);
    console.log(`# ${msg.op.kind} ${msg.cid}: ${(performance.now() - t).toFixed(1)} ms to the ${r.type}`);
    return r;
  };

  before(async () => {
    d = await startDaemon({ dir, args: ['--workers', '1', '--no-web'] });
    model = await importModel(d, Buffer.from(sharedFacadeObj(6, 4)), { name: 'facade' });
    const r = await http(d, 'POST', `/api/v1/models/${model.id}/proceduralize`, {});
    assert.equal(r.status, 202, r.text);
    const job = await waitJob(d, r.json.id, { timeout: 60000 });
    assert.equal(job.status, 'succeeded', JSON.stringify(job));
    model = (await http(d, 'GET', `/api/v1/models/${model.id}`)).json;
  });
  after(async () => {
    for (const c of clients) await c.close().catch(() => {});
    if (d) { try { await d.stop(); } finally { await d.kill(); } }
    removeDir(dir);
  });

  it('a split keeps every id; the wall resized by its old id; rebased ops keep their ids; a removed node is nacked', async () => {
    const A = await open('ana');
    const B = await open('bo');
    const t0 = await tree();
    const wall = wallOf(t0);
    const wins = windowsOf(t0);
    assert.equal(wins.length, 24);

    // ana splits the wall at 40 % of its width
    const at = wall.box[0] + 0.4 * size(wall.box, 0);
    const split = await timed(A, { type: 'op', base: t0.version, cid: 'split', op: { kind: 'split', node: wall.id, axis: 'x', at } });
    assert.equal(split.type, 'ack', JSON.stringify(split));
    const t1 = await tree();
    const inWall = below(t0, wall.id);
    keptAlone(t0, t1, inWall, 'split');
    // the wall's id names the lower half; its copy (same label) is appended with the upper one
    const lower = [...wall.box];
    lower[3] = at;
    const upper = [...wall.box];
    upper[0] = at;
    assert.ok(sameBox(t1.nodes[wall.id].box, lower), JSON.stringify(t1.nodes[wall.id]));
    assert.equal(t1.nodes[wall.id].label, wall.label);
    const copy = t1.nodes.find((n) => n.id >= t0.nodes.length && n.visible && sameBox(n.box, upper));
    assert.ok(copy && copy.label === wall.label, 'the upper half is an appended copy of the wall');
    for (const id of inWall) if (t0.nodes[id].visible) assert.ok(t1.nodes[id].visible, `node ${id} of the wall lost its id`);

    // bo resizes a window on the version before the split: rebased, the same id
    const w = wins[3];
    const wb = [...w.box];
    wb[5] += 0.2;
    const seen = A.next((m) => m.type === 'op' && m.cid === 'bo-win', 60000, 'bo-win');
    const rb = await timed(B, { type: 'op', base: t0.version, cid: 'bo-win', op: { kind: 'resize', node: w.id, box: wb, mode: 'local' } });
    assert.equal(rb.type, 'ack', JSON.stringify(rb));
    assert.equal((await seen).op.node, w.id, 'the rebased op names the window by its id');
    const t2 = await tree();
    assert.ok(near(size(t2.nodes[w.id].box, 2), size(w.box, 2) + 0.2), JSON.stringify(t2.nodes[w.id]));

    // ana resizes the wall (its lower half) by its old id
    const tall = [...t2.nodes[wall.id].box];
    tall[4] += 0.5;
    const rw = await timed(A, { type: 'op', base: rb.version, cid: 'wall', op: { kind: 'resize', node: wall.id, box: tall, mode: 'local' } });
    assert.equal(rw.type, 'ack', JSON.stringify(rw));
    const t3 = await tree();
    assert.equal(t3.nodes[wall.id].label, wall.label);
    assert.ok(near(size(t3.nodes[wall.id].box, 1), size(tall, 1)), JSON.stringify(t3.nodes[wall.id]));

    // ana removes a window; bo's ops made before it: on another window rebased with its id, on
    // the removed one nacked naming it removed
    const [gone, stays] = [windowsOf(t3)[0], windowsOf(t3)[5]];
    const rm = await timed(A, { type: 'op', base: rw.version, cid: 'rm', op: { kind: 'remove', nodes: [gone.id] } });
    assert.equal(rm.type, 'ack', JSON.stringify(rm));
    const t4 = await tree();
    assert.equal(t4.nodes[gone.id].kind, 'dead');
    keptAlone(t3, t4, below(t3, gone.id), 'remove');
    const grow = (n) => { const b = [...n.box]; b[5] += 0.1; return { kind: 'resize', node: n.id, box: b, mode: 'local' }; };
    const lost = await timed(B, { type: 'op', base: rw.version, cid: 'bo-gone', op: grow(gone) });
    assert.equal(lost.type, 'nack', JSON.stringify(lost));
    assert.equal(lost.problem.type, 'urn:archgram:problem:stale');
    assert.match(lost.problem.detail, new RegExp(`the remove op of version ${rm.version} by ana removed node ${gone.id}`));
    const kept = await timed(B, { type: 'op', base: rw.version, cid: 'bo-stays', op: grow(stays) });
    assert.equal(kept.type, 'ack', JSON.stringify(kept));
    const t5 = await tree();
    assert.ok(near(t5.nodes[stays.id].box[5], stays.box[5] + 0.1), JSON.stringify(t5.nodes[stays.id]));

    // ana pastes a window onto another; undo gives the tree before it back exactly
    const [src, dst] = [windowsOf(t5)[1], windowsOf(t5)[2]];
    const paste = await timed(A, { type: 'op', base: kept.version, cid: 'paste', op: { kind: 'paste', source: [src.id], target: dst.id, placement: 'replace', fit: 'derive' } });
    assert.equal(paste.type, 'ack', JSON.stringify(paste));
    const t6 = await tree();
    keptAlone(t5, t6, below(t5, dst.id), 'paste');
    assert.equal(t6.nodes[dst.id].kind, 'dead');
    const pasted = t6.nodes.filter((n) => n.id >= t5.nodes.length && n.visible);
    assert.ok(pasted.some((n) => sameBox(n.box, dst.box) && n.label === src.label), JSON.stringify(pasted));
    const undo = await timed(A, { type: 'op', base: paste.version, cid: 'undo-paste', op: { kind: 'undo' } });
    assert.equal(undo.type, 'ack', JSON.stringify(undo));
    assert.equal(nodesText(await tree()), nodesText(t5), 'undo of the paste does not give the tree before it back');
  });

  it('over REST: a window split, then resized by its old id; a join keeps the node nearest the root', async () => {
    const post = (op, version) => http(d, 'POST', `/api/v1/models/${model.id}/ops`, {
      body: { op }, headers: { 'If-Match': `"${version}"`, 'X-Archgram-User': 'cy' }, timeout: 60000,
    });
    const t0 = await tree();
    const w = windowsOf(t0)[7];
    const at = w.box[0] + 0.5 * size(w.box, 0);
    let r = await post({ kind: 'split', node: w.id, axis: 'x', at }, t0.version);
    assert.equal(r.status, 200, r.text);
    const t1 = await tree();
    keptAlone(t0, t1, below(t0, w.id), 'REST split');
    assert.ok(near(t1.nodes[w.id].box[3], at), JSON.stringify(t1.nodes[w.id]));
    const b = [...t1.nodes[w.id].box];
    b[5] += 0.3;
    r = await post({ kind: 'resize', node: w.id, box: b, mode: 'local' }, t1.version);
    assert.equal(r.status, 200, r.text);
    const t2 = await tree();
    assert.ok(near(t2.nodes[w.id].box[5], b[5]), JSON.stringify(t2.nodes[w.id]));
    assert.equal(t2.nodes[w.id].label, w.label);
    // join two other windows: one keeps its id with the union box, the other is dead
    const [j1, j2] = [windowsOf(t2)[10], windowsOf(t2)[11]];
    r = await post({ kind: 'join', nodes: [j1.id, j2.id] }, t2.version);
    assert.equal(r.status, 200, r.text);
    const t3 = await tree();
    keptAlone(t2, t3, new Set([j1.id, j2.id]), 'REST join');
    const [kept, gone] = t3.nodes[j1.id].kind === 'dead' ? [j2, j1] : [j1, j2];
    assert.equal(t3.nodes[gone.id].kind, 'dead');
    const u = [0, 1, 2].map((a) => Math.min(j1.box[a], j2.box[a])).concat([0, 1, 2].map((a) => Math.max(j1.box[a + 3], j2.box[a + 3])));
    assert.ok(sameBox(t3.nodes[kept.id].box, u), JSON.stringify([t3.nodes[kept.id].box, u]));
  });
});
