// A point model's edits keep the ids of the nodes they leave alone (issue 14 §4), as mesh
// edits do: after a remove over REST and one over the websocket every other node of GET …/tree
// has its id, kind and box, the removed window is dead, an op naming a kept id edits that node,
// and a restart of the daemon serves the same tree and an op after it names the same nodes; a
// resize of one window, which resizes every window of its rule, keeps every node at its id
// (the windows with their new boxes), and undo and redo keep them too. The windows are found by
// their boxes in the test's own building (points_building.js), never by archgram's ids.
// A join keeps every node at its id too (a point model keeps the joined placements as they were).
import assert from 'node:assert/strict';
import { after, before, describe, it } from 'node:test';
import { http, removeDir, startDaemon, tempDir, waitJob, WsClient } from './harness.js';
import { parsePly } from './clouds.js';
import { buildingPly, glassOf, ORIGIN, windowBox } from './points_building.js';

const box6 = (s) => s.split(',').map(Number);
const offsetOf = (ply) => {
  const c = ply.comments.find((x) => x.startsWith('offset'));
  return c ? c.split(' ').slice(1).map(Number) : [0, 0, 0];
};
const near = (a, b, eps = 1e-6) => a.length === b.length && a.every((v, i) => Math.abs(v - b[i]) <= eps);

// Every component of `before` but those in `gone` is at its id in `after` with its kind and box.
function assertKept(before, after, gone, what) {
  let kept = 0;
  for (const n of before.nodes) {
    if (n.kind !== 'component' || gone.has(n.id)) continue;
    const m = after.nodes[n.id];
    assert.ok(m && m.id === n.id && m.kind === 'component', `${what}: node ${n.id} lost its id (${JSON.stringify(m)})`);
    assert.ok(near(m.box, n.box), `${what}: node ${n.id} has box ${JSON.stringify(m.box)}, not ${JSON.stringify(n.box)}`);
    kept++;
  }
  return kept;
}

const components = (t) => t.nodes.filter((n) => n.kind === 'component').length;

describe('point model edits keep node ids', () => {
  let d;
  let id;
  const dir = tempDir();
  before(async () => {
    d = await startDaemon({ dir });
  });
  after(async () => {
    if (d) { try { await d.stop(); } finally { await d.kill(); } }
    removeDir(dir);
  });

  const tree = async () => {
    const r = await http(d, 'GET', `/api/v1/models/${id}/tree`);
    assert.equal(r.status, 200, r.text.slice(0, 300));
    r.json.nodes.forEach((n, i) => assert.equal(n.id, i, `node ${i} is at its id`));
    return r.json;
  };
  const op = async (body, cid) => {
    const v = (await http(d, 'GET', `/api/v1/models/${id}`)).json.version;
    const r = await http(d, 'POST', `/api/v1/models/${id}/ops`, { body: { op: body, cid }, headers: { 'If-Match': `"${v}"` }, timeout: 120000 });
    assert.equal(r.status, 200, r.text.slice(0, 400));
    return r.json;
  };

  let t0, t1, t2, t3, t4;
  const removed = new Set();

  it('a remove over REST keeps every other node at its id', async () => {
    const q = new URLSearchParams({ name: 'house', format: 'ply' });
    const up = await http(d, 'POST', `/api/v1/models?${q}`, { body: buildingPly(60000).bytes, headers: { 'Content-Type': 'application/octet-stream' }, timeout: 120000 });
    assert.equal(up.status, 202, up.text);
    id = (await waitJob(d, up.json.id, { timeout: 120000 })).result.model;
    const pj = await http(d, 'POST', `/api/v1/models/${id}/proceduralize`, { body: { templates: [box6(windowBox(2))], auto: false } });
    assert.equal(pj.status, 202, pj.text);
    const job = await waitJob(d, pj.json.id, { timeout: 120000 });
    assert.equal(job.status, 'succeeded', JSON.stringify(job.error));
    t0 = await tree();
    const w = glassOf(t0, 1);
    assert.ok(w, 'window 1');
    await op({ kind: 'remove', nodes: [w.id] }, 'rm-1');
    removed.add(w.id);
    t1 = await tree();
    assert.equal(assertKept(t0, t1, removed, 'after the remove'), components(t0) - 1);
    assert.notEqual(t1.nodes[w.id]?.kind, 'component', 'the removed window is not a component any more');
    assert.equal(glassOf(t1, 1), undefined, 'window 1 is gone');
  });

  it('a remove over the websocket names a kept id and keeps the others', async () => {
    const W = await WsClient.open(d.wsUrl);
    try {
      const wel = await W.request({ type: 'hello', model: id, user: 'ana' }, 'welcome');
      const w = glassOf(t1, 6);
      assert.ok(w, 'window 6');
      // the id the client holds from the tree before the first remove
      assert.equal(w.id, glassOf(t0, 6).id);
      const r = await W.request({ type: 'op', cid: 'rm-2', base: wel.version, op: { kind: 'remove', nodes: [w.id] } },
        (m) => (m.type === 'ack' || m.type === 'nack') && m.cid === 'rm-2', 120000);
      assert.equal(r.type, 'ack', JSON.stringify(r));
      removed.add(w.id);
    } finally {
      await W.close();
    }
    t2 = await tree();
    assert.equal(assertKept(t0, t2, removed, 'after both removes'), components(t0) - 2);
    assert.equal(glassOf(t2, 6), undefined, 'window 6 is gone');
  });

  it('a restart serves the same ids, and an op names them', async () => {
    await d.stop();
    d = await startDaemon({ dir, db: d.db });
    const back = await tree();
    assert.deepEqual(back.nodes, t2.nodes);
    // a remove of window 3's glass by the id it had before any edit
    const w = glassOf(t0, 3);
    await op({ kind: 'remove', nodes: [w.id] }, 'rm-3');
    removed.add(w.id);
    t3 = await tree();
    assert.equal(assertKept(t0, t3, removed, 'after a restart and a third remove'), components(t0) - 3);
    assert.equal(glassOf(t3, 3), undefined, 'window 3 is gone');
    assert.ok(Math.abs(t3.nodes[t3.root].box[0] - ORIGIN[0]) < 0.1, 'the model stays where it is');
  });

  it('a resize of a window keeps every node at its id, its rule-mates with their new boxes; undo and redo keep them', async () => {
    const left = [0, 2, 4, 5, 7, 8, 9].map((w) => glassOf(t3, w));
    left.forEach((w, i) => assert.ok(w, `window ${i}`));
    const grow = (b) => [b[0], b[1], b[2], b[3] + 0.1, b[4], b[5] + 0.1];
    const w7 = glassOf(t3, 7);
    await op({ kind: 'resize', node: w7.id, box: grow(w7.box) }, 'grow-7');
    t4 = await tree();
    // every window, the one resized and those of its rule, is at its id with its new box
    for (const w of left) {
      const m = t4.nodes[w.id];
      assert.ok(m && m.kind === 'component', `window node ${w.id} lost its id (${JSON.stringify(m)})`);
      assert.ok(near(m.box, grow(w.box), 1e-3), `window node ${w.id} has box ${JSON.stringify(m.box)}, not ${JSON.stringify(grow(w.box))}`);
    }
    // and so is every other node: a resize removes nothing
    let kept = 0;
    for (const n of t3.nodes) {
      if (n.kind !== 'component') continue;
      assert.equal(t4.nodes[n.id]?.kind, 'component', `node ${n.id} is no component after the resize`);
      kept++;
    }
    assert.equal(kept, components(t3));
    assert.equal(components(t4), components(t3));
    // undo brings the tree before the resize back, ids and boxes; redo the resized one
    await op({ kind: 'undo' }, 'undo-grow');
    assert.deepEqual((await tree()).nodes, t3.nodes);
    await op({ kind: 'redo' }, 'redo-grow');
    assert.deepEqual((await tree()).nodes, t4.nodes);
  });

  it('a resize of the whole building past a metre of its origin keeps every node at its id', async () => {
    // the model is kept local to a whole metre below its lower corner: growing the building a
    // metre towards -x moves that origin, and the ids follow the nodes there too
    const root = t4.nodes[t4.root];
    const box = [root.box[0] - 1, ...root.box.slice(1)];
    await op({ kind: 'resize', node: 'root', box }, 'grow-west');
    const t5 = await tree();
    assert.ok(near(t5.nodes[t5.root].box, box, 1e-3), `the root has box ${JSON.stringify(t5.nodes[t5.root].box)}`);
    for (const n of t4.nodes) {
      if (n.kind !== 'component') continue;
      const m = t5.nodes[n.id];
      assert.equal(m?.kind, 'component', `node ${n.id} is no component after the resize (${JSON.stringify(m)})`);
      // stretched by 17/16 at most, moved by a metre at most: never another node's place
      assert.ok(m.box.every((v, i) => Math.abs(v - n.box[i]) <= 1.001), `node ${n.id} went from ${JSON.stringify(n.box)} to ${JSON.stringify(m.box)}`);
    }
    assert.equal(components(t5), components(t4));
  });

  // A point model has no joined terminal: a join reads the joined group back as its members'
  // placements, where they were. So a join removes no node, and every node keeps its id and
  // box, the two joined windows too; undo gives the same tree back.
  it('a join on a model of its own keeps every node at its id, the joined windows too', async () => {
    const q = new URLSearchParams({ name: 'house', format: 'ply' });
    const up = await http(d, 'POST', `/api/v1/models?${q}`, { body: buildingPly(60000).bytes, headers: { 'Content-Type': 'application/octet-stream' }, timeout: 120000 });
    assert.equal(up.status, 202, up.text);
    id = (await waitJob(d, up.json.id, { timeout: 120000 })).result.model;
    const pj = await http(d, 'POST', `/api/v1/models/${id}/proceduralize`, { body: { templates: [box6(windowBox(2))], auto: false } });
    assert.equal(pj.status, 202, pj.text);
    assert.equal((await waitJob(d, pj.json.id, { timeout: 120000 })).status, 'succeeded');
    const t0 = await tree();
    const a = glassOf(t0, 0), b = glassOf(t0, 1);
    assert.ok(a && b, 'windows 0 and 1');
    await op({ kind: 'join', nodes: [a.id, b.id] }, 'join-0-1');
    const t1 = await tree();
    assert.equal(assertKept(t0, t1, new Set(), 'after the join'), components(t0));
    assert.equal(components(t1), components(t0), 'the join adds no node');
    assert.equal(glassOf(t1, 0)?.id, a.id);
    assert.equal(glassOf(t1, 1)?.id, b.id);
    await op({ kind: 'undo' }, 'undo-join');
    assert.equal(assertKept(t0, await tree(), new Set(), 'after undo'), components(t0));
  });
});

// A cloud's segment ids (issue 14 §4, before any proceduralization): segment_roi keeps the id
// of every segment with points outside its box, a restart serves the same ids from the store
// (each id's kind with them), and a mark_template after it keeps every id and label, its
// template at the next id; undo brings the ids before it back.
describe('cloud segment ids survive segment_roi, a restart and mark_template', () => {
  let d;
  let id;
  const dir = tempDir();
  before(async () => {
    d = await startDaemon({ dir });
  });
  after(async () => {
    if (d) { try { await d.stop(); } finally { await d.kill(); } }
    removeDir(dir);
  });
  const op = async (body, cid) => {
    const v = (await http(d, 'GET', `/api/v1/models/${id}`)).json.version;
    const r = await http(d, 'POST', `/api/v1/models/${id}/ops`, { body: { op: body, cid }, headers: { 'If-Match': `"${v}"` }, timeout: 120000 });
    assert.equal(r.status, 200, r.text.slice(0, 400));
    return r.json;
  };
  const ply = async () => {
    const r = await http(d, 'GET', `/api/v1/models/${id}/points.ply`, { timeout: 60000 });
    assert.equal(r.status, 200, r.text.slice(0, 300));
    return parsePly(r.body);
  };
  const logged = async (kind) => (await http(d, 'GET', `/api/v1/models/${id}/ops`)).json.items.filter((e) => e.op.kind === kind).at(-1);

  it('keeps every id', async () => {
    const q = new URLSearchParams({ name: 'house', format: 'ply' });
    const up = await http(d, 'POST', `/api/v1/models?${q}`, { body: buildingPly(60000).bytes, headers: { 'Content-Type': 'application/octet-stream' }, timeout: 120000 });
    assert.equal(up.status, 202, up.text);
    id = (await waitJob(d, up.json.id, { timeout: 120000 })).result.model;
    const sj = await http(d, 'POST', `/api/v1/models/${id}/segment`, { body: {} });
    assert.equal(sj.status, 202, sj.text);
    assert.equal((await waitJob(d, sj.json.id, { timeout: 120000 })).status, 'succeeded');
    const off = (await http(d, 'GET', `/api/v1/models/${id}`)).json.stats.offset;
    const local = (b) => box6(b).map((v, k) => v - off[k % 3]);
    const s0 = await ply();
    const at = (s, i) => [s.props.x[i], s.props.y[i], s.props.z[i]].map((v, k) => v + offsetOf(s)[k] - off[k]);
    const inside = (b, s, i) => at(s, i).every((v, k) => v >= b[k] - 1e-6 && v <= b[3 + k] + 1e-6);
    // the front wall: the segment most of the points at y = 0 are in
    const count = new Map();
    for (let i = 0; i < s0.n; i++) {
      const s = s0.props.segment[i];
      if (s >= 0 && Math.abs(at(s0, i)[1] - (ORIGIN[1] - off[1])) < 0.01) count.set(s, (count.get(s) ?? 0) + 1);
    }
    const wall = [...count.entries()].sort((a, b) => b[1] - a[1])[0][0];
    // ROI: window 7 and the wall around it, finer
    const roi = local(windowBox(7, 0.6));
    await op({ kind: 'segment_roi', box: roi, threshold: 0.005 }, 'roi');
    const r1 = (await logged('segment_roi')).op.report;
    assert.equal(r1.segments_before, Math.max(...s0.props.segment) + 1);
    const s1 = await ply();
    let fresh = 0;
    for (let i = 0; i < s1.n; i++) {
      if (!inside(roi, s1, i)) assert.equal(s1.props.segment[i], s0.props.segment[i], `point ${i} outside the ROI changed segment`);
      else if (s1.props.segment[i] >= 0) { assert.ok(s1.props.segment[i] >= r1.segments_before, `point ${i} inside the ROI is in old segment ${s1.props.segment[i]}`); fresh++; }
    }
    assert.ok(fresh > 0, 'the ROI made new segments');
    // a restart serves the same ids and labels
    await d.stop();
    d = await startDaemon({ dir, db: d.db });
    const s1b = await ply();
    assert.deepEqual(s1b.props.segment, s1.props.segment);
    assert.deepEqual(s1b.props.label, s1.props.label);
    // a template on the wall around window 1, by the wall's id from before the ROI
    const rep = (await op({ kind: 'mark_template', segment: wall, box: local(windowBox(1, 0.5)) }, 'tmpl')).report ?? (await logged('mark_template')).op.report;
    assert.equal(rep.template_segment, r1.segment_ids, JSON.stringify(rep));
    assert.ok(rep.copies >= 1, JSON.stringify(rep));
    const s2 = await ply();
    const label1 = new Map();
    for (let i = 0; i < s1.n; i++) if (s1.props.segment[i] >= 0) label1.set(s1.props.segment[i], s1.props.label[i]);
    let marked = 0;
    for (let i = 0; i < s2.n; i++) {
      const s = s2.props.segment[i];
      if (s >= r1.segment_ids) {
        assert.equal(s1.props.segment[i], wall, `point ${i} of the template or a copy was not the wall's`);
        assert.equal(s2.props.label[i], rep.label);
        marked++;
      } else {
        assert.equal(s, s1.props.segment[i], `point ${i} changed segment`);
        if (s >= 0 && s !== wall) assert.equal(s2.props.label[i], label1.get(s), `segment ${s} changed label`);
      }
    }
    assert.ok(marked >= rep.template_points);
    console.log(`# cloud segment ids: ROI ${r1.segments_before} → ${r1.segment_ids} ids (${r1.segments} segments), kept outside it, over a restart and a template with ${rep.copies} copies`);
    // undo brings the ids of before the template back
    await op({ kind: 'undo' }, 'undo-tmpl');
    assert.deepEqual((await ply()).props.segment, s1.props.segment);
  });
});
