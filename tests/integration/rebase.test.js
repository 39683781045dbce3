// Live ops made on an older version: rebased onto the current one when nothing since
// conflicts (a resize over notes and renames; a resize of a window over another window's
// resize, its node id rewritten), nacked naming the op that conflicts otherwise; and a bounded
// 50-client soak of mixed ops in which nearly every structural op is acked on its first send
// and every client ends with the database's op log.
import assert from 'node:assert/strict';
import { after, before, describe, it } from 'node:test';
import { http, removeDir, startDaemon, WsClient } from './harness.js';
import { runSoak, soakModel } from './soak.js';

const near = (a, b, eps = 1e-6) => a.every((v, i) => Math.abs(v - b[i]) <= eps);

describe('rebasing live ops', () => {
  let d;
  let model;
  const clients = [];
  const open = async (user) => {
    const c = await WsClient.open(d.wsUrl);
    clients.push(c);
    const w = await c.request({ type: 'hello', model: model.id, user }, 'welcome');
    c.version = w.version;
    return c;
  };
  const tree = async () => (await http(d, 'GET', `/api/v1/models/${model.id}/tree`)).json;
  const reply = (cid) => (m) => (m.type === 'ack' || m.type === 'nack') && m.cid === cid;
  const windowsOf = (t) => t.nodes.filter((n) => n.visible && n.box[3] - n.box[0] < 2);
  const grow = (w, by = 0.05) => {
    const box = [...w.box];
    box[3] += by;
    box[5] += by;
    const region = [w.box[0] - 0.02, w.box[1] - 0.02, w.box[2] - 0.02, box[3] + 0.02, w.box[4] + 0.02, box[5] + 0.02];
    return { kind: 'resize', node: w.id, box, mode: 'local', region };
  };

  before(async () => {
    d = await startDaemon({ args: ['--no-web', '--rate-ws', '0', '--rate-rest', '0', '--max-connections-per-address', '1024'] });
    model = await soakModel(d, 8);
  });
  after(async () => {
    for (const c of clients) await c.close();
    if (d) { try { await d.stop(); } finally { await d.kill(); removeDir(d.dir); } }
  });

  it('a resize made before notes and a rename is applied on the current version', async () => {
    const A = await open('ana');
    const B = await open('bo');
    const t = await tree();
    const base = t.version;
    for (const [i, op] of [{ kind: 'note', text: 'one' }, { kind: 'rename', name: 'renamed' }, { kind: 'note', text: 'two' }].entries()) {
      const r = await B.request({ type: 'op', cid: `b${i}`, base: base + i, op }, reply(`b${i}`));
      assert.equal(r.type, 'ack', JSON.stringify(r));
    }
    const w = windowsOf(t)[0];
    const op = grow(w);
    const r = await A.request({ type: 'op', cid: 'a-resize', base, op }, reply('a-resize'), 60000);
    assert.equal(r.type, 'ack', JSON.stringify(r));
    assert.equal(r.version, base + 4);
    const seen = await B.next((m) => m.type === 'op' && m.cid === 'a-resize');
    assert.equal(seen.op.node, w.id, 'nothing geometric came between: the same node');
    const after = await tree();
    assert.ok(after.nodes.some((n) => n.kind === 'component' && near(n.box, op.box)), 'the window has its new box');
  });

  it('a window resized over another window\'s resize: rebased with the id the window has now', async () => {
    const A = await open('ana2');
    const B = await open('bo2');
    const t = await tree();
    const [wa, wb] = [windowsOf(t)[1], windowsOf(t)[2]];
    const rb = await B.request({ type: 'op', cid: 'b-first', base: t.version, op: grow(wb) }, reply('b-first'), 60000);
    assert.equal(rb.type, 'ack', JSON.stringify(rb));
    const mid = await tree();
    const moved = mid.nodes.find((n) => n.kind === 'component' && near(n.box, wa.box));
    assert.ok(moved, 'window a is unchanged');
    const op = grow(wa);
    const ra = await A.request({ type: 'op', cid: 'a-second', base: t.version, op }, reply('a-second'), 60000);
    assert.equal(ra.type, 'ack', JSON.stringify(ra));
    assert.equal(ra.version, rb.version + 1);
    const seen = await B.next((m) => m.type === 'op' && m.cid === 'a-second');
    assert.equal(seen.op.node, moved.id, `rewritten from ${wa.id} to the id at version ${rb.version}`);
    const after = await tree();
    assert.ok(after.nodes.some((n) => n.kind === 'component' && near(n.box, op.box)), 'a has its new box');
    assert.ok(after.nodes.some((n) => n.kind === 'component' && near(n.box, grow(wb).box)), 'b kept its own');
  });

  it('a resize made on a version no edit has kept a state of yet is rebased too', async () => {
    // a fresh model: its first structural edit keeps the state before it, which is the state
    // of every version since the proceduralization
    const fresh = await soakModel(d, 4);
    const A = await WsClient.open(d.wsUrl);
    const B = await WsClient.open(d.wsUrl);
    clients.push(A, B);
    const w = await A.request({ type: 'hello', model: fresh.id, user: 'ana5' }, 'welcome');
    await B.request({ type: 'hello', model: fresh.id, user: 'bo5' }, 'welcome');
    const t = (await http(d, 'GET', `/api/v1/models/${fresh.id}/tree`)).json;
    const [wa, wb] = windowsOf(t);
    assert.equal((await B.request({ type: 'op', cid: 'f-note', base: w.version, op: { kind: 'note', text: 'hi' } }, reply('f-note'))).type, 'ack');
    const rb = await B.request({ type: 'op', cid: 'f-b', base: w.version + 1, op: grow(wb) }, reply('f-b'), 60000);
    assert.equal(rb.type, 'ack', JSON.stringify(rb));
    const ra = await A.request({ type: 'op', cid: 'f-a', base: w.version, op: grow(wa) }, reply('f-a'), 60000);
    assert.equal(ra.type, 'ack', JSON.stringify(ra));
    assert.equal(ra.version, rb.version + 1);
  });

  it('two resizes of one window: the later is nacked naming the op that changed it', async () => {
    const A = await open('ana3');
    const B = await open('bo3');
    const t = await tree();
    const w = windowsOf(t)[3];
    const rb = await B.request({ type: 'op', cid: 'b-win', base: t.version, op: grow(w, 0.1) }, reply('b-win'), 60000);
    assert.equal(rb.type, 'ack');
    const ra = await A.request({ type: 'op', cid: 'a-win', base: t.version, op: grow(w, -0.1) }, reply('a-win'), 60000);
    assert.equal(ra.type, 'nack', JSON.stringify(ra));
    assert.equal(ra.problem.type, 'urn:archgram:problem:stale');
    assert.equal(ra.version, rb.version, 'the nack carries the current version');
    assert.match(ra.problem.detail, new RegExp(`the resize op of version ${rb.version} by bo3 changed node ${w.id}`));
  });

  it('a rename after a rename made on the same version is a conflict; an undo rebases', async () => {
    const A = await open('ana4');
    const B = await open('bo4');
    const t = await tree();
    assert.equal((await B.request({ type: 'op', cid: 'rn-b', base: t.version, op: { kind: 'rename', name: 'B' } }, reply('rn-b'))).type, 'ack');
    const ra = await A.request({ type: 'op', cid: 'rn-a', base: t.version, op: { kind: 'rename', name: 'A' } }, reply('rn-a'));
    assert.equal(ra.type, 'nack');
    assert.match(ra.problem.detail, /the rename op of version \d+ by bo4 came since/);
    // ana4 resizes, bo4 notes, ana4 undoes from her old base
    const w = windowsOf(await tree())[4];
    const cur = (await http(d, 'GET', `/api/v1/models/${model.id}`)).json.version;
    assert.equal((await A.request({ type: 'op', cid: 'a-edit', base: cur, op: grow(w) }, reply('a-edit'), 60000)).type, 'ack');
    assert.equal((await B.request({ type: 'op', cid: 'b-note', base: cur + 1, op: { kind: 'note', text: 'nice' } }, reply('b-note'))).type, 'ack');
    const undo = await A.request({ type: 'op', cid: 'a-undo', base: cur, op: { kind: 'undo' } }, reply('a-undo'), 60000);
    assert.equal(undo.type, 'ack', JSON.stringify(undo));
    const after = await tree();
    assert.ok(after.nodes.some((n) => n.kind === 'component' && near(n.box, w.box)), 'the window is back');
  });
});

describe('collaboration soak (bounded)', () => {
  let d;
  after(async () => { if (d) { try { await d.stop(); } finally { await d.kill(); removeDir(d.dir); } } });

  it('50 clients of mixed ops: ≥ 95 % of the structural ops acked on the first send, every client ends with the database', async () => {
    d = await startDaemon({ args: ['--no-web', '--rate-ws', '0', '--rate-rest', '0', '--max-connections-per-address', '1024'] });
    const model = await soakModel(d, 50);
    const r = await runSoak(d, model, { clients: 50, seconds: 35 });
    // of the structural ops that did not conflict (a nacked one whose window had not changed
    // counts against)
    const rate = r.firstAcked / (r.structural - r.conflicts);
    console.log(`# soak: ${r.clients} clients, ${r.seconds.toFixed(1)} s, ${r.ops} ops (${r.versions} versions), ` +
      `${r.structural} structural (${r.conflicts} true conflicts): ${r.firstAcked} acked on the first send ` +
      `(${(100 * rate).toFixed(1)} % of those that did not conflict); notes and renames nacked: ${r.fastNacked} of ${r.notes + r.renames}`);
    for (const detail of r.nackDetails.slice(0, 3)) console.log(`# nack: ${detail}`);
    assert.ok(r.structural >= 50, `only ${r.structural} structural ops`);
    assert.ok(rate >= 0.95, `first-send acks ${(100 * rate).toFixed(1)} %: ${r.nackDetails.slice(0, 5).join(' | ')}`);
  });
});
