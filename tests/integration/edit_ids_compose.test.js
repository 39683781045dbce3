// A selection another person holds names the same nodes after a resize, a paste, a
// composition the graft cannot pair and grammar text edits (the model is then its derivation
// proceduralized again, and the nodes it left alone get their ids back): bo selects windows
// and the wall, ana edits over REST and the websocket, and after each op bo's ids name nodes
// of the same label on the same boxes; an op bo made before the composition, naming a window
// by its id, is rebased onto it and resizes that window; the model reloads node for node
// after a restart.
import assert from 'node:assert/strict';
import { after, before, describe, it } from 'node:test';
import { http, importModel, proceduralizedWall, removeDir, startDaemon, tempDir, waitJob, windowWallObj, WsClient } from './harness.js';

const near = (a, b, eps = 1e-6) => Math.abs(a - b) <= eps;
const sameBox = (a, b, eps = 1e-6) => a.every((v, k) => near(v, b[k], eps));
const size = (b, a) => b[3 + a] - b[a];

describe('ids held by another client survive resize, paste, a proceduralized composition and grammar edits', () => {
  const dir = tempDir();
  let d;
  const clients = [];

  const proceduralized = (opt, name) => proceduralizedWall(d, opt, name);
  const tree = async (id) => {
    const r = await http(d, 'GET', `/api/v1/models/${id}/tree`);
    assert.equal(r.status, 200, r.text);
    return r.json;
  };
  const open = async (model, user) => {
    const c = await WsClient.open(d.wsUrl);
    clients.push(c);
    await c.request({ type: 'hello', model, user }, 'welcome');
    return c;
  };
  const reply = (cid) => (m) => (m.type === 'ack' || m.type === 'nack') && m.cid === cid;
  const below = (t, id) => {
    const out = new Set([id]);
    const walk = (n) => { for (const c of t.nodes[n].children ?? []) { out.add(c); walk(c); } };
    walk(id);
    return out;
  };
  // every visible node of a outside `touched` has its id, label and box in b
  const keptAlone = (a, b, touched, what) => {
    let n = 0;
    for (const x of a.nodes) {
      if (!x.visible || touched.has(x.id)) continue;
      const y = b.nodes[x.id];
      assert.ok(y && y.visible, `${what}: node ${x.id} lost its id`);
      assert.equal(y.label, x.label, `${what}: node ${x.id} changed label`);
      assert.ok(sameBox(y.box, x.box), `${what}: node ${x.id} moved ${JSON.stringify([x.box, y.box])}`);
      n++;
    }
    return n;
  };

  before(async () => {
    d = await startDaemon({ dir, args: ['--workers', '1', '--no-web'] });
  });
  after(async () => {
    for (const c of clients) await c.close().catch(() => {});
    if (d) { try { await d.stop(); } finally { await d.kill(); } }
    removeDir(dir);
  });

  it('bo\'s selection names the same nodes after each of ana\'s ops', async () => {
    // the part: a window of one building; the model: a wall with windows set into it
    const a = await proceduralized({ cols: 3, rows: 2, ww: 1.2, wh: 1.8, frame: 0.08, mullions: 1 }, 'a');
    const ta = await tree(a.id);
    const win = ta.nodes.find((n) => n.visible && sameBox(n.box, a.slots[1])).id;
    const saved = await http(d, 'POST', '/api/v1/parts', { body: { model: a.id, version: ta.version, node: win, name: 'window' } });
    assert.equal(saved.status, 201, saved.text);
    const part = saved.json.id;
    const b = await proceduralized({ cols: 4, rows: 2, ww: 1.6, wh: 2.0, frame: 0.12, mullions: 2 }, 'b');
    const t0 = await tree(b.id);
    const slotNode = (t, s) => t.nodes.find((n) => n.visible && sameBox(n.box, s));
    const wall = t0.nodes.filter((n) => n.visible).sort((p, q) => size(q.box, 0) * size(q.box, 2) - size(p.box, 0) * size(p.box, 2))[0];
    const [w0, w1, w5, w6, w7] = [0, 1, 5, 6, 7].map((i) => slotNode(t0, b.slots[i]));

    const A = await open(b.id, 'ana');
    const B = await open(b.id, 'bo');
    const held = [w0.id, w1.id, wall.id];
    const seenPresence = A.next((m) => m.type === 'presence' && m.user === 'bo', 10000, 'bo\'s presence');
    B.send({ type: 'presence', state: { selection: held } });
    assert.deepEqual((await seenPresence).state.selection, held);
    // bo's selection names what it named in ref: same labels, same boxes
    const stillHeld = (t, what, ref = t0) => {
      for (const id of held) {
        const x = ref.nodes[id], y = t.nodes[id];
        assert.ok(y && y.visible, `${what}: bo's node ${id} is gone`);
        assert.equal(y.label, x.label, `${what}: bo's node ${id} changed label`);
        assert.ok(sameBox(y.box, x.box), `${what}: bo's node ${id} moved`);
      }
    };

    // a resize over REST: one window taller, alone
    const tall = [...w7.box];
    tall[5] += 0.2;
    let r = await http(d, 'POST', `/api/v1/models/${b.id}/ops`, {
      body: { op: { kind: 'resize', node: w7.id, box: tall, mode: 'local' } },
      headers: { 'If-Match': `"${t0.version}"`, 'X-Archgram-User': 'ana' }, timeout: 60000,
    });
    assert.equal(r.status, 200, r.text);
    const t1 = await tree(b.id);
    assert.ok(near(size(t1.nodes[w7.id].box, 2), size(w7.box, 2) + 0.2), JSON.stringify(t1.nodes[w7.id]));
    stillHeld(t1, 'resize');

    // a paste over the websocket: one window onto another
    const paste = await A.request({ type: 'op', base: t1.version, cid: 'paste', op: { kind: 'paste', source: [w5.id], target: w6.id, placement: 'replace', fit: 'derive' } }, reply('paste'), 60000);
    assert.equal(paste.type, 'ack', JSON.stringify(paste));
    const t2 = await tree(b.id);
    // the replaced window keeps its id, served as the id alone; every id still indexes nodes
    assert.deepEqual(t2.nodes[w6.id], { id: w6.id, kind: 'dead' });
    t2.nodes.forEach((n, i) => assert.equal(n.id, i));
    keptAlone(t1, t2, below(t1, w6.id), 'paste');
    stillHeld(t2, 'paste');

    // a composition the graft cannot pair: the window inserted into the whole building puts
    // its casing on the wall's box, so the derivation is proceduralized again
    const seen = B.next((m) => m.type === 'op' && m.cid === 'compose', 60000, 'the compose op');
    const compose = await A.request({ type: 'op', base: t2.version, cid: 'compose', op: { kind: 'compose', part, target: 0, mode: 'insert' } }, reply('compose'), 60000);
    assert.equal(compose.type, 'ack', JSON.stringify(compose));
    const report = (await seen).op.report;
    assert.equal(report.state, 'proceduralized', JSON.stringify(report));
    assert.match(report.fallback, /node/);
    const t3 = await tree(b.id);
    t3.nodes.forEach((n, i) => assert.ok(n.id === i && (n.kind !== 'dead' || Object.keys(n).length === 2), JSON.stringify(n)));
    const kept = keptAlone(t2, t3, new Set(), 'compose (proceduralized)');
    assert.equal(kept, t2.nodes.filter((n) => n.visible).length);
    const added = t3.nodes.filter((n) => n.visible && !(t2.nodes[n.id]?.visible));
    assert.ok(added.length > 0, 'the part brought nothing');
    for (const n of added) assert.ok(n.id >= t2.nodes.length, `new node ${n.id} takes an old id`);
    stillHeld(t3, 'compose');

    // bo's op made before the composition, naming a window he holds: rebased, that window
    const grown = [...w1.box];
    grown[5] += 0.1;
    const late = await B.request({ type: 'op', base: t2.version, cid: 'bo-late', op: { kind: 'resize', node: w1.id, box: grown, mode: 'local' } }, reply('bo-late'), 60000);
    assert.equal(late.type, 'ack', JSON.stringify(late));
    const t4 = await tree(b.id);
    assert.ok(near(t4.nodes[w1.id].box[5], w1.box[5] + 0.1), JSON.stringify(t4.nodes[w1.id]));
    assert.equal(t4.nodes[w1.id].label, w1.label);

    // grammar text edits re-derive and proceduralize the model: the text as it is keeps every
    // id; one more terminal placed in a corner of the axiom keeps them too and adds one node
    const put = (text, version) => http(d, 'PUT', `/api/v1/models/${b.id}/grammar`, {
      body: text, headers: { 'If-Match': `"${version}"`, 'Content-Type': 'text/plain', 'X-Archgram-User': 'ana' }, timeout: 60000,
    });
    const text = (await http(d, 'GET', `/api/v1/models/${b.id}/grammar`)).text;
    r = await put(text, t4.version);
    assert.equal(r.status, 200, r.text);
    const t5 = await tree(b.id);
    assert.equal(keptAlone(t4, t5, new Set(), 'grammar text as it is'), t4.nodes.filter((n) => n.visible).length);
    assert.equal(t5.nodes.filter((n) => n.visible).length, t4.nodes.filter((n) => n.visible).length);
    stillHeld(t5, 'grammar text as it is', t4);
    const terminal = text.match(/^terminal (\S+) /m)[1];
    const axiomEnd = text.lastIndexOf('}');
    const more = `${text.slice(0, axiomEnd)}  added_corner = split(p, 0.05, 0.05, 0.05, 1)\n  ${terminal}(added_corner)\n${text.slice(axiomEnd)}`;
    r = await put(more, t5.version);
    assert.equal(r.status, 200, r.text);
    const t6 = await tree(b.id);
    keptAlone(t5, t6, new Set(), 'grammar text with one more terminal');
    const grown6 = t6.nodes.filter((n) => n.visible && !(t5.nodes[n.id]?.visible));
    assert.equal(grown6.length, 1, JSON.stringify(grown6));
    assert.ok(grown6[0].id >= t5.nodes.length);
    stillHeld(t6, 'grammar text with one more terminal', t4);

    // the composed version reloads node for node after a restart
    const before = JSON.stringify((await tree(b.id)).nodes);
    await d.stop();
    d = await startDaemon({ dir, db: d.db, args: ['--workers', '1', '--no-web'] });
    assert.equal(JSON.stringify((await tree(b.id)).nodes), before);
  });
});
