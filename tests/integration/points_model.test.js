// Point clouds proceduralized and edited in the service, as meshes are: the proceduralize job on
// a pointcloud model (progress by stage, a template's copies found, bad options refused), GET
// …/tree and …/grammar, GET …/derived.ply (the cloud the grammar derives), PUT …/grammar, resize
// and paste ops over REST and the websocket (live drag previews, broadcast, logged with their
// report, undone and redone by their author, rebased or nacked when made on an older version),
// with the density kept. The checks are the test's own: windows are counted and densities
// measured on the derived points (points_building.js), never taken from archgram's report.
import assert from 'node:assert/strict';
import { after, before, describe, it } from 'node:test';
import { assertProblem, http, importModel, PROBLEM, removeDir, sql, startDaemon, waitJob, WsClient, facadeObj } from './harness.js';
import { absolutePly, buildingPly, countWindows, frontsOf, glassOf, ORIGIN, windowBox } from './points_building.js';

const absolute = absolutePly;

// Points per m² of the front wall (the plane y = 0 between the windows) and of the windows'
// glass (0.25 m behind it), measured on a cloud of a front `width` m wide with `windows` windows.
function densities(c, width, windows) {
  let wall = 0, glass = 0;
  for (let i = 0; i < c.n; i++) {
    const x = c.props.x[i] - ORIGIN[0], y = c.props.y[i] - ORIGIN[1], z = c.props.z[i] - ORIGIN[2];
    if (x < 0.05 || x > width - 0.05 || z < 0.05 || z > 6.95) continue;
    if (Math.abs(y) < 0.02) wall++;
    else if (Math.abs(y - 0.25) < 0.02) glass++;
  }
  const wallArea = (width - 0.1) * 6.9 - windows * 1.2 * 1.5;
  return { wall: wall / wallArea, glass: glass / (windows * 1.2 * 1.5) };
}

const near = (a, b, eps = 1e-6) => a.every((v, i) => Math.abs(v - b[i]) <= eps);

const within = (a, b, rel, what) => assert.ok(Math.abs(a / b - 1) <= rel, `${what}: ${a.toFixed(1)} against ${b.toFixed(1)} per m²`);
const box6 = (s) => s.split(',').map(Number);

describe('point models in the service', () => {
  let d;
  let id;
  let mesh;
  const input = buildingPly(60000);
  before(async () => {
    d = await startDaemon();
  });
  after(async () => {
    if (d) { try { await d.stop(); } finally { await d.kill(); removeDir(d.dir); } }
  });

  const state = async () => ({
    version: (await http(d, 'GET', `/api/v1/models/${id}`)).json.version,
    ops: (await http(d, 'GET', `/api/v1/models/${id}/ops`)).json.items.length,
    grammar: (await http(d, 'GET', `/api/v1/models/${id}/grammar`)).text,
    rows: sql(d.db, `SELECT (SELECT count(*) FROM model_states WHERE model_id = ${id}), (SELECT count(*) FROM grammars WHERE model_id = ${id}), (SELECT count(*) FROM terminals WHERE model_id = ${id}), (SELECT count(*) FROM blobs)`),
  });
  const derived = async () => {
    const r = await http(d, 'GET', `/api/v1/models/${id}/derived.ply`, { timeout: 60000 });
    assert.equal(r.status, 200, r.text.slice(0, 300));
    assert.equal(r.headers.get('content-type'), 'application/x-ply');
    return absolute(r.body);
  };

  it('a cloud that is not proceduralized has no tree, grammar or derived cloud, and refuses edits', async () => {
    const q = new URLSearchParams({ name: 'house', format: 'ply' });
    const up = await http(d, 'POST', `/api/v1/models?${q}`, { body: input.bytes, headers: { 'Content-Type': 'application/octet-stream' }, timeout: 120000 });
    assert.equal(up.status, 202, up.text);
    const job = await waitJob(d, up.json.id, { timeout: 120000 });
    assert.equal(job.status, 'succeeded', JSON.stringify(job.error));
    id = job.result.model;
    assertProblem(await http(d, 'GET', `/api/v1/models/${id}/tree`), 404, 'not-found', 'tree');
    assertProblem(await http(d, 'GET', `/api/v1/models/${id}/grammar`), 404, 'not-found', 'grammar');
    assertProblem(await http(d, 'GET', `/api/v1/models/${id}/derived.ply`), 409, 'not-proceduralized', 'derived.ply');
    const v = (await http(d, 'GET', `/api/v1/models/${id}`)).json.version;
    const r = await http(d, 'POST', `/api/v1/models/${id}/ops`, { body: { op: { kind: 'resize', node: 'root', scale: [2, 1, 1] } }, headers: { 'If-Match': `"${v}"` } });
    assertProblem(r, 409, 'not-proceduralized', 'resize a cloud');
    assert.match(r.json.detail, /not proceduralized/);
  });

  it('bad proceduralize options are refused before a job is queued', async () => {
    mesh = await importModel(d, facadeObj(3, 2), { name: 'a mesh' });
    const bad = async (model, body, detail) => {
      const r = await http(d, 'POST', `/api/v1/models/${model}/proceduralize`, { body });
      assertProblem(r, 400, 'invalid', JSON.stringify(body));
      assert.match(r.json.detail, detail);
    };
    await bad(id, { templates: [[1, 2, 3]] }, /templates\[0\]: a box/);
    await bad(id, { templates: [[0, 0, 0, 1, 1, 'x']] }, /templates\[0\]\[5\] is not a finite number/);
    await bad(id, { rois: [[0, 0, 2, 1, 1, 1]] }, /rois\[0\]: its minimum 2 lies above its maximum 1 on axis z/);
    await bad(id, { templates: Array(65).fill([0, 0, 0, 1, 1, 1]) }, /at most 64/);
    await bad(id, { auto: 'no' }, /"auto" takes true or false/);
    await bad(id, { colour: 1 }, /"colour" is not an option of proceduralize/);
    await bad(id, { exact: true }, /"exact": model \d+ is a point cloud/);
    await bad(mesh.id, { templates: [[0, 0, 0, 1, 1, 1]] }, /is a mesh; templates, rois and auto are options of point clouds/);
    await bad(mesh.id, { colour: 1 }, /"colour" is not an option of proceduralize/);
    assert.equal((await http(d, 'GET', `/api/v1/models/${id}`)).json.version, 1);
    // a template in the air passes the request's checks and fails the job, storing nothing
    const air = [ORIGIN[0] + 4, ORIGIN[1] + 3, ORIGIN[2] + 30, ORIGIN[0] + 5, ORIGIN[1] + 4, ORIGIN[2] + 31];
    const r = await http(d, 'POST', `/api/v1/models/${id}/proceduralize`, { body: { templates: [air] } });
    assert.equal(r.status, 202, r.text);
    const job = await waitJob(d, r.json.id, { timeout: 120000 });
    assert.equal(job.status, 'failed', JSON.stringify(job));
    assert.match(job.error.detail, /template/, JSON.stringify(job.error));
    assert.equal((await http(d, 'GET', `/api/v1/models/${id}`)).json.version, 1);
    assertProblem(await http(d, 'GET', `/api/v1/models/${id}/tree`), 404, 'not-found', 'tree after a failed job');
    assert.deepEqual(sql(d.db, `SELECT count(*) FROM grammars WHERE model_id = ${id}`), [['0']]);
    assert.deepEqual(sql(d.db, `SELECT count(*) FROM terminals WHERE model_id = ${id}`), [['0']]);
  });

  it('the proceduralize job finds the template\'s copies and stores tree, grammar and terminals', async () => {
    const W = await WsClient.open(d.wsUrl);
    try {
      const r = await http(d, 'POST', `/api/v1/models/${id}/proceduralize`, { body: { templates: [box6(windowBox(2))], auto: false } });
      assert.equal(r.status, 202, r.text);
      W.send({ type: 'watch', job: r.json.id });
      const done = await W.next((m) => m.type === 'job.done' && m.job === r.json.id, 120000, 'job.done');
      assert.equal(done.status, 'succeeded', JSON.stringify(done));
      assert.deepEqual(Object.keys(done.result).sort(), ['grammar', 'href', 'model', 'tree', 'version']);
      assert.equal(done.result.version, 2);
      const stages = new Set(['start', 'segment', 'repeat', 'absorb', 'consensus', 'tree', 'grammar', 'verify']);
      let last = 0;
      const progress = W.all.filter((m) => m.type === 'job.progress' && m.job === r.json.id);
      for (const p of progress) {
        assert.ok(p.progress >= last && p.progress <= 1, JSON.stringify(p));
        if (p.stage) assert.ok(stages.has(p.stage), `stage ${p.stage}`);
        last = p.progress;
      }
      console.log(`# proceduralize job: ${progress.length} job.progress messages, stages ${[...new Set(progress.map((p) => p.stage))].join(', ')}`);
    } finally {
      await W.close();
    }
    const m = (await http(d, 'GET', `/api/v1/models/${id}`)).json;
    assert.equal(m.proceduralized, true);
    assert.equal(m.stats.points, 60000); // the cloud's figures stay
    const t = (await http(d, 'GET', `/api/v1/models/${id}/tree`)).json;
    assert.equal(t.version, 2);
    assert.equal(t.summary.kind, 'pointcloud');
    for (const s of ['segment', 'repeat', 'absorb', 'consensus', 'tree', 'grammar', 'verify', 'total']) assert.equal(typeof t.summary.seconds[s], 'number', s);
    assert.equal(t.summary.repetition.templates[0].matches, 10, JSON.stringify(t.summary.repetition));
    assert.ok(t.summary.completion.some((c) => c.members === 10), JSON.stringify(t.summary.completion));
    assert.ok(t.summary.fidelity.coverage >= 0.97, JSON.stringify(t.summary.fidelity));
    // the tree's boxes are in the cloud's coordinates: the root holds the building
    const root = t.nodes[t.root];
    assert.ok(Math.abs(root.box[0] - ORIGIN[0]) < 0.1 && Math.abs(root.box[3] - ORIGIN[0] - 16) < 0.1, JSON.stringify(root.box));
    // the grammar names PLY terminals; the log has the proceduralization
    const g = await http(d, 'GET', `/api/v1/models/${id}/grammar`);
    assert.equal(g.status, 200);
    assert.ok([...g.text.matchAll(/"terminals\/[0-9a-f]{16}\.ply"/g)].length >= 5, g.text.slice(0, 400));
    const log = (await http(d, 'GET', `/api/v1/models/${id}/ops`)).json.items;
    assert.equal(log.at(-1).op.kind, 'proceduralize');
    assert.equal(log.at(-1).op.input, 'pointcloud');
    // the derived cloud: the input's windows, at its density
    const c = await derived();
    assert.ok(c.n > 55000 && c.n < 66000, String(c.n));
    assert.ok('label' in c.props && 'segment' in c.props);
    assert.equal(countWindows(c), 10);
    const i = absolute(input.bytes), a = densities(i, 16, 10), b = densities(c, 16, 10);
    within(b.wall, a.wall, 0.1, 'the front wall derived');
    within(b.glass, a.glass, 0.1, 'the glass derived');
    // an ETag that names the state
    const again = await http(d, 'GET', `/api/v1/models/${id}/derived.ply`, { headers: { 'If-None-Match': (await http(d, 'GET', `/api/v1/models/${id}/derived.ply`)).headers.get('etag') } });
    assert.equal(again.status, 304);
    // a budget: every k-th point of the derivation, k the least that keeps within it
    const some = await http(d, 'GET', `/api/v1/models/${id}/derived.ply?budget=1000`, { timeout: 60000 });
    assert.equal(some.status, 200, some.text.slice(0, 300));
    const s = absolute(some.body), k = Math.ceil(c.n / 1000);
    assert.equal(s.n, Math.ceil(c.n / k));
    assert.ok(s.n <= 1000);
    for (let i = 0; i < s.n; i++) assert.ok(s.props.x[i] === c.props.x[i * k] && s.props.segment[i] === c.props.segment[i * k], `point ${i}`);
    assert.notEqual(some.headers.get('etag'), again.headers.get('etag'));
    assert.equal((await http(d, 'GET', `/api/v1/models/${id}/derived.ply?budget=0`, { timeout: 60000 })).body.length, (await http(d, 'GET', `/api/v1/models/${id}/derived.ply`, { timeout: 60000 })).body.length);
    assertProblem(await http(d, 'GET', `/api/v1/models/${id}/derived.ply?budget=-1`), 400, 'invalid', 'a negative budget');
  });

  it('PUT grammar of a point model re-derives it; bad text is refused and nothing changes', async () => {
    const g = await http(d, 'GET', `/api/v1/models/${id}/grammar`);
    const v = (await http(d, 'GET', `/api/v1/models/${id}`)).json.version;
    const tree0 = (await http(d, 'GET', `/api/v1/models/${id}/tree`)).json;
    const n0 = (await derived()).n;
    const r = await http(d, 'PUT', `/api/v1/models/${id}/grammar`, { body: g.text, headers: { 'If-Match': `"${v}"`, 'Content-Type': 'text/plain' } });
    assert.equal(r.status, 200, r.text);
    assert.equal(r.json.version, v + 1);
    assert.equal((await http(d, 'GET', `/api/v1/models/${id}/grammar`)).text, g.text);
    assert.deepEqual((await http(d, 'GET', `/api/v1/models/${id}/tree`)).json.nodes, tree0.nodes);
    assert.equal((await derived()).n, n0);
    const log = (await http(d, 'GET', `/api/v1/models/${id}/ops`)).json.items.at(-1);
    assert.deepEqual(log.op, { kind: 'grammar', bytes: Buffer.byteLength(g.text) });
    const before = await state();
    const lines = g.text.split('\n');
    const at = lines.findIndex((l) => l.startsWith('terminal '));
    const broken = [...lines];
    broken[at] = broken[at].replace(' size ', ' size , ');
    const p = await http(d, 'PUT', `/api/v1/models/${id}/grammar`, { body: broken.join('\n'), headers: { 'If-Match': `"${v + 1}"` } });
    assertProblem(p, 422, 'parse', 'a syntax error');
    assert.equal(p.json.line, at + 1);
    const t = await http(d, 'PUT', `/api/v1/models/${id}/grammar`, { body: g.text.replace(/terminals\/[0-9a-f]{16}\.ply/, 'terminals/0123456789abcdef.ply'), headers: { 'If-Match': `"${v + 1}"` } });
    assertProblem(t, 422, 'parse', 'a terminal the model does not keep');
    assert.match(t.json.detail, /terminals\/0123456789abcdef\.ply/);
    const mesh = await http(d, 'PUT', `/api/v1/models/${id}/grammar`, { body: g.text.replace(/(terminals\/[0-9a-f]{16})\.ply/g, '$1.obj'), headers: { 'If-Match': `"${v + 1}"` } });
    assertProblem(mesh, 422, 'parse', 'mesh terminals on a point model');
    assert.deepEqual(await state(), before);
  });

  it('a resize doubling the front doubles its windows at the input density; undo and redo over the websocket', async () => {
    const t = (await http(d, 'GET', `/api/v1/models/${id}/tree`)).json;
    const front = frontsOf(t)[0];
    assert.ok(front, 'a front wall node');
    const box = [...front.box];
    box[3] = box[0] + 2 * (box[3] - box[0]);
    const before = await state();
    const c0 = await derived();
    const A = await WsClient.open(d.wsUrl), B = await WsClient.open(d.wsUrl);
    try {
      await A.request({ type: 'hello', model: id, user: 'ana' }, 'welcome');
      await B.request({ type: 'hello', model: id, user: 'bo' }, 'welcome');
      let version = before.version;
      const send = async (cid, op) => {
        const seen = B.next((m) => m.type === 'op' && m.cid === cid, 120000, `${cid} at the other client`);
        const reply = await A.request({ type: 'op', base: version, cid, op }, (m) => (m.type === 'ack' || m.type === 'nack') && m.cid === cid, 120000);
        assert.equal(reply.type, 'ack', JSON.stringify(reply));
        const other = await seen;
        assert.equal(other.version, reply.version);
        version = reply.version;
        return other;
      };
      // a live drag: the solved boxes reach the other client, in the cloud's coordinates
      const shown = B.next((m) => m.type === 'preview', 60000, 'the preview at the other client');
      A.send({ type: 'preview', model: id, base: version, op: { kind: 'resize', node: front.id, box } });
      const pv = await shown;
      assert.equal(pv.author, 'ana');
      const moved = pv.boxes.find((b) => b.node === front.id);
      assert.ok(moved && Math.abs(moved.box[3] - box[3]) < 0.05, JSON.stringify(pv.boxes.slice(0, 5)));
      assert.ok(pv.boxes.length > 1, 'the neighbours move with it');
      const stale = await A.request({ type: 'preview', model: id, base: version - 1, op: { kind: 'resize', node: front.id, box } }, (m) => m.type === 'preview.error', 60000);
      assert.equal(stale.version, version);
      A.send({ type: 'preview.end' });
      const r = await send('wide-1', { kind: 'resize', node: front.id, box });
      assert.equal(r.op.kind, 'resize');
      assert.ok(r.op.report.equations > 0 && r.op.report.placements > 80, JSON.stringify(r.op.report));
      const w = await derived();
      assert.equal(countWindows(w), 20);
      const a = densities(absolute(input.bytes), 16, 10), b = densities(w, 32, 20);
      within(b.wall, a.wall, 0.1, 'the doubled front wall');
      within(b.glass, a.glass, 0.1, 'the doubled windows\' glass');
      console.log(`# doubled front: ${countWindows(w)} windows; wall ${b.wall.toFixed(1)} points/m² (input ${a.wall.toFixed(1)}), glass ${b.glass.toFixed(1)} (input ${a.glass.toFixed(1)}); ${w.n} points derived`);
      let far = 0;
      for (let i = 0; i < w.n; i++) far += w.props.x[i] - ORIGIN[0] > 32.5;
      assert.ok(far < 0.01 * w.n, `${far} points past x = 32.5`);
      const wideTree = (await http(d, 'GET', `/api/v1/models/${id}/tree`)).json;
      assert.equal(wideTree.version, version);
      assert.ok(Math.abs(wideTree.nodes[wideTree.root].box[3] - ORIGIN[0] - 32) < 0.1, JSON.stringify(wideTree.nodes[wideTree.root].box));
      const wideGrammar = (await http(d, 'GET', `/api/v1/models/${id}/grammar`)).text;
      // bo has nothing of his own to undo; ana's undo brings the model back exactly
      const bo = await B.request({ type: 'op', base: version, cid: 'bo-undo', op: { kind: 'undo' } }, (m) => m.cid === 'bo-undo', 60000);
      assert.equal(bo.type, 'nack');
      assert.equal(bo.problem.type, `${PROBLEM}undo-conflict`);
      const u = await send('undo-1', { kind: 'undo' });
      assert.equal(u.op.kind, 'restore');
      assert.equal((await http(d, 'GET', `/api/v1/models/${id}/grammar`)).text, before.grammar);
      const back = await derived();
      assert.equal(back.n, c0.n);
      assert.deepEqual(back.props.x, c0.props.x);
      assert.equal(countWindows(back), 10);
      assert.deepEqual((await http(d, 'GET', `/api/v1/models/${id}/tree`)).json.nodes, t.nodes);
      await send('redo-1', { kind: 'redo' });
      assert.equal((await http(d, 'GET', `/api/v1/models/${id}/grammar`)).text, wideGrammar);
      assert.equal(countWindows(await derived()), 20);
      await send('undo-2', { kind: 'undo' });
      assert.equal((await http(d, 'GET', `/api/v1/models/${id}/grammar`)).text, before.grammar);
    } finally {
      await A.close();
      await B.close();
    }
    // the log: the resize with its report, the undo and redo as restores
    const log = (await http(d, 'GET', `/api/v1/models/${id}/ops`)).json.items.slice(-4);
    assert.deepEqual(log.map((e) => [e.op.kind, e.author]), [['resize', 'ana'], ['restore', 'ana'], ['restore', 'ana'], ['restore', 'ana']]);
    assert.ok(log[0].op.report.unknowns > 0);
  });

  it('live resizes made on an older version: rebased when nothing since changed their node, else nacked naming the op', async () => {
    const A = await WsClient.open(d.wsUrl), B = await WsClient.open(d.wsUrl);
    try {
      const wel = await A.request({ type: 'hello', model: id, user: 'cy' }, 'welcome');
      await B.request({ type: 'hello', model: id, user: 'di' }, 'welcome');
      const t = (await http(d, 'GET', `/api/v1/models/${id}/tree`)).json;
      assert.equal(t.version, wel.version);
      const wa = glassOf(t, 5), wb = glassOf(t, 7);
      assert.ok(wa && wb, 'window nodes');
      // the back wall: the node spanning the building at y = 8
      const back = t.nodes.find((nd) => nd.kind === 'component' && nd.box[3] - nd.box[0] > 14 && nd.box[5] - nd.box[2] > 6 &&
        Math.abs(nd.box[4] - ORIGIN[1] - 8) < 0.2 && nd.box[4] - nd.box[1] < 0.6);
      assert.ok(back, 'the back wall');
      const grow = (w) => ({ kind: 'resize', node: w.id, box: [w.box[0], w.box[1], w.box[2], w.box[3] + 0.1, w.box[4], w.box[5] + 0.1] });
      const reply = (cid) => (m) => (m.type === 'ack' || m.type === 'nack') && m.cid === cid;
      const rb = await B.request({ type: 'op', cid: 'di-1', base: t.version, op: grow(wb) }, reply('di-1'), 60000);
      assert.equal(rb.type, 'ack', JSON.stringify(rb));
      const now = (await http(d, 'GET', `/api/v1/models/${id}/tree`)).json;
      // the windows share a rule: b's resize resized a too, so a's op made before it is stale
      const wa2 = glassOf(now, 5);
      assert.ok(wa2 && near(wa2.box, grow(wa).box, 1e-3), `window a went with window b: ${JSON.stringify(wa2?.box)}`);
      const ra = await A.request({ type: 'op', cid: 'cy-1', base: t.version, op: grow(wa) }, reply('cy-1'), 60000);
      assert.equal(ra.type, 'nack', JSON.stringify(ra));
      assert.equal(ra.problem.type, `${PROBLEM}stale`);
      assert.equal(ra.version, rb.version);
      assert.match(ra.problem.detail, new RegExp(`the resize op of version ${rb.version} by di changed node ${wa.id}`));
      // the back wall is not changed by it: the same op is rebased onto the current version
      const taller = [...back.box.slice(0, 5), back.box[5] + 0.5];
      const rc = await A.request({ type: 'op', cid: 'cy-2', base: t.version, op: { kind: 'resize', node: back.id, box: taller } }, reply('cy-2'), 60000);
      assert.equal(rc.type, 'ack', JSON.stringify(rc));
      assert.equal(rc.version, rb.version + 1);
      const last = (await http(d, 'GET', `/api/v1/models/${id}/tree`)).json;
      assert.ok(last.nodes.some((n) => n.kind === 'component' && near(n.box, taller, 1e-3)), 'the back wall has its new box');
      assert.equal(countWindows(await derived()), 10);
      // bo's undo would reach over cy's op: refused; a restore of the version before both is not
      const v = (await http(d, 'GET', `/api/v1/models/${id}`)).json.version;
      const ru = await B.request({ type: 'op', cid: 'di-undo', base: v, op: { kind: 'undo' } }, reply('di-undo'), 60000);
      assert.equal(ru.type, 'nack', JSON.stringify(ru));
      assert.equal(ru.problem.type, `${PROBLEM}undo-conflict`);
      const rr = await B.request({ type: 'op', cid: 'di-restore', base: v, op: { kind: 'restore', version: t.version } }, reply('di-restore'), 60000);
      assert.equal(rr.type, 'ack', JSON.stringify(rr));
      assert.deepEqual((await http(d, 'GET', `/api/v1/models/${id}/tree`)).json.nodes, t.nodes);
    } finally {
      await A.close();
      await B.close();
    }
  });

  it('a paste over REST copies another model\'s window onto a window; bad ops get problems and store nothing', async () => {
    // a second point model to paste into: the same building, proceduralized automatically
    const q = new URLSearchParams({ name: 'house 2', format: 'ply' });
    const up = await waitJob(d, (await http(d, 'POST', `/api/v1/models?${q}`, { body: input.bytes, headers: { 'Content-Type': 'application/octet-stream' }, timeout: 120000 })).json.id, { timeout: 120000 });
    const other = up.result.model;
    const pj = await waitJob(d, (await http(d, 'POST', `/api/v1/models/${other}/proceduralize`, { body: {} })).json.id, { timeout: 120000 });
    assert.equal(pj.status, 'succeeded', JSON.stringify(pj.error));
    const t = (await http(d, 'GET', `/api/v1/models/${id}/tree`)).json;
    // a window of model id (window 0) pasted over window 1
    const src = glassOf(t, 0), dst = glassOf(t, 1);
    assert.ok(src && dst, 'window nodes');
    const before = await state();
    const post = (op, headers = { 'If-Match': `"${before.version}"` }) => http(d, 'POST', `/api/v1/models/${id}/ops`, { body: { op }, headers, timeout: 60000 });
    // refused, naming what is wrong, and nothing is stored
    assertProblem(await post({ kind: 'resize', node: 99999, scale: [2, 1, 1] }), 404, 'not-found', 'an unknown node');
    let r = await post({ kind: 'resize', node: src.id, box: [0, 0, 0, -1, 1, 1] });
    assertProblem(r, 400, 'invalid', 'a box upside down');
    r = await post({ kind: 'paste', source: [src.id], target: dst.id, source_model: mesh.id });
    assertProblem(r, 409, 'conflict', 'a paste from a mesh');
    assert.match(r.json.detail, /source_model: model \d+ is not a point cloud/);
    r = await post({ kind: 'paste', source: [src.id], target: dst.id, source_model: 987654 });
    assertProblem(r, 404, 'not-found', 'a paste from nowhere');
    assert.match(r.json.detail, /source_model: there is no model 987654/);
    r = await post({ kind: 'paste', source: [src.id], target: dst.id, source_dir: '../x' });
    assertProblem(r, 400, 'invalid', 'a folder');
    assertProblem(await post({ kind: 'resize', node: src.id, scale: [2, 1, 1] }, { 'If-Match': '"1"' }), 412, null, 'a stale version');
    // parts are saved from meshes and composed into meshes
    r = await http(d, 'POST', '/api/v1/parts', { body: { model: id, version: before.version, node: src.id, name: 'a window' } });
    assertProblem(r, 409, 'conflict', 'a part of a point model');
    assert.match(r.json.detail, /is a point cloud/);
    assertProblem(await http(d, 'GET', `/api/v1/models/${id}/selection?nodes=${src.id}`), 409, 'conflict', 'a selection of a point model');
    assert.deepEqual(await state(), before);
    assert.deepEqual(sql(d.db, 'PRAGMA integrity_check'), [['ok']]);
    // a paste from the other model: its window onto this one's
    const ot = (await http(d, 'GET', `/api/v1/models/${other}/tree`)).json;
    const osrc = glassOf(ot, 0);
    assert.ok(osrc, 'a window node of the other model');
    r = await post({ kind: 'paste', source: [osrc.id], target: dst.id, source_model: other, placement: 'replace' });
    assert.equal(r.status, 200, r.text);
    const log = (await http(d, 'GET', `/api/v1/models/${id}/ops`)).json.items.at(-1);
    assert.equal(log.op.kind, 'paste');
    assert.equal(log.op.report.source_version, 2);
    const c = await derived();
    assert.equal(countWindows(c), 10);
    const a = densities(absolute(input.bytes), 16, 10), b = densities(c, 16, 10);
    within(b.glass, a.glass, 0.1, 'the glass after the paste');
  });
});
