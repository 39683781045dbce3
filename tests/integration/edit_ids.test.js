// Node ids survive edits: a window selected before a resize of its facade is the same window
// after it (in the served tree, in another client's presence, in ops that name it), through
// a restart of the service (the store reloads the edited model node for node) and through
// undo and redo.
import assert from 'node:assert/strict';
import { after, before, describe, it } from 'node:test';
import {
  http, importModel, removeDir, startDaemon, tempDir, waitJob, WsClient,
  facadeObj as sharedFacadeObj,
} from './harness.js';

const near = (a, b, eps = 1e-6) => Math.abs(a - b) <= eps;
const size = (b, a) => b[3 + a] - b[a];

describe('node ids survive edits', () => {
  const dir = tempDir();
  let d;
  let model;
  const clients = [];

  const open = async () => { const c = await WsClient.open(d.wsUrl); clients.push(c); return c; };
  const tree = async () => {
    const r = await http(d, 'GET', `/api/v1/models/${model.id}/tree`);
    assert.equal(r.status, 200, r.text);
    return r.json;
  };
  const nodesText = (t) => JSON.stringify({ nodes: t.nodes, labels: t.labels, rules: t.rules });
  const reply = (cid) => (m) => (m.type === 'ack' || m.type === 'nack') && m.cid === cid;
  // the wall: the visible node with the largest front area; windows: the other visible nodes
  const wallOf = (t) => t.nodes.filter((n) => n.visible)
    .sort((a, b) => size(b.box, 0) * size(b.box, 2) - size(a.box, 0) * size(a.box, 2))[0];
  const windowsOf = (t) => { const w = wallOf(t); return t.nodes.filter((n) => n.visible && n.label !== w.label); };

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

  it('a selected window keeps its id through a facade resize, a restart, undo and redo', async () => {
    const t0 = await tree();
    const wall = wallOf(t0);
    const wins0 = windowsOf(t0);
    assert.equal(wins0.length, 24);
    // the first window of the bottom row and the last of the top row (z is up)
    const byPlace = [...wins0].sort((a, b) => a.box[2] - b.box[2] || a.box[0] - b.box[0]);
    const first = byPlace[0];
    const last = byPlace.at(-1);
    const label = first.label;

    // another person selects both windows
    const B = await open();
    await B.request({ type: 'hello', model: model.id, user: 'bo' }, 'welcome');
    B.send({ type: 'presence', state: { selection: [first.id, last.id] } });
    const A = await open();
    const wa = await A.request({ type: 'hello', model: model.id, user: 'ana' }, 'welcome');
    assert.ok(wa.peers.some((p) => p.user === 'bo'), JSON.stringify(wa.peers));

    // the wall twice as wide, from the websocket
    const box = [...wall.box];
    box[3] = box[0] + 2 * size(wall.box, 0);
    const sent = performance.now();
    const seenB = B.next((m) => m.type === 'op' && m.cid === 'wide', 60000, 'wide op');
    const ack = await A.request({ type: 'op', base: model.version, cid: 'wide', op: { kind: 'resize', node: wall.id, box, mode: 'global' } }, reply('wide'), 60000);
    assert.equal(ack.type, 'ack', JSON.stringify(ack));
    await seenB;
    console.log(`# facade resize (24 windows) → other client: ${(performance.now() - sent).toFixed(1)} ms`);
    const t1 = await tree();

    // every node the edit kept has its id, kind and label; new ones come after the old ones
    let kept = 0;
    for (const n of t0.nodes) {
      const m = t1.nodes[n.id];
      assert.ok(m, `node ${n.id} is gone from the numbering`);
      assert.equal(m.id, n.id);
      if (m.kind === 'dead') continue;
      kept++;
      assert.equal(m.kind, n.kind, `node ${n.id} changed kind`);
      assert.equal(m.label, n.label, `node ${n.id} changed label`);
    }
    assert.ok(kept >= t0.nodes.filter((n) => n.kind !== 'dead').length - 2, `only ${kept} nodes kept`);
    const wins1 = windowsOf(t1);
    assert.ok(wins1.length >= 44, `more windows of the original size: ${wins1.length}`);
    assert.ok(t1.nodes.filter((n) => n.visible).every((n) => t0.nodes[n.id] === undefined ||
      t0.nodes[n.id].visible), 'an old invisible id names a visible node');
    // the wall's id still names the wall (a leaf stretched past 1.8x is two copies of it: the
    // pieces with its label span twice its width); the selected ids still name windows of
    // their size
    assert.equal(t1.nodes[wall.id].label, wall.label);
    const pieces = t1.nodes.filter((n) => n.visible && n.label === wall.label);
    const span = Math.max(...pieces.map((n) => n.box[3])) - Math.min(...pieces.map((n) => n.box[0]));
    assert.ok(near(span, 2 * size(wall.box, 0), 1e-6), JSON.stringify(pieces.map((n) => n.box)));
    for (const w of [first, last]) {
      const m = t1.nodes[w.id];
      assert.ok(m.visible && m.label === label, JSON.stringify(m));
      for (const a of [0, 1, 2]) assert.ok(near(size(m.box, a), size(w.box, a), 1e-6), JSON.stringify([w.box, m.box]));
    }
    // in their places: the first window is still the first of the bottom row, the last one
    // still in the top row
    const byPlace1 = [...wins1].sort((a, b) => a.box[2] - b.box[2] || a.box[0] - b.box[0]);
    assert.equal(byPlace1[0].id, first.id);
    assert.ok(near(t1.nodes[last.id].box[2], last.box[2], 1e-6), JSON.stringify(t1.nodes[last.id]));
    assert.ok(near(t1.nodes[first.id].box[2], first.box[2], 1e-6), JSON.stringify(t1.nodes[first.id]));

    // someone joining now sees bo's selection, and those ids are still the windows
    const C = await open();
    const wc = await C.request({ type: 'hello', model: model.id, user: 'cy' }, 'welcome');
    const bo = wc.peers.find((p) => p.user === 'bo');
    assert.deepEqual(bo.state.selection, [first.id, last.id]);

    // an op naming the window by the id it had before the edit applies to it
    const tb = [...t1.nodes[first.id].box];
    tb[5] += 0.4;
    const tall = await A.request({ type: 'op', base: ack.version, cid: 'tall', op: { kind: 'resize', node: first.id, box: tb, mode: 'global' } }, reply('tall'), 60000);
    assert.equal(tall.type, 'ack', JSON.stringify(tall));
    const t2 = await tree();
    assert.ok(near(size(t2.nodes[first.id].box, 2), size(first.box, 2) + 0.4, 1e-6), JSON.stringify(t2.nodes[first.id]));
    assert.ok(windowsOf(t2).every((n) => near(size(n.box, 2), size(first.box, 2) + 0.4, 1e-6)), 'every window of the rule is taller');
    assert.equal(t2.nodes[wall.id].id, wall.id);

    // a restart reloads the edited model from the store: the same tree, node for node
    for (const c of clients.splice(0)) await c.close().catch(() => {});
    await d.stop();
    d = await startDaemon({ dir, db: d.db, args: ['--workers', '1', '--no-web'] });
    const t2r = await tree();
    assert.equal(nodesText(t2r), nodesText(t2), 'the tree after a restart differs');
    // and an op naming the old id still applies after the restart
    const R = await open();
    await R.request({ type: 'hello', model: model.id, user: 'ana' }, 'welcome');
    const undo = await R.request({ type: 'op', base: tall.version, cid: 'undo-tall', op: { kind: 'undo' } }, reply('undo-tall'), 60000);
    assert.equal(undo.type, 'ack', JSON.stringify(undo));
    assert.equal(nodesText(await tree()), nodesText(t1), 'undo does not give the tree before the op back');
    const redo = await R.request({ type: 'op', base: undo.version, cid: 'redo-tall', op: { kind: 'redo' } }, reply('redo-tall'), 60000);
    assert.equal(redo.type, 'ack', JSON.stringify(redo));
    assert.equal(nodesText(await tree()), nodesText(t2), 'redo does not give the edited tree back');
    const again = [...t2.nodes[last.id].box];
    again[5] += 0.2;
    const op = await R.request({ type: 'op', base: redo.version, cid: 'last', op: { kind: 'resize', node: last.id, box: again, mode: 'local' } }, reply('last'), 60000);
    assert.equal(op.type, 'ack', JSON.stringify(op));
    const t3 = await tree();
    assert.ok(near(size(t3.nodes[last.id].box, 2), size(first.box, 2) + 0.6, 1e-6), JSON.stringify(t3.nodes[last.id]));
  });
});
