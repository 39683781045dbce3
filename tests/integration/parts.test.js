// The parts library as a service: parts saved from a model (a node or a selection's common
// ancestor) with thumbnails, meshes and provenance; search by words and tags with paging;
// versions; bundles exported and imported on a fresh database byte for byte; bad bundles
// refused whole with the element named and nothing stored; deleting with If-Match; compose
// ops over REST and the websocket seen by a second client, previewed first, undone; and a part
// that outlives the model it came from. Geometry is checked on the served trees: every slot of
// the target holds the part's pieces, the frame bars keep their width.
import assert from 'node:assert/strict';
import crypto from 'node:crypto';
import { after, before, describe, it } from 'node:test';
import { decodePng } from '../browser/png.js';
import {
  WsClient, assertProblem, http, importModel, parseGlb, removeDir, startDaemon, waitJob,
  proceduralizedWall, windowWallObj,
} from './harness.js';

const A = { cols: 3, rows: 2, ww: 1.2, wh: 1.8, frame: 0.08, mullions: 1 };
const B = { cols: 4, rows: 2, ww: 1.6, wh: 2.0, frame: 0.12, mullions: 2 };

const near = (a, b, tol = 1e-6) => a.every((x, i) => Math.abs(x - b[i]) < tol);
const inSlot = (n, s) => n.box.every((x, i) => (i < 3 ? x >= s[i] - 1e-6 : x <= s[i] + 1e-6));
const pieces = (tree, s) => tree.nodes.filter((n) => n.kind === 'component' && inSlot(n, s));

describe('parts library', () => {
  let d;
  const dirs = [];

  const proceduralized = async (opt, name) => {
    const { id, slots } = await proceduralizedWall(d, opt, name);
    const t = await tree(id);
    return { id, slots, version: t.version, tree: t, nodeOf: (s) => t.nodes.find((n) => n.kind === 'component' && near(n.box, s)).id };
  };
  const tree = async (id) => {
    const r = await http(d, 'GET', `/api/v1/models/${id}/tree`);
    assert.equal(r.status, 200, r.text);
    return r.json;
  };
  const grammar = async (id) => {
    const r = await http(d, 'GET', `/api/v1/models/${id}/grammar`);
    assert.equal(r.status, 200, r.text);
    return r.text;
  };
  const version = async (id) => (await http(d, 'GET', `/api/v1/models/${id}`)).json.version;
  const save = (body, status = 201) => http(d, 'POST', '/api/v1/parts', { body }).then((r) => {
    assert.equal(r.status, status, r.text);
    return r;
  });
  const partCount = async (daemon = d) => {
    const r = await http(daemon, 'GET', '/api/v1/parts?page_size=200');
    assert.equal(r.status, 200, r.text);
    return r.json.items.length;
  };
  const op = (model, base, body, user = 'ana') => http(d, 'POST', `/api/v1/models/${model}/ops`, {
    body: { op: body }, headers: { 'If-Match': `"${base}"`, 'X-Archgram-User': user },
  });

  let a, b, window;

  before(async () => {
    d = await startDaemon();
    a = await proceduralized(A, 'a');
    b = await proceduralized(B, 'b');
  });
  after(async () => {
    await d?.stop();
    removeDir(d?.dir);
    for (const x of dirs) removeDir(x);
  });

  it('saves a window of a model with its thumbnail, mesh and provenance', async () => {
    const node = a.nodeOf(a.slots[1]);
    const r = await save({ model: a.id, version: a.version, node, name: 'sash window', tags: ['window', 'timber'], description: 'one mullion' });
    window = r.json;
    assert.equal(r.headers.get('location'), `/api/v1/parts/${window.id}`);
    assert.equal(r.headers.get('etag'), '"1"');
    assert.deepEqual(window.tags, ['window', 'timber']);
    assert.equal(window.version, 1);
    assert.equal(window.versions.length, 1);
    const v1 = window.versions[0];
    assert.deepEqual(v1.source, { model: a.id, name: 'a', version: a.version, node });
    assert.equal(v1.stats.visible, 7); // casing, four bars, pane, mullion
    assert.ok(near(v1.stats.size, [1.2, 0.16, 1.8]));

    // the thumbnail: a 128 × 128 PNG, the window in the middle, transparent around it
    const png = await http(d, 'GET', window.thumbnail);
    assert.equal(png.status, 200);
    assert.equal(png.headers.get('content-type'), 'image/png');
    const img = decodePng(png.body);
    assert.equal(img.width, 128);
    assert.equal(img.height, 128);
    const alpha = (x, y) => img.data[4 * (y * 128 + x) + 3];
    assert.equal(alpha(0, 0), 0);
    assert.equal(alpha(64, 64), 255);
    let covered = 0;
    for (let i = 0; i < 128 * 128; i++) covered += img.data[4 * i + 3] > 127;
    assert.ok(covered > 0.2 * 128 * 128 && covered < 0.9 * 128 * 128, `covered ${covered}`);
    const again = await http(d, 'GET', window.thumbnail, { headers: { 'If-None-Match': png.headers.get('etag') } });
    assert.equal(again.status, 304);

    // its mesh: the seven pieces with their labels, inside the slot it came from
    const glb = await http(d, 'GET', window.mesh);
    assert.equal(glb.status, 200);
    const g = parseGlb(glb.body);
    assert.equal(g.magic, 'glTF');
    const labelled = g.json.nodes.filter((n) => typeof n.extras?.label === 'string');
    assert.equal(labelled.length, 7);

    // a selection saves its common ancestor: the window's members → the window (two bars
    // alone meet at the pattern that repeats them)
    const t = a.tree;
    const bars = pieces(t, a.slots[1]).filter((n) => n.id !== node).map((n) => n.id);
    assert.equal(bars.length, 6);
    const sel = await http(d, 'GET', `/api/v1/models/${a.id}/selection?nodes=${bars.join(',')}&version=${a.version}`);
    assert.equal(sel.status, 200, sel.text);
    assert.equal(sel.json.tree, node);
    assert.ok(sel.json.rule.length >= 1);
    const r2 = await save({ model: a.id, version: a.version, nodes: bars, name: 'sash window (selected)', tags: ['window'] });
    assert.equal(r2.json.versions[0].source.node, node);
  });

  it('refuses bad saves precisely', async () => {
    const base = { model: a.id, version: a.version, name: 'w' };
    let r = await http(d, 'POST', '/api/v1/parts', { body: { ...base, node: 99999 } });
    assertProblem(r, 404, 'not-found', 'unknown node');
    assert.match(r.json.detail, /node/);
    r = await http(d, 'POST', '/api/v1/parts', { body: { ...base, version: a.version + 5, node: 3 } });
    assertProblem(r, 412, 'stale', 'other version');
    r = await http(d, 'POST', '/api/v1/parts', { body: { model: a.id, version: a.version, node: 3 } });
    assertProblem(r, 400, 'invalid', 'no name');
    r = await http(d, 'POST', '/api/v1/parts', { body: { ...base, node: 3, colour: 'red' } });
    assertProblem(r, 400, 'invalid', 'unknown member');
    assert.match(r.json.detail, /colour/);
    r = await http(d, 'POST', '/api/v1/parts', { body: { ...base, node: 3, nodes: [3] } });
    assertProblem(r, 400, 'invalid', 'node and nodes');
    r = await http(d, 'POST', '/api/v1/parts', { body: { ...base, node: 3, tags: ['x'.repeat(300)] } });
    assertProblem(r, 400, 'invalid', 'long tag');
    const raw = await importModel(d, Buffer.from(windowWallObj(A).obj), { name: 'raw', up: 'z' });
    r = await http(d, 'POST', '/api/v1/parts', { body: { model: raw.id, version: raw.version, node: 1, name: 'w' } });
    assertProblem(r, 409, 'not-proceduralized', 'not proceduralized');
    r = await http(d, 'POST', '/api/v1/parts', { body: { ...base, model: 987654, node: 1 } });
    assertProblem(r, 404, 'not-found', 'no model');
  });

  it('finds parts by words and tags, page by page', async () => {
    const node = b.nodeOf(b.slots[0]);
    await save({ model: b.id, version: b.version, node, name: 'bay window', tags: ['window', 'stone'], description: 'two mullions, wide' });
    await save({ model: b.id, version: b.version, node, name: 'front door', tags: ['door'], description: 'panelled timber' });
    const list = async (q) => {
      const r = await http(d, 'GET', `/api/v1/parts?${new URLSearchParams(q)}`);
      assert.equal(r.status, 200, r.text);
      return r.json;
    };
    const names = (page) => page.items.map((p) => p.name).sort();
    assert.deepEqual(names(await list({ q: 'wind' })), ['bay window', 'sash window', 'sash window (selected)']);
    assert.deepEqual(names(await list({ q: 'mull' })), ['bay window', 'sash window']); // descriptions
    assert.deepEqual(names(await list({ q: 'timber' })), ['front door', 'sash window']); // a tag and a description
    assert.deepEqual(names(await list({ tag: 'window' })), ['bay window', 'sash window', 'sash window (selected)']);
    assert.deepEqual(names(await list({ q: 'Sash', tag: 'timber' })), ['sash window']);
    assert.deepEqual(names(await list({ q: 'chimney' })), []);
    // FTS5 syntax is only separators: the words are "wind" and "sash"
    assert.deepEqual(names(await list({ q: '"wind"*( -sash:' })), ['sash window', 'sash window (selected)']);
    // pages of one, followed to the end
    const seen = [];
    let token = null;
    for (let i = 0; i < 10; i++) {
      const page = await list(token ? { page_size: 1, page_token: token } : { page_size: 1 });
      seen.push(...page.items.map((p) => p.id));
      token = page.next_page_token;
      if (!token) break;
    }
    assert.equal(seen.length, 4);
    assert.equal(new Set(seen).size, 4);
    let r = await http(d, 'GET', '/api/v1/parts?page_token=zz');
    assertProblem(r, 400, 'invalid', 'bad token');
    r = await http(d, 'GET', `/api/v1/parts?q=${'a'.repeat(201)}`);
    assertProblem(r, 400, 'invalid', 'long q');
    r = await http(d, 'GET', '/api/v1/parts?page_size=0');
    assertProblem(r, 400, 'invalid', 'page size');
  });

  it('keeps versions: an update is a new version, made on the newest', async () => {
    const node = b.nodeOf(b.slots[2]);
    const url = `/api/v1/parts/${window.id}/versions`;
    let r = await http(d, 'POST', url, { body: { model: b.id, version: b.version, node } });
    assertProblem(r, 428, 'precondition-required', 'no If-Match');
    r = await http(d, 'POST', url, { body: { model: b.id, version: b.version, node, description: 'from b' }, headers: { 'If-Match': '"1"' } });
    assert.equal(r.status, 201, r.text);
    assert.equal(r.headers.get('etag'), '"2"');
    assert.equal(r.json.version, 2);
    assert.equal(r.json.name, 'sash window'); // kept
    assert.deepEqual(r.json.tags, ['window', 'timber']);
    assert.equal(r.json.description, 'from b');
    assert.deepEqual(r.json.versions.map((v) => v.version), [2, 1]);
    assert.equal(r.json.versions[0].stats.visible, 8); // b's windows have two mullions
    assert.equal(r.json.versions[1].stats.visible, 7);
    r = await http(d, 'POST', url, { body: { model: b.id, version: b.version, node }, headers: { 'If-Match': '"1"' } });
    assertProblem(r, 412, 'stale', 'made on version 1 again');
    const t1 = await http(d, 'GET', `/api/v1/parts/${window.id}/thumbnail.png?version=1`);
    const t2 = await http(d, 'GET', `/api/v1/parts/${window.id}/thumbnail.png?version=2`);
    assert.equal(t1.status, 200);
    assert.equal(t2.status, 200);
    assert.notDeepEqual(t1.body, t2.body);
    r = await http(d, 'GET', `/api/v1/parts/${window.id}/thumbnail.png?version=9`);
    assertProblem(r, 404, 'not-found', 'no version 9');
  });

  it('exports a bundle that a fresh database imports byte for byte', async () => {
    const one = await http(d, 'GET', `/api/v1/parts/${window.id}/bundle?version=1`);
    assert.equal(one.status, 200, one.text);
    assert.equal(one.json.format, 'archgram-part-bundle');
    assert.equal(one.json.parts[0].version, 1);
    const all = await http(d, 'GET', '/api/v1/parts:export');
    assert.equal(all.status, 200, all.text);
    assert.equal(all.json.parts.length, await partCount());
    const fresh = await startDaemon();
    dirs.push(fresh.dir);
    try {
      let r = await http(fresh, 'POST', '/api/v1/parts:import', { body: one.body, headers: { 'Content-Type': 'application/json' } });
      assert.equal(r.status, 201, r.text);
      assert.equal(r.json.items.length, 1);
      const id = r.json.items[0].id;
      assert.equal(r.json.items[0].version, 1);
      assert.equal(r.json.items[0].versions[0].source.name, 'a');
      assert.equal(r.json.items[0].versions[0].source.model, null); // provenance, not a reference
      const back = await http(fresh, 'GET', `/api/v1/parts/${id}/bundle`);
      assert.equal(back.status, 200);
      assert.equal(back.text, one.text);
      const png = await http(fresh, 'GET', `/api/v1/parts/${id}/thumbnail.png`);
      assert.equal(png.status, 200);
      r = await http(fresh, 'POST', '/api/v1/parts:import', { body: all.body });
      assert.equal(r.status, 201, r.text);
      assert.equal(await partCount(fresh), 1 + all.json.parts.length);
      const ids = r.json.items.map((p) => p.id).join(',');
      const again = await http(fresh, 'GET', `/api/v1/parts:export?ids=${ids}`);
      assert.equal(again.text, all.text);
    } finally {
      await fresh.stop();
    }
  });

  it('refuses bad bundles whole, naming the element, storing nothing', async () => {
    const good = (await http(d, 'GET', `/api/v1/parts/${window.id}/bundle?version=1`)).json;
    const before = await partCount();
    const refuse = async (bundle, element, detail, what) => {
      const body = typeof bundle === 'string' ? bundle : JSON.stringify(bundle);
      const r = await http(d, 'POST', '/api/v1/parts:import', { body, headers: { 'Content-Type': 'application/json' } });
      assertProblem(r, 422, 'parse', what);
      assert.equal(r.json.element, element, `${what}: ${r.text}`);
      if (detail) assert.match(r.json.detail, detail, what);
      assert.equal(await partCount(), before, `${what}: nothing stored`);
    };
    const clone = () => structuredClone(good);
    const sha = (t) => crypto.createHash('sha256').update(t).digest('hex');

    await refuse(JSON.stringify(good).slice(0, 300), 'bundle', /line 1 column/, 'truncated JSON');
    let x = clone();
    const key = Object.keys(x.terminals)[0];
    delete x.terminals[key];
    await refuse(x, 'parts[0].grammar', new RegExp(`needs terminals\\.${key}`), 'a missing terminal');
    x = clone();
    x.parts[0].grammar = x.parts[0].grammar.replace(/(rule (\w+) size [^{]*\{\n)/, '$1  $2(p)\n');
    await refuse(x, 'parts[0].grammar', /applies itself/, 'a cyclic rule');
    x = clone();
    x.parts[0].root = 'not an identifier';
    await refuse(x, 'parts[0].root', /not an identifier/, 'a root that is not an identifier');
    x = clone();
    x.parts[0].grammar = x.parts[0].grammar.replace(/^rule (\w+) size/m, 'rule 9$1 size');
    await refuse(x, 'parts[0].grammar', null, 'a rule name that is not an identifier');
    // a terminal whose faces name vertices it does not have (hash kept honest)
    x = clone();
    const obj = x.terminals[key].replace(/^f 1 2 3$/m, 'f 1 2 99');
    assert.notEqual(obj, x.terminals[key]);
    delete x.terminals[key];
    x.terminals[sha(obj)] = obj;
    x.parts[0].grammar = x.parts[0].grammar.replace(key, sha(obj));
    await refuse(x, `terminals.${sha(obj)}`, /99/, 'bad face indices');
    x = clone();
    x.terminals[key] = `${x.terminals[key]}# tampered\n`;
    await refuse(x, `terminals.${key}`, /does not match its hash/, 'a tampered terminal');
    x = clone();
    x.format = 'something-else';
    await refuse(x, 'format', null, 'another format');
    x = clone();
    x.parts.push({ ...clone().parts[0], nodes: 'none' });
    await refuse(x, 'parts[1].nodes', null, 'a second part that is bad');
    const empty = await http(d, 'POST', '/api/v1/parts:import', { body: '' });
    assertProblem(empty, 400, 'invalid', 'an empty body');
  });

  it('composes a part as an op over REST and the websocket, previewed, seen by a second client, undone', async () => {
    // the window part as saved from a (version 1): every window of b, each fitted to b's slot
    const ana = await WsClient.open(d.wsUrl);
    const bo = await WsClient.open(d.wsUrl);
    try {
      const v0 = await version(b.id);
      const g0 = await grammar(b.id);
      ana.send({ type: 'hello', model: b.id, user: 'ana' });
      bo.send({ type: 'hello', model: b.id, user: 'bo' });
      await ana.next('welcome');
      await bo.next('welcome');
      const target = b.nodeOf(b.slots[3]);
      const compose = { kind: 'compose', part: window.id, version: 1, target, mode: 'replace', scope: 'rule' };

      // a preview first: the mesh, nothing stored
      let r = await http(d, 'POST', `/api/v1/models/${b.id}/compose-preview`, { body: { op: compose }, headers: { 'If-Match': `"${v0}"` } });
      assert.equal(r.status, 200, r.text);
      assert.equal(r.headers.get('content-type'), 'model/gltf-binary');
      assert.equal(r.headers.get('x-archgram-instances'), String(b.slots.length));
      // the wall and seven pieces per slot, the pieces labelled as the part's
      const preview = parseGlb(r.body).json.nodes.filter((n) => typeof n.extras?.component === 'number');
      assert.equal(preview.length, 1 + 7 * b.slots.length);
      assert.equal(preview.filter((n) => n.extras.label.startsWith('sash_window_')).length, 7 * b.slots.length);
      assert.equal(await version(b.id), v0);
      r = await http(d, 'POST', `/api/v1/models/${b.id}/compose-preview`, { body: { op: compose }, headers: { 'If-Match': `"${v0 + 3}"` } });
      assertProblem(r, 412, 'stale', 'a preview on another version');

      const t0 = await tree(b.id);
      r = await op(b.id, v0, compose);
      assert.equal(r.status, 200, r.text);
      const v1 = r.json.version;
      assert.equal(v1, v0 + 1);
      const seen = await bo.next((m) => m.type === 'op' && m.version === v1, 10000, 'the compose op');
      assert.equal(seen.op.kind, 'compose');
      assert.equal(seen.op.version, 1);
      assert.equal(seen.op.report.instances, b.slots.length);
      assert.equal(seen.op.report.state, 'grafted'); // the part grafted into b's tree
      assert.equal(seen.author, 'ana');
      await ana.next((m) => m.type === 'op' && m.version === v1, 10000, 'the compose op (author)');

      // every slot of b holds the seven pieces of a's window, its jambs 0.08 m wide
      const t1 = await tree(b.id);
      assert.equal(t1.version, v1);
      assert.equal(t1.nodes.filter((n) => n.visible).length, preview.length); // as previewed
      for (const s of b.slots) {
        const p = pieces(t1, s);
        assert.equal(p.length, 7, `slot ${s}`);
        assert.equal(p.filter((n) => Math.abs(n.box[3] - n.box[0] - 0.08) < 1e-6).length, 2, `jambs in ${s}`);
      }
      // the nodes outside the windows keep their ids and boxes
      const inAnySlot = (n) => b.slots.some((sl) => n.box.every((x, i) => (i < 3 ? x >= sl[i] - 1e-6 : x <= sl[i] + 1e-6)));
      const kept = t0.nodes.filter((n) => n.visible && !inAnySlot(n));
      assert.ok(kept.length > 0);
      const byId = new Map(t1.nodes.map((n) => [n.id, n]));
      for (const n of kept) {
        const m = byId.get(n.id);
        assert.ok(m && m.visible, `node ${n.id} stays`);
        assert.ok(m.box.every((x, i) => Math.abs(x - n.box[i]) < 1e-6), `node ${n.id} keeps its box`);
      }
      // the grammar is the composition as made: it keeps b's rules and holds the part's root
      const g1 = await grammar(b.id);
      assert.notEqual(g1, g0);
      assert.match(g1, new RegExp(`rule ${seen.op.report.root_rule} `));

      // over the websocket: the part's newest version into one window slot of b
      const one = pieces(t1, b.slots[0]).sort((p, q) => (q.box[3] - q.box[0]) * (q.box[5] - q.box[2]) - (p.box[3] - p.box[0]) * (p.box[5] - p.box[2]))[0];
      const ack = await ana.request(
        { type: 'op', base: v1, cid: 'c-compose', op: { kind: 'compose', part: window.id, target: one.id, mode: 'replace' } },
        (m) => (m.type === 'ack' || m.type === 'nack') && m.cid === 'c-compose', 20000, 'ack');
      assert.equal(ack.type, 'ack', JSON.stringify(ack));
      const v2 = ack.version;
      const seen2 = await bo.next((m) => m.type === 'op' && m.version === v2, 10000, 'the websocket compose op');
      assert.equal(seen2.op.version, 2); // the newest, named in the log
      assert.equal(seen2.op.report.instances, 1);
      // a bad compose: precise nack, nothing applied
      const nack = await ana.request(
        { type: 'op', base: v2, cid: 'c-bad', op: { kind: 'compose', part: window.id, target: 999999, mode: 'replace' } },
        (m) => (m.type === 'ack' || m.type === 'nack') && m.cid === 'c-bad', 20000, 'nack');
      assert.equal(nack.type, 'nack');
      assert.equal(nack.problem.status, 404);
      assert.match(nack.problem.detail, /target/);
      const nack2 = await ana.request(
        { type: 'op', base: v2, cid: 'c-bad2', op: { kind: 'compose', part: window.id, target: 1, mode: 'sideways' } },
        (m) => (m.type === 'ack' || m.type === 'nack') && m.cid === 'c-bad2', 20000, 'nack');
      assert.equal(nack2.problem.status, 400);
      assert.match(nack2.problem.detail, /mode/);
      assert.equal(await version(b.id), v2);
      // the composed model edits like any other: a resize of the whole building
      r = await op(b.id, v2, { kind: 'resize', node: 'root', scale: [1.2, 1, 1] });
      assert.equal(r.status, 200, r.text);

      // undo all three: the grammar before the first composition, byte for byte
      r = await op(b.id, r.json.version, { kind: 'undo' });
      assert.equal(r.status, 200, r.text);
      r = await op(b.id, r.json.version, { kind: 'undo' });
      assert.equal(r.status, 200, r.text);
      r = await op(b.id, r.json.version, { kind: 'undo' });
      assert.equal(r.status, 200, r.text);
      assert.equal(await grammar(b.id), g0);
      const ops = (await http(d, 'GET', `/api/v1/models/${b.id}/ops?since=${v0}`)).json.items;
      assert.deepEqual(ops.map((o) => o.op.kind), ['compose', 'compose', 'resize', 'restore', 'restore', 'restore']);
      b.version = await version(b.id);
    } finally {
      await ana.close();
      await bo.close();
    }
  });

  it('refuses a composition past its budget, storing nothing', async () => {
    // a blank wall of 240 × 120 m filled with the 1.2 × 1.8 m window: 200 × 67 cells of 84
    // triangles, past the million one op may make
    const wall = await importModel(d, Buffer.from([
      'v 0 0 0', 'v 240 0 0', 'v 240 0.3 0', 'v 0 0.3 0', 'v 0 0 120', 'v 240 0 120', 'v 240 0.3 120', 'v 0 0.3 120',
      'f 1 3 2', 'f 1 4 3', 'f 5 6 7', 'f 5 7 8', 'f 1 2 6', 'f 1 6 5', 'f 4 8 7', 'f 4 7 3', 'f 1 5 8', 'f 1 8 4', 'f 2 3 7', 'f 2 7 6', '',
    ].join('\n')), { name: 'wall', up: 'z' });
    const r0 = await http(d, 'POST', `/api/v1/models/${wall.id}/proceduralize`, {});
    assert.equal((await waitJob(d, r0.json.id, { timeout: 60000 })).status, 'succeeded');
    const t = await tree(wall.id);
    const slab = t.nodes.find((n) => n.visible).id;
    const fill = { kind: 'compose', part: window.id, version: 1, target: slab, mode: 'fill' };
    let r = await http(d, 'POST', `/api/v1/models/${wall.id}/compose-preview`, { body: { op: fill }, headers: { 'If-Match': `"${t.version}"` } });
    assertProblem(r, 413, 'too-large', 'a preview past the budget');
    assert.match(r.json.detail, /1000000 triangles/);
    r = await op(wall.id, t.version, fill);
    assertProblem(r, 413, 'too-large', 'an op past the budget');
    assert.equal(await version(wall.id), t.version);
    assert.equal((await http(d, 'GET', `/api/v1/models/${wall.id}/ops?since=${t.version}`)).json.items.length, 0);
  });

  it('deletes with If-Match, and a part outlives the model it came from', async () => {
    // the model goes; the part stays whole and still composes
    const v = await version(a.id);
    let r = await http(d, 'DELETE', `/api/v1/models/${a.id}`, { headers: { 'If-Match': `"${v}"` } });
    assert.equal(r.status, 204, r.text);
    r = await http(d, 'GET', `/api/v1/parts/${window.id}`);
    assert.equal(r.status, 200);
    assert.equal(r.json.versions.at(-1).source.model, a.id);
    assert.equal((await http(d, 'GET', `/api/v1/parts/${window.id}/bundle?version=1`)).status, 200);
    assert.equal((await http(d, 'GET', `/api/v1/parts/${window.id}/mesh.glb?version=1`)).status, 200);
    const target = b.nodeOf(b.slots[1]);
    r = await op(b.id, b.version, { kind: 'compose', part: window.id, version: 1, target, mode: 'replace' });
    assert.equal(r.status, 200, r.text);

    const url = `/api/v1/parts/${window.id}`;
    r = await http(d, 'DELETE', url);
    assertProblem(r, 428, 'precondition-required', 'no If-Match');
    r = await http(d, 'DELETE', url, { headers: { 'If-Match': '"1"' } });
    assertProblem(r, 412, 'stale', 'an old version');
    r = await http(d, 'DELETE', url, { headers: { 'If-Match': '"2"' } });
    assert.equal(r.status, 204, r.text);
    assertProblem(await http(d, 'GET', url), 404, 'not-found', 'gone');
    assertProblem(await http(d, 'GET', `${url}/thumbnail.png`), 404, 'not-found', 'its thumbnail');
    // the composed model keeps what it composed
    assert.equal((await http(d, 'GET', `/api/v1/models/${b.id}/mesh.glb`)).status, 200);
  });
});
