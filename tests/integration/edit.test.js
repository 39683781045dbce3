// Structure-preserving editing as a service: resize ops over REST and websockets, concurrent
// clients, per-person undo/redo (restore ops), undo conflicts, restoring a version, live drag
// previews that store nothing, and edits refused on models that are not proceduralized.
import assert from 'node:assert/strict';
import { after, before, describe, it } from 'node:test';
import {
  assertProblem, http, importModel, PROBLEM, removeDir, startDaemon, waitJob, WsClient,
  facadeObj as sharedFacadeObj,
} from './harness.js';

const facadeObj = (cols, rows) => Buffer.from(sharedFacadeObj(cols, rows));

const near = (a, b, eps = 1e-6) => Math.abs(a - b) <= eps;

describe('structural edits as ops', () => {
  let d;
  let model; // the proceduralized facade
  let plain; // never proceduralized
  const clients = [];

  const open = async () => { const c = await WsClient.open(d.wsUrl); clients.push(c); return c; };
  const getModel = async (id = model.id) => {
    const r = await http(d, 'GET', `/api/v1/models/${id}`);
    assert.equal(r.status, 200, r.text);
    return r.json;
  };
  const tree = async (id = model.id) => {
    const r = await http(d, 'GET', `/api/v1/models/${id}/tree`);
    assert.equal(r.status, 200, r.text);
    return r;
  };
  const grammar = async () => (await http(d, 'GET', `/api/v1/models/${model.id}/grammar`)).text;
  // the tree without the model version it is served for, as text (exact comparisons)
  const treeText = async () => {
    const t = (await tree()).json;
    delete t.version;
    return JSON.stringify(t);
  };
  const same = (a, b, what) => assert.ok(a === b, `${what} differs`);
  const differ = (a, b, what) => assert.ok(a !== b, `${what} did not change`);
  const restOp = (op, version, { user = 'api', cid } = {}) => http(d, 'POST', `/api/v1/models/${model.id}/ops`, {
    body: cid ? { cid, op } : { op }, headers: { 'If-Match': `"${version}"`, 'X-Archgram-User': user }, timeout: 60000,
  });
  const reply = (cid) => (m) => (m.type === 'ack' || m.type === 'nack') && m.cid === cid;
  // the wall: the visible node with the largest box
  const wallNode = (t) => t.nodes.filter((n) => n.visible)
    .sort((a, b) => (b.box[3] - b.box[0]) * (b.box[5] - b.box[2]) - (a.box[3] - a.box[0]) * (a.box[5] - a.box[2]))[0];
  const windows = (t) => t.nodes.filter((n) => n.visible && n.id !== wallNode(t).id).length;

  before(async () => {
    d = await startDaemon({ args: ['--workers', '1', '--no-web'] });
    model = await importModel(d, facadeObj(), { name: 'facade' });
    plain = await importModel(d, facadeObj(2, 1), { name: 'plain' });
    const r = await http(d, 'POST', `/api/v1/models/${model.id}/proceduralize`, {});
    assert.equal(r.status, 202, r.text);
    const job = await waitJob(d, r.json.id, { timeout: 60000 });
    assert.equal(job.status, 'succeeded', JSON.stringify(job));
    model = await getModel();
    assert.equal(model.proceduralized, true);
  });
  after(async () => {
    for (const c of clients) await c.close().catch(() => {});
    if (d) { try { await d.stop(); } finally { await d.kill(); removeDir(d.dir); } }
  });

  it('an op on a model that is not proceduralized is a not-proceduralized problem', async () => {
    const r = await http(d, 'POST', `/api/v1/models/${plain.id}/ops`, {
      body: { op: { kind: 'resize', node: 'root', scale: [2, 1, 1] } }, headers: { 'If-Match': `"${plain.version}"` },
    });
    assertProblem(r, 409, 'not-proceduralized', 'resize on a plain mesh');
    assert.match(r.json.detail, /not proceduralized/);
    const W = await open();
    await W.request({ type: 'hello', model: plain.id, user: 'ana' }, 'welcome');
    const n = await W.request({ type: 'op', base: plain.version, cid: 'np', op: { kind: 'resize', node: 'root', scale: [2, 1, 1] } }, reply('np'));
    assert.equal(n.type, 'nack');
    assert.equal(n.problem.type, `${PROBLEM}not-proceduralized`);
    assert.match(n.problem.detail, /not proceduralized/);
    assert.equal((await getModel(plain.id)).version, plain.version);
    // an invalid op is refused before anything is computed
    const bad = await http(d, 'POST', `/api/v1/models/${model.id}/ops`, {
      body: { op: { kind: 'resize', node: 'root', box: [0, 0, 0, 1, 1] } }, headers: { 'If-Match': `"${model.version}"` },
    });
    assertProblem(bad, 400, 'invalid', 'short box');
    assert.match(bad.json.detail, /box/);
    const missing = await restOp({ kind: 'resize', node: 9999, scale: [2, 1, 1] }, model.version);
    assert.ok(missing.status === 404 || missing.status === 400, missing.text);
    assert.match(missing.json.detail, /9999/);
  });

  it('a resize over REST stretches the wall: the tree, grammar and mesh change, version + 1, the room sees it', async () => {
    const W = await open();
    await W.request({ type: 'hello', model: model.id, user: 'watcher' }, 'welcome');
    const t0 = (await tree()).json;
    const wall = wallNode(t0);
    const before = windows(t0);
    const g0 = await grammar();
    const box = [...t0.nodes[0].box];
    const width = box[3] - box[0];
    box[3] = box[0] + 2 * width; // the whole facade twice as wide
    const r = await restOp({ kind: 'resize', node: 'root', box, mode: 'global' }, model.version, { user: 'ana', cid: 'wide' });
    assert.equal(r.status, 200, r.text);
    assert.equal(r.json.version, model.version + 1);
    const seen = await W.next((m) => m.type === 'op' && m.cid === 'wide', 10000, 'resize op');
    assert.equal(seen.author, 'ana');
    assert.equal(seen.op.kind, 'resize');
    assert.ok(seen.op.report && seen.op.report.unknowns >= 0, JSON.stringify(seen.op));
    const m = await getModel();
    assert.equal(m.version, model.version + 1);
    assert.equal(m.proceduralized, true);
    assert.ok(near(m.stats.bounds.max[0] - m.stats.bounds.min[0], 2 * (model.stats.bounds.max[0] - model.stats.bounds.min[0]), 1e-3),
      `${JSON.stringify(model.stats.bounds)} → ${JSON.stringify(m.stats.bounds)}`);
    const t1 = await tree();
    assert.equal(t1.headers.get('etag'), `"${m.version}"`);
    const root1 = t1.json.nodes[0].box;
    assert.ok(near(root1[3] - root1[0], 2 * width, 1e-3), JSON.stringify([t0.nodes[0].box, root1]));
    // stretched past 1.8×, the pattern grows: more windows of the original width
    const win = (t) => t.nodes.filter((n) => n.visible && (n.box[3] - n.box[0]) < 2);
    const w0 = win(t0)[0].box;
    const after = win(t1.json);
    assert.ok(after.length > before, `more windows, not stretched ones: ${before} → ${after.length}`);
    assert.ok(after.every((n) => near(n.box[3] - n.box[0], w0[3] - w0[0], 0.1 * (w0[3] - w0[0]))), JSON.stringify(after.map((n) => n.box)));
    console.log(`# 2× wider facade: ${before} → ${after.length} windows; wall ${JSON.stringify(wall.box)}`);
    assert.notEqual(await grammar(), g0);
    const log = (await http(d, 'GET', `/api/v1/models/${model.id}/ops`)).json.items;
    assert.equal(log.at(-1).op.kind, 'resize');
    assert.equal(log.at(-1).author, 'ana');
    assert.equal(typeof log.at(-1).at, 'string');
    model = m;
  });

  it('a resize over the websocket reaches the other client (latency printed) and matches the database', async () => {
    const A = await open();
    const B = await open();
    await A.request({ type: 'hello', model: model.id, user: 'ana' }, 'welcome');
    await B.request({ type: 'hello', model: model.id, user: 'bo' }, 'welcome');
    const t0 = (await tree()).json;
    // one window, 0.4 m taller, in global mode: every window of its rule follows
    const win = t0.nodes.find((n) => n.visible && (n.box[3] - n.box[0]) < 2);
    const box = [...win.box];
    box[5] += 0.4;
    const h0 = win.box[5] - win.box[2];
    const sent = performance.now();
    const seenP = B.next((m) => m.type === 'op' && m.cid === 'tall', 60000, 'tall op');
    const ack = await A.request({ type: 'op', base: model.version, cid: 'tall', op: { kind: 'resize', node: win.id, box, mode: 'global' } }, reply('tall'), 60000);
    const seen = await seenP;
    const latency = performance.now() - sent;
    assert.equal(ack.type, 'ack', JSON.stringify(ack));
    assert.equal(seen.version, ack.version);
    const rep = seen.op.report;
    console.log(`# resize op (one window, global) → other client: ${latency.toFixed(1)} ms; ${rep.equations} equations, ` +
      `${rep.unknowns} unknowns, solve ${rep.solve_ms.toFixed(2)} ms, edit ${rep.edit_ms.toFixed(1)} ms, max residual ${rep.max_residual}`);
    assert.ok(rep.equations > 0, JSON.stringify(rep));
    const m = await getModel();
    assert.equal(m.version, ack.version);
    const t1 = (await tree()).json;
    const wins = t1.nodes.filter((n) => n.visible && (n.box[3] - n.box[0]) < 2);
    assert.ok(wins.length > 0);
    assert.ok(wins.every((n) => near(n.box[5] - n.box[2], h0 + 0.4, 1e-3)), JSON.stringify(wins.map((n) => n.box)));
    model = m;
  });

  it('two clients send ops on the same version at once: one applies, the stale one is nacked, both agree with the database', async () => {
    const A = await open();
    const B = await open();
    await A.request({ type: 'hello', model: model.id, user: 'ana' }, 'welcome');
    await B.request({ type: 'hello', model: model.id, user: 'bo' }, 'welcome');
    const t0 = (await tree()).json;
    const a = [...t0.nodes[0].box];
    a[3] = a[0] + 0.8 * (a[3] - a[0]);
    const b = [...t0.nodes[0].box];
    b[5] = b[2] + 0.9 * (b[5] - b[2]);
    const ra = A.next(reply('race-a'), 60000);
    const rb = B.next(reply('race-b'), 60000);
    A.send({ type: 'op', base: model.version, cid: 'race-a', op: { kind: 'resize', node: 'root', box: a } });
    B.send({ type: 'op', base: model.version, cid: 'race-b', op: { kind: 'resize', node: 'root', box: b } });
    const [xa, xb] = await Promise.all([ra, rb]);
    assert.deepEqual([xa.type, xb.type].sort(), ['ack', 'nack'], JSON.stringify([xa, xb]));
    const [won, lost, loser, winner] = xa.type === 'ack' ? [xa, xb, B, A] : [xb, xa, A, B];
    assert.equal(lost.problem.type, `${PROBLEM}stale`);
    assert.equal(lost.version, won.version, 'the nack carries the current version');
    const seen = await loser.next((m) => m.type === 'op' && m.version === won.version, 10000, 'the winning op');
    await winner.none((m) => m.type === 'op' && m.version === won.version, 200, 'own op echoed');
    // the stale one, rebased by its client on the new tree and sent again, is applied too
    const fresh = [...(await tree()).json.nodes[0].box];
    if (lost.cid === 'race-a') fresh[3] = fresh[0] + (a[3] - a[0]);
    else fresh[5] = fresh[2] + (b[5] - b[2]);
    const retry = await loser.request({ type: 'op', base: won.version, cid: `${lost.cid}-retry`, op: { kind: 'resize', node: 'root', box: fresh } }, reply(`${lost.cid}-retry`), 60000);
    assert.equal(retry.type, 'ack', JSON.stringify(retry));
    await winner.next((m) => m.type === 'op' && m.version === retry.version, 10000, 'the retried op');
    const m = await getModel();
    assert.equal(m.version, retry.version);
    assert.equal(seen.version, won.version);
    const t1 = (await tree()).json;
    assert.ok(near(t1.nodes[0].box[3] - t1.nodes[0].box[0], a[3] - a[0], 1e-3), JSON.stringify(t1.nodes[0].box));
    assert.ok(near(t1.nodes[0].box[5] - t1.nodes[0].box[2], b[5] - b[2], 1e-3), JSON.stringify(t1.nodes[0].box));
    model = m;
  });

  it('undo then redo return exactly the previous tree and grammar', async () => {
    const A = await open();
    await A.request({ type: 'hello', model: model.id, user: 'cy' }, 'welcome');
    const tBefore = await treeText();
    const gBefore = await grammar();
    const t0 = JSON.parse(tBefore);
    const box = [...t0.nodes[0].box];
    box[3] = box[0] + 1.3 * (box[3] - box[0]);
    const e = await A.request({ type: 'op', base: model.version, cid: 'cy-1', op: { kind: 'resize', node: 'root', box } }, reply('cy-1'), 60000);
    assert.equal(e.type, 'ack', JSON.stringify(e));
    const tEdited = await treeText();
    const gEdited = await grammar();
    differ(tEdited, tBefore, 'the edited tree');
    const u = await A.request({ type: 'op', base: e.version, cid: 'cy-undo', op: { kind: 'undo' } }, reply('cy-undo'), 60000);
    assert.equal(u.type, 'ack', JSON.stringify(u));
    assert.equal(u.version, e.version + 1);
    same(await treeText(), tBefore, 'the tree after undo');
    same(await grammar(), gBefore, 'the grammar after undo');
    const log = (await http(d, 'GET', `/api/v1/models/${model.id}/ops`)).json.items;
    assert.deepEqual(log.at(-1).op, { kind: 'restore', version: e.version - 1, undoes: e.version });
    assert.equal(log.at(-1).author, 'cy');
    const r = await A.request({ type: 'op', base: u.version, cid: 'cy-redo', op: { kind: 'redo' } }, reply('cy-redo'), 60000);
    assert.equal(r.type, 'ack', JSON.stringify(r));
    same(await treeText(), tEdited, 'the tree after redo');
    same(await grammar(), gEdited, 'the grammar after redo');
    // nothing left to redo
    const again = await A.request({ type: 'op', base: r.version, cid: 'cy-redo-2', op: { kind: 'redo' } }, reply('cy-redo-2'));
    assert.equal(again.type, 'nack');
    assert.equal(again.problem.type, `${PROBLEM}undo-conflict`);
    model = await getModel();
    // an edit after the redo still applies on the redone model
    const t2 = JSON.parse(tEdited);
    const b2 = [...t2.nodes[0].box];
    b2[5] = b2[2] + 1.1 * (b2[5] - b2[2]);
    const e2 = await A.request({ type: 'op', base: model.version, cid: 'cy-2', op: { kind: 'resize', node: 'root', box: b2 } }, reply('cy-2'), 60000);
    assert.equal(e2.type, 'ack', JSON.stringify(e2));
    model = await getModel();
  });

  it("undo is refused when another person's op came after the edit, naming that op", async () => {
    const t0 = (await tree()).json;
    const box = [...t0.nodes[0].box];
    box[3] = box[0] + 0.9 * (box[3] - box[0]);
    const e = await restOp({ kind: 'resize', node: 'root', box }, model.version, { user: 'dee', cid: 'dee-1' });
    assert.equal(e.status, 200, e.text);
    const b2 = [...box];
    b2[5] = b2[2] + 0.95 * (b2[5] - b2[2]);
    const o = await restOp({ kind: 'resize', node: 'root', box: b2 }, e.json.version, { user: 'eve', cid: 'eve-1' });
    assert.equal(o.status, 200, o.text);
    const u = await restOp({ kind: 'undo' }, o.json.version, { user: 'dee', cid: 'dee-undo' });
    assertProblem(u, 409, 'undo-conflict', 'undo after another person');
        assert.match(u.json.detail, new RegExp(`version ${o.json.version} by eve`));
    assert.equal((await getModel()).version, o.json.version);
    // eve may undo hers; restoring a version is open to anyone
    const ue = await restOp({ kind: 'undo' }, o.json.version, { user: 'eve', cid: 'eve-undo' });
    assert.equal(ue.status, 200, ue.text);
    const treeAtE = await treeText();
    const rs = await restOp({ kind: 'restore', version: model.version }, ue.json.version, { user: 'fay', cid: 'fay-1' });
    assert.equal(rs.status, 200, rs.text);
    differ(await treeText(), treeAtE, 'the restored tree');
    const back = await restOp({ kind: 'restore', version: e.json.version }, rs.json.version, { user: 'fay', cid: 'fay-2' });
    assert.equal(back.status, 200, back.text);
    same(await treeText(), treeAtE, 'the tree restored to the undone state');
    const future = await restOp({ kind: 'restore', version: 99999 }, back.json.version, { user: 'fay' });
    assertProblem(future, 404, 'not-found');
    model = await getModel();
  });

  it('previews reach the other client, store nothing, and preview.end clears them', async () => {
    const A = await open();
    const B = await open();
    const wa = await A.request({ type: 'hello', model: model.id, user: 'ana' }, 'welcome');
    await B.request({ type: 'hello', model: model.id, user: 'bo' }, 'welcome');
    const t0 = (await tree()).json;
    const box = [...t0.nodes[0].box];
    const sends = 12;
    for (let i = 1; i <= sends; i++) {
      const b = [...box];
      b[3] = box[0] + (1 + 0.05 * i) * (box[3] - box[0]);
      A.send({ type: 'preview', model: model.id, base: model.version, op: { kind: 'resize', node: 'root', box: b } });
    }
    const last = box[0] + (1 + 0.05 * sends) * (box[3] - box[0]);
    const got = await B.next((m) => m.type === 'preview' && m.boxes.some((x) => x.node === 0 && near(x.box[3], last, 1e-6)), 10000, 'the newest preview');
    assert.equal(got.author, 'ana');
    assert.equal(got.peer, wa.you);
    assert.equal(got.base, model.version);
    assert.equal(typeof got.solve_ms, 'number');
    assert.ok(got.boxes.length >= 1);
    await sleep(100);
    const previews = B.all.filter((m) => m.type === 'preview');
    assert.ok(previews.length < sends, `previews are rate limited: ${previews.length} of ${sends} solved`);
    console.log(`# previews: ${sends} sent at once, ${previews.length} solved and shown; drag re-solve ${got.solve_ms.toFixed(3)} ms`);
    A.send({ type: 'preview.end' });
    const end = await B.next('preview.end', 5000);
    assert.equal(end.peer, wa.you);
    const m = await getModel();
    assert.equal(m.version, model.version, 'previews store nothing');
    const stale = await A.request({ type: 'preview', model: model.id, base: model.version - 1, op: { kind: 'resize', node: 'root', box } }, 'preview.error');
    assert.equal(stale.problem.type, `${PROBLEM}stale`);
    assert.equal(stale.version, model.version);
  });
});

function sleep(ms) { return new Promise((r) => setTimeout(r, ms)); }
