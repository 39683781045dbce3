// Edits across models and edit history as a service: a paste from another model (style
// transfer between buildings), random sequences of structural ops undone and redone exactly,
// and grammar text edits (PUT …/grammar) as undo steps of their author.
import assert from 'node:assert/strict';
import { after, before, describe, it } from 'node:test';
import {
  assertProblem, http, importModel, removeDir, rng, startDaemon, waitJob,
} from './harness.js';

// One OBJ group per box (y-up): [name, x0, y0, z0, x1, y1, z1].
function boxesObj(boxes) {
  const v = [];
  const f = [];
  for (const [name, x0, y0, z0, x1, y1, z1] of boxes) {
    f.push(`g ${name}`);
    const b = v.length + 1;
    for (const z of [z0, z1]) for (const y of [y0, y1]) for (const x of [x0, x1]) v.push(`v ${x} ${y} ${z}`);
    for (const q of [[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]]) {
      f.push(`f ${q.map((i) => b + i).join(' ')}`);
    }
  }
  return Buffer.from(`${v.join('\n')}\n${f.join('\n')}\n`);
}

// A wall with a cols × rows grid of identical windows in front of it.
const facade = (cols, rows) => boxesObj([
  ['wall', 0, 0, 0, 2.5 * cols + 2.5, 3.2 * rows + 0.8, 0.3],
  ...Array.from({ length: cols * rows }, (_, k) => {
    const i = k % cols;
    const j = Math.floor(k / cols);
    return [`window_${j}_${i}`, 1 + 2.5 * i, 1 + 3.2 * j, 0.3, 2.3 + 2.5 * i, 2.86 + 3.2 * j, 0.5];
  }),
]);
// A bare 8 m wall on a plinth: nothing to repeat.
const bareWall = () => boxesObj([['wall', 0, 0, 0, 8, 4, 0.3], ['plinth', 0, 0, 0.3, 8, 0.4, 0.6]]);

const area = (n) => (n.box[3] - n.box[0]) * (n.box[4] - n.box[1]) + (n.box[3] - n.box[0]) * (n.box[5] - n.box[2]) +
  (n.box[4] - n.box[1]) * (n.box[5] - n.box[2]);
const visible = (t) => t.nodes.filter((n) => n.visible);
// the wall: the visible node with the largest box
const wallOf = (t) => visible(t).sort((a, b) => area(b) - area(a))[0];

describe('edits across models and edit history', () => {
  let d;

  const proceduralize = async (body, name) => {
    const m = await importModel(d, body, { name });
    const r = await http(d, 'POST', `/api/v1/models/${m.id}/proceduralize`, {});
    assert.equal(r.status, 202, r.text);
    const job = await waitJob(d, r.json.id, { timeout: 60000 });
    assert.equal(job.status, 'succeeded', JSON.stringify(job));
    return getModel(m.id);
  };
  const getModel = async (id) => {
    const r = await http(d, 'GET', `/api/v1/models/${id}`);
    assert.equal(r.status, 200, r.text);
    return r.json;
  };
  const tree = async (id) => {
    const r = await http(d, 'GET', `/api/v1/models/${id}/tree`);
    assert.equal(r.status, 200, r.text);
    return r.json;
  };
  // the served tree without the version it is served for, and the grammar, as text
  const state = async (id) => {
    const r = await http(d, 'GET', `/api/v1/models/${id}/tree`);
    assert.equal(r.status, 200, r.text);
    const t = JSON.parse(r.text);
    delete t.version;
    const g = await http(d, 'GET', `/api/v1/models/${id}/grammar`);
    assert.equal(g.status, 200, g.text);
    return { tree: JSON.stringify(t), grammar: g.text };
  };
  const sameState = (a, b, what) => {
    assert.ok(a.tree === b.tree, `${what}: the tree differs`);
    assert.ok(a.grammar === b.grammar, `${what}: the grammar differs`);
  };
  const post = (id, op, version, user) => http(d, 'POST', `/api/v1/models/${id}/ops`, {
    body: { op }, headers: { 'If-Match': `"${version}"`, 'X-Archgram-User': user }, timeout: 60000,
  });

  before(async () => {
    d = await startDaemon({ args: ['--workers', '1', '--no-web'] });
  });
  after(async () => {
    if (d) { try { await d.stop(); } finally { await d.kill(); removeDir(d.dir); } }
  });

  it('a paste from another model copies its window onto this wall; the source model is only read', async () => {
    const A = await proceduralize(facade(3, 1), 'windows');
    const B = await proceduralize(bareWall(), 'bare');
    const plain = await importModel(d, bareWall(), { name: 'plain' });
    const a0 = await state(A.id);
    const tA = await tree(A.id);
    const tB = await tree(B.id);
    const b0 = await state(B.id);
    const wallA = wallOf(tA);
    const win = visible(tA).find((n) => n.id !== wallA.id);
    const wallB = wallOf(tB);
    const before = visible(tB).length;
    const op = { kind: 'paste', source: [win.id], target: wallB.id, placement: 'insert', fit: 'fill', source_model: A.id };

    // precise problems first: nothing is stored
    let r = await post(B.id, { ...op, source_model: 99999 }, B.version, 'sty');
    assertProblem(r, 404, 'not-found', 'unknown source model');
    assert.match(r.json.detail, /source_model: there is no model 99999/);
    r = await post(B.id, { ...op, source_model: plain.id }, B.version, 'sty');
    assertProblem(r, 409, 'not-proceduralized', 'plain source model');
    assert.match(r.json.detail, new RegExp(`source_model: model ${plain.id} is not proceduralized`));
    r = await post(B.id, { ...op, source: [99999] }, B.version, 'sty');
    assertProblem(r, 404, 'not-found', 'unknown source node');
    assert.match(r.json.detail, new RegExp(`source\\[0\\] \\(of model ${A.id}\\).*99999`));
    r = await post(B.id, { kind: 'paste', source: [win.id], target: wallB.id, source_dir: '/tmp' }, B.version, 'sty');
    assertProblem(r, 400, 'invalid', 'source_dir in the service');
    assert.match(r.json.detail, /^source_dir:/);
    assert.equal((await getModel(B.id)).version, B.version);

    r = await post(B.id, op, B.version, 'sty');
    assert.equal(r.status, 200, r.text);
    assert.equal(r.json.version, B.version + 1);
    const tB1 = await tree(B.id);
    const after1 = visible(tB1);
    assert.ok(after1.length >= before + 2, `B gets new instances: ${before} → ${after1.length}`);
    // the pasted windows have the source window's size and lie on B's wall
    const h = win.box[5] - win.box[2];
    // (fill repeats it at a whole count per axis, each copy stretched to its cell: sizes within 15%)
    const w = win.box[3] - win.box[0];
    const pasted = after1.filter((n) => Math.abs(n.box[5] - n.box[2] - h) < 0.15 * h && Math.abs(n.box[3] - n.box[0] - w) < 0.15 * w);
    assert.ok(pasted.length >= 2, JSON.stringify(after1.map((n) => n.box)));
    for (const n of pasted) {
      for (const k of [0, 2]) assert.ok(n.box[k] >= wallB.box[k] - 1e-6 && n.box[k + 3] <= wallB.box[k + 3] + 1e-6, JSON.stringify([n.box, wallB.box]));
    }
    assert.notEqual((await state(B.id)).grammar, b0.grammar);
    const log = (await http(d, 'GET', `/api/v1/models/${B.id}/ops`)).json.items;
    assert.equal(log.at(-1).op.kind, 'paste');
    assert.equal(log.at(-1).op.source_model, A.id);
    assert.equal(log.at(-1).op.report.source_version, A.version);
    // A unchanged
    assert.equal((await getModel(A.id)).version, A.version);
    sameState(await state(A.id), a0, 'the source model');
    // the paste is one undo step of its author
    const u = await post(B.id, { kind: 'undo' }, r.json.version, 'sty');
    assert.equal(u.status, 200, u.text);
    sameState(await state(B.id), b0, 'B after undoing the paste');
  });

  it('random sequences of ops followed by their undos return the original tree exactly; redos the edited one', async () => {
    const M = await proceduralize(facade(4, 2), 'random');
    // fixed seed; ARCHGRAM_EDIT_SEED tries another sequence
    const next = rng(Number(process.env.ARCHGRAM_EDIT_SEED ?? 20261123));
    const pick = (xs) => xs[Math.floor(next() * xs.length)];
    // every kind once, in a random order, then random kinds
    const KINDS = ['resize-global', 'resize-local', 'split', 'join', 'paste', 'remove'];
    const order = [...KINDS];
    for (let i = order.length - 1; i > 0; i--) {
      const j = Math.floor(next() * (i + 1));
      [order[i], order[j]] = [order[j], order[i]];
    }
    order.push(pick(KINDS), pick(KINDS));
    const N = order.length;
    const user = 'rnd';
    let version = M.version;
    const states = [await state(M.id)];
    const applied = [];
    // one random valid op on the current tree
    const randomOp = (t, kind) => {
      const vis = visible(t);
      const wall = wallOf(t);
      const wins = vis.filter((n) => n.id !== wall.id);
      const node = pick(vis);
      const b = [...node.box];
      switch (kind) {
        case 'resize-global':
        case 'resize-local': {
          const a = pick([0, 2]);
          const f = 0.75 + 0.6 * next();
          b[a + 3] = b[a] + f * (b[a + 3] - b[a]);
          return { kind: 'resize', node: node.id, box: b, mode: kind === 'resize-global' ? 'global' : 'local' };
        }
        case 'split': {
          const a = pick([0, 2]);
          return { kind: 'split', node: node.id, axis: 'xyz'[a], at: b[a] + (0.3 + 0.4 * next()) * (b[a + 3] - b[a]) };
        }
        case 'join': {
          if (wins.length < 2) return null;
          const w = pick(wins);
          // its nearest other window
          const other = wins.filter((x) => x.id !== w.id)
            .sort((p, q) => Math.hypot(p.box[0] - w.box[0], p.box[2] - w.box[2]) - Math.hypot(q.box[0] - w.box[0], q.box[2] - w.box[2]))[0];
          return { kind: 'join', nodes: [w.id, other.id] };
        }
        case 'paste':
          if (!wins.length) return null;
          return { kind: 'paste', source: [pick(wins).id], target: wall.id, placement: pick(['insert', 'replace']), fit: pick(['fill', 'derive']) };
        default:
          if (wins.length < 2) return null;
          return { kind: 'remove', nodes: [pick(wins).id] };
      }
    };
    let attempts = 0;
    while (applied.length < N) {
      assert.ok(++attempts < 80, `only ${applied.length} of ${N} random ops applied: ${JSON.stringify(applied)}`);
      const op = randomOp(await tree(M.id), order[applied.length]);
      if (!op) continue;
      const r = await post(M.id, op, version, user);
      if (r.status !== 200) {
        // a random op may be refused (e.g. a plane outside a node): never a server error,
        // and nothing is stored
        assert.ok(r.status >= 400 && r.status < 500, `${JSON.stringify(op)}: ${r.status} ${r.text}`);
        assert.equal((await getModel(M.id)).version, version);
        continue;
      }
      version = r.json.version;
      applied.push(order[applied.length]);
      states.push(await state(M.id));
      assert.ok(states.at(-1).tree !== states.at(-2).tree || states.at(-1).grammar !== states.at(-2).grammar,
        `${op.kind} changed nothing`);
    }
    console.log(`# random ops (${attempts} tried): ${applied.join(', ')}`);
    for (let k = N - 1; k >= 0; k--) {
      const u = await post(M.id, { kind: 'undo' }, version, user);
      assert.equal(u.status, 200, u.text);
      version = u.json.version;
      sameState(await state(M.id), states[k], `after undoing ${applied[k]} (#${k + 1})`);
    }
    sameState(await state(M.id), states[0], 'after every undo');
    const none = await post(M.id, { kind: 'undo' }, version, user);
    assertProblem(none, 409, 'undo-conflict', 'nothing left to undo');
    for (let k = 1; k <= N; k++) {
      const r = await post(M.id, { kind: 'redo' }, version, user);
      assert.equal(r.status, 200, r.text);
      version = r.json.version;
      sameState(await state(M.id), states[k], `after redoing ${applied[k - 1]} (#${k})`);
    }
    sameState(await state(M.id), states[N], 'after every redo');
  });

  it('a grammar edit over PUT is an undo step of its author: undo brings back the old text exactly', async () => {
    const M = await proceduralize(facade(4, 1), 'grammar');
    const s0 = await state(M.id);
    const put = (text, version, user) => http(d, 'PUT', `/api/v1/models/${M.id}/grammar`, {
      body: text, headers: { 'If-Match': `"${version}"`, 'X-Archgram-User': user, 'Content-Type': 'text/plain' }, timeout: 60000,
    });
    // a pattern count: one window fewer
    const m = s0.grammar.match(/subdivide\((\w+), (\d+),/);
    assert.ok(m, s0.grammar);
    const fewer = s0.grammar.replace(m[0], `subdivide(${m[1]}, ${Number(m[2]) - 1},`);
    let r = await put(fewer, M.version, 'gus');
    assert.equal(r.status, 200, r.text);
    const v1 = r.json.version;
    assert.equal(v1, M.version + 1);
    const s1 = await state(M.id);
    assert.equal(s1.grammar, fewer);
    assert.equal(visible(JSON.parse(s1.tree)).length, visible(JSON.parse(s0.tree)).length - 1);
    // a rule parameter: the repeated window 10% narrower
    const rm = fewer.match(/rule (\w+) size ([0-9.e+-]+) /);
    assert.ok(rm, fewer);
    const narrower = fewer.replace(rm[0], `rule ${rm[1]} size ${Number(rm[2]) * 0.9} `);
    r = await put(narrower, v1, 'gus');
    assert.equal(r.status, 200, r.text);
    const s2 = await state(M.id);
    assert.equal(s2.grammar, narrower);
    assert.notEqual(s2.tree, s1.tree);
    const log = (await http(d, 'GET', `/api/v1/models/${M.id}/ops`)).json.items;
    assert.equal(log.at(-1).op.kind, 'grammar');
    assert.equal(log.at(-1).author, 'gus');
    // someone else cannot undo gus's grammar edit
    let u = await post(M.id, { kind: 'undo' }, r.json.version, 'hal');
    assertProblem(u, 409, 'undo-conflict', "another person's undo");
    u = await post(M.id, { kind: 'undo' }, r.json.version, 'gus');
    assert.equal(u.status, 200, u.text);
    sameState(await state(M.id), s1, 'after undoing the rule parameter');
    u = await post(M.id, { kind: 'undo' }, u.json.version, 'gus');
    assert.equal(u.status, 200, u.text);
    sameState(await state(M.id), s0, 'after undoing the pattern count');
    assert.equal((await http(d, 'GET', `/api/v1/models/${M.id}/grammar`)).text, s0.grammar);
    const rd = await post(M.id, { kind: 'redo' }, u.json.version, 'gus');
    assert.equal(rd.status, 200, rd.text);
    sameState(await state(M.id), s1, 'after redoing the pattern count');
    // a structural edit after the redo works on the re-derived model
    const t = await tree(M.id);
    const b = [...t.nodes[0].box];
    b[3] = b[0] + 1.2 * (b[3] - b[0]);
    const e = await post(M.id, { kind: 'resize', node: 'root', box: b }, rd.json.version, 'gus');
    assert.equal(e.status, 200, e.text);
  });
});
