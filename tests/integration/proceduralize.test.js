// Proceduralization as a service: POST …/proceduralize (a job with stages), GET …/tree and
// …/grammar, PUT …/grammar (re-derive, 422 with line/column, preconditions), mesh.glb extras,
// live ops in the room, stale and cancelled jobs, and a deleted model leaving nothing behind.
import assert from 'node:assert/strict';
import fs from 'node:fs';
import path from 'node:path';
import { after, before, describe, it } from 'node:test';
import {
  assertProblem, http, importModel, parseGlb, removeDir, sql, startDaemon, upload, waitJob,
  writeGridObj, WsClient,
  facadeObj as sharedFacadeObj,
} from './harness.js';

const facadeObj = (cols, rows) => Buffer.from(sharedFacadeObj(cols, rows));

const STAGES = ['segment', 'label', 'tree', 'rules', 'patterns', 'export', 'verify'];

describe('proceduralization over REST and websockets', () => {
  let d;
  let model; // the facade
  let other; // never proceduralized
  let W; // a websocket client in the facade's room
  let bigFile;
  let dir;
  const clients = [];

  const getModel = async (id = model.id) => {
    const r = await http(d, 'GET', `/api/v1/models/${id}`);
    assert.equal(r.status, 200, r.text);
    return r.json;
  };
  // A long import occupies the only worker, so the next job waits in the queue.
  const occupyWorker = async () => {
    const job = await upload(d, fs.readFileSync(bigFile), { name: 'blocker' });
    const t0 = Date.now();
    for (;;) {
      const j = (await http(d, 'GET', `/api/v1/jobs/${job.id}`)).json;
      if (j.status === 'running') return job.id;
      assert.ok(j.status === 'queued' && Date.now() - t0 < 30000, `blocker job: ${JSON.stringify(j)}`);
      await new Promise((r) => setTimeout(r, 10));
    }
  };
  const release = async (blocker) => {
    const del = await http(d, 'DELETE', `/api/v1/jobs/${blocker}`);
    assert.equal(del.status, 200, del.text);
    const done = await waitJob(d, blocker);
    assert.equal(done.status, 'cancelled', `the blocker finished before it was released: ${JSON.stringify(done)}`);
  };
  const proceduralize = async (id, headers = {}) => {
    const r = await http(d, 'POST', `/api/v1/models/${id}/proceduralize`, { headers });
    return r;
  };

  before(async () => {
    d = await startDaemon({ args: ['--workers', '1', '--no-web'] });
    dir = d.dir;
    bigFile = path.join(d.dir, 'big.obj');
    writeGridObj(bigFile, 40e6);
    model = await importModel(d, facadeObj(), { name: 'facade' });
    other = await importModel(d, facadeObj(2, 1), { name: 'plain' });
    W = await WsClient.open(d.wsUrl);
    clients.push(W);
    const welcome = await W.request({ type: 'hello', model: model.id, user: 'watcher' }, 'welcome');
    assert.equal(welcome.version, model.version);
  });
  after(async () => {
    for (const c of clients) await c.close().catch(() => {});
    try {
      if (d) { try { await d.stop(); } finally { await d.kill(); } }
    } finally {
      removeDir(dir);
    }
  });

  it('a model never proceduralized has no tree and no grammar (404 problems)', async () => {
    assert.equal(model.proceduralized, false);
    for (const what of ['tree', 'grammar']) {
      const r = await http(d, 'GET', `/api/v1/models/${other.id}/${what}`);
      assertProblem(r, 404, 'not-found', `GET ${what}`);
      assert.equal(r.json.detail, `model ${other.id} has not been proceduralized`);
    }
    assertProblem(await http(d, 'GET', '/api/v1/models/999999/tree'), 404, 'not-found');
    assertProblem(await proceduralize(999999), 404, 'not-found');
    const list = (await http(d, 'GET', '/api/v1/models')).json.items;
    assert.ok(list.every((m) => m.proceduralized === false), JSON.stringify(list));
  });

  it('POST proceduralize: 202 job that runs through every stage and replaces the mesh', async () => {
    const blocker = await occupyWorker();
    const r = await proceduralize(model.id, { 'X-Archgram-User': 'ana' });
    assert.equal(r.status, 202, r.text);
    assert.equal(r.json.kind, 'proceduralize');
    assert.equal(r.json.status, 'queued');
    assert.equal(r.headers.get('location'), `/api/v1/jobs/${r.json.id}`);
    const J = await WsClient.open(d.wsUrl);
    clients.push(J);
    J.send({ type: 'watch', job: r.json.id });
    await new Promise((res) => setTimeout(res, 100)); // the watch is registered before it runs
    await release(blocker);
    const done = await J.next((m) => m.type === 'job.done' && m.job === r.json.id, 30000, 'job.done');
    assert.equal(done.status, 'succeeded', JSON.stringify(done));
    const progress = J.all.filter((m) => m.type === 'job.progress' && m.job === r.json.id);
    const stages = progress.map((m) => m.stage).filter((s, i, a) => STAGES.includes(s) && a.indexOf(s) === i);
    assert.deepEqual(stages, STAGES, `stages seen: ${JSON.stringify(progress)}`);
    for (let i = 1; i < progress.length; i++) assert.ok(progress[i].progress >= progress[i - 1].progress);
    assert.ok(progress.every((m) => m.progress >= 0 && m.progress <= 1));

    const job = await waitJob(d, r.json.id);
    assert.deepEqual(job.result, {
      model: model.id, version: model.version + 1, href: `/api/v1/models/${model.id}`,
      tree: `/api/v1/models/${model.id}/tree`, grammar: `/api/v1/models/${model.id}/grammar`,
    });
    const m = await getModel();
    assert.equal(m.version, model.version + 1);
    assert.equal(m.proceduralized, true);
    assert.equal(m.stats.triangles, model.stats.triangles, 'the derived mesh has every input triangle');
    assert.equal(m.stats.components, 25);
    assert.deepEqual(m.stats.group_names.sort(), ['L1', 'L2']);
    // the room got the op, authored by the caller
    const op = await W.next((x) => x.type === 'op' && x.version === m.version, 5000, 'proceduralize op');
    assert.equal(op.author, 'ana');
    assert.deepEqual(op.op, { kind: 'proceduralize', rules: 1, terminals: 2, patterns: 1 });
    const log = (await http(d, 'GET', `/api/v1/models/${model.id}/ops`)).json.items;
    assert.deepEqual(log.at(-1).op, op.op);
    model = m;
  });

  it('GET tree: a 6 × 4 pattern of one rule, visible nodes naming the mesh components', async () => {
    const r = await http(d, 'GET', `/api/v1/models/${model.id}/tree`);
    assert.equal(r.status, 200, r.text);
    assert.equal(r.headers.get('etag'), `"${model.version}"`);
    const t = r.json;
    assert.equal(t.model, model.id);
    assert.equal(t.version, model.version);
    assert.equal(t.root, 0);
    assert.equal(t.nodes[0].kind, 'root');
    assert.equal(t.nodes[0].parent, null);
    t.nodes.forEach((n, i) => {
      assert.equal(n.id, i);
      // a removed node (cells moved under the pattern) is served as its id alone
      if (n.kind === 'dead') return assert.deepEqual(n, { id: i, kind: 'dead' });
      assert.equal(n.box.length, 6);
      for (const c of n.children) assert.equal(t.nodes[c].parent, n.id);
      assert.equal(n.visible, n.kind === 'component');
    });
    const patterns = t.nodes.filter((n) => n.kind === 'pattern');
    assert.equal(patterns.length, 1, JSON.stringify(patterns));
    const p = patterns[0];
    assert.deepEqual([...p.pattern.counts].sort((a, b) => a - b), [1, 4, 6]);
    assert.equal(p.pattern.step.length, 3);
    assert.equal(p.children.length, 24);
    const cells = p.children.map((c) => t.nodes[c]);
    assert.ok(cells.every((c) => c.kind === 'component' && c.rule === p.rule && c.label === cells[0].label));
    const visible = t.nodes.filter((n) => n.visible);
    assert.deepEqual(visible.map((n) => n.component).sort((a, b) => a - b), [...Array(25).keys()]);
    assert.deepEqual(t.labels.map((l) => l.count).sort((a, b) => a - b), [1, 24]);
    assert.ok(t.labels.every((l) => /^#[0-9a-f]{6}$/.test(l.color)));
    assert.deepEqual(t.rules, [{ name: p.rule, instances: 24 }]);
    assert.equal(t.summary.patterns[0].instances, 24);
    assert.equal(t.summary.fidelity.unmatched, 0);
  });

  it('mesh.glb extras carry each component\'s label and tree node', async () => {
    const [glbRes, treeRes] = await Promise.all([
      http(d, 'GET', `/api/v1/models/${model.id}/mesh.glb`),
      http(d, 'GET', `/api/v1/models/${model.id}/tree`),
    ]);
    assert.equal(glbRes.status, 200);
    const glb = parseGlb(glbRes.body);
    const t = treeRes.json;
    assert.equal(glb.json.nodes.length, 25);
    for (const n of glb.json.nodes) {
      const e = n.extras;
      const tn = t.nodes[e.node];
      assert.ok(tn, `extras ${JSON.stringify(e)}`);
      assert.equal(tn.component, e.component);
      assert.equal(tn.label, e.label);
      assert.equal(e.group, e.label);
    }
    // the model never proceduralized is served as before
    const plain = parseGlb((await http(d, 'GET', `/api/v1/models/${other.id}/mesh.glb`)).body);
    assert.ok(plain.json.nodes.every((n) => !('label' in n.extras) && !('node' in n.extras)));
  });

  it('PUT grammar with the same text: a new version with the same mesh and text', async () => {
    const g = await http(d, 'GET', `/api/v1/models/${model.id}/grammar`);
    assert.equal(g.status, 200);
    assert.match(g.headers.get('content-type'), /^text\/plain; charset=utf-8/);
    assert.equal(g.headers.get('etag'), `"${model.version}"`);
    assert.match(g.text, /^archgram-grammar 1\n/);
    assert.match(g.text, /subdivide\(/);
    const tree0 = (await http(d, 'GET', `/api/v1/models/${model.id}/tree`)).json;
    const r = await http(d, 'PUT', `/api/v1/models/${model.id}/grammar`, {
      body: g.text, headers: { 'If-Match': `"${model.version}"`, 'Content-Type': 'text/plain', 'X-Archgram-User': 'bo' },
    });
    assert.equal(r.status, 200, r.text);
    assert.equal(r.json.version, model.version + 1);
    assert.equal(r.headers.get('etag'), `"${model.version + 1}"`);
    assert.equal(r.json.proceduralized, true);
    assert.equal(r.json.stats.triangles, model.stats.triangles);
    const g2 = await http(d, 'GET', `/api/v1/models/${model.id}/grammar`);
    assert.equal(g2.text, g.text);
    assert.equal(g2.headers.get('etag'), `"${model.version + 1}"`);
    const tree1 = (await http(d, 'GET', `/api/v1/models/${model.id}/tree`)).json;
    assert.deepEqual(tree1.nodes, tree0.nodes);
    const op = await W.next((x) => x.type === 'op' && x.version === model.version + 1, 5000, 'grammar op');
    assert.deepEqual(op.op, { kind: 'grammar', bytes: Buffer.byteLength(g.text) });
    assert.equal(op.author, 'bo');
    model = r.json;
  });

  it('PUT grammar with an edit re-derives the mesh and the tree', async () => {
    const g = (await http(d, 'GET', `/api/v1/models/${model.id}/grammar`)).text;
    const edited = g.replace(/subdivide\(([^,]+), 6, 1, 4, 2\.5,/, 'subdivide($1, 3, 1, 4, 5,');
    assert.notEqual(edited, g, g);
    const r = await http(d, 'PUT', `/api/v1/models/${model.id}/grammar`, {
      body: edited, headers: { 'If-Match': '*' },
    });
    assert.equal(r.status, 200, r.text);
    assert.equal(r.json.stats.components, 13);
    const t = (await http(d, 'GET', `/api/v1/models/${model.id}/tree`)).json;
    assert.equal(t.version, r.json.version);
    assert.deepEqual(t.nodes.find((n) => n.kind === 'pattern').pattern.counts, [3, 1, 4]);
    assert.equal(t.nodes.filter((n) => n.visible).length, 13);
    // and back
    const back = await http(d, 'PUT', `/api/v1/models/${model.id}/grammar`, {
      body: g, headers: { 'If-Match': `"${r.json.version}"` },
    });
    assert.equal(back.status, 200, back.text);
    assert.equal(back.json.stats.components, 25);
    model = back.json;
  });

  it('PUT grammar with a syntax error: 422 with line and column, nothing changed', async () => {
    const g = (await http(d, 'GET', `/api/v1/models/${model.id}/grammar`)).text;
    const lines = g.split('\n');
    const at = lines.findIndex((l) => l.includes('subdivide('));
    lines[at] = lines[at].replace('subdivide(', 'subdivide(,');
    const r = await http(d, 'PUT', `/api/v1/models/${model.id}/grammar`, {
      body: lines.join('\n'), headers: { 'If-Match': `"${model.version}"` },
    });
    assertProblem(r, 422, 'parse', 'syntax error');
    assert.equal(r.json.line, at + 1);
    assert.equal(r.json.column, lines[at].indexOf('(,') + 2);
    assert.match(r.json.detail, new RegExp(`^line ${at + 1}, column ${r.json.column}: `));
    // a terminal the model does not have
    const t = await http(d, 'PUT', `/api/v1/models/${model.id}/grammar`, {
      body: g.replace(/terminals\/[0-9a-f]{16}\.obj/, 'terminals/0123456789abcdef.obj'),
      headers: { 'If-Match': `"${model.version}"` },
    });
    assertProblem(t, 422, 'parse', 'unknown terminal');
    assert.match(t.json.detail, /terminal 'T1'/);
    assert.equal(t.json.line, 3);
    const m = await getModel();
    assert.equal(m.version, model.version);
    assert.equal((await http(d, 'GET', `/api/v1/models/${model.id}/grammar`)).text, g);
  });

  it('PUT grammar preconditions: 428 without If-Match, 412 when stale', async () => {
    const g = (await http(d, 'GET', `/api/v1/models/${model.id}/grammar`)).text;
    assertProblem(await http(d, 'PUT', `/api/v1/models/${model.id}/grammar`, { body: g }), 428, 'precondition-required');
    assertProblem(await http(d, 'PUT', `/api/v1/models/${model.id}/grammar`, {
      body: g, headers: { 'If-Match': `"${model.version - 1}"` },
    }), 412, 'stale');
    assertProblem(await proceduralize(model.id, { 'If-Match': `"${model.version - 1}"` }), 412, 'stale');
    assertProblem(await http(d, 'PUT', `/api/v1/models/${other.id}/grammar`, {
      body: g, headers: { 'If-Match': '*' },
    }), 404, 'not-found');
    assert.equal((await getModel()).version, model.version);
  });

  it('websocket clients cannot send proceduralize or grammar ops', async () => {
    for (const kind of ['proceduralize', 'grammar']) {
      const nack = await W.request({ type: 'op', base: model.version, cid: `x-${kind}`, op: { kind } },
        (m) => m.type === 'nack' && m.cid === `x-${kind}`);
      assert.equal(nack.problem.type, 'urn:archgram:problem:invalid');
      assert.match(nack.problem.detail, /made by the server/);
    }
    assert.equal((await getModel()).version, model.version);
  });

  it('the body takes exact (a boolean) and unit (a length unit) and nothing else; exact copies derive the input back', async () => {
    const m = await importModel(d, facadeObj(3, 2), { name: 'exact' });
    for (const [body, detail] of [[{ exact: 'yes' }, '"exact" takes true or false'],
      [{ tolerance: 1 }, '"tolerance" is not an option of proceduralize'],
      [{ unit: 'yd' }, '"unit": the length unit of the mesh, m, dm, cm, mm, ft or in (or left out: decided from the content)'],
      [{ unit: 5 }, '"unit": the length unit of the mesh, m, dm, cm, mm, ft or in (or left out: decided from the content)']]) {
      const r = await http(d, 'POST', `/api/v1/models/${m.id}/proceduralize`, { body });
      assert.ok(r.status >= 400 && r.status < 500, r.text);
      assert.equal(r.headers.get('content-type'), 'application/problem+json');
      assert.equal(r.json.detail, detail);
    }
    assert.equal((await getModel(m.id)).version, m.version, 'a refused request stores nothing');
    const r = await http(d, 'POST', `/api/v1/models/${m.id}/proceduralize`, { body: { exact: true, unit: 'm' } });
    assert.equal(r.status, 202, r.text);
    const job = await waitJob(d, r.json.id);
    assert.equal(job.status, 'succeeded', JSON.stringify(job));
    const after = await getModel(m.id);
    assert.equal(after.proceduralized, true);
    assert.equal(after.stats.triangles, m.stats.triangles);
    const del = await http(d, 'DELETE', `/api/v1/models/${m.id}`, { headers: { 'If-Match': `"${after.version}"` } });
    assert.equal(del.status, 204, del.text);
  });

  it('a model that changes while the job waits makes it fail as stale, storing nothing', async () => {
    const blocker = await occupyWorker();
    const r = await proceduralize(model.id);
    assert.equal(r.status, 202, r.text);
    const renamed = await http(d, 'PATCH', `/api/v1/models/${model.id}`, {
      body: { name: 'facade 2' }, headers: { 'If-Match': `"${model.version}"` },
    });
    assert.equal(renamed.status, 200, renamed.text);
    await release(blocker);
    const job = await waitJob(d, r.json.id);
    assert.equal(job.status, 'failed', JSON.stringify(job));
    assert.equal(job.error.type, 'urn:archgram:problem:stale');
    const m = await getModel();
    assert.equal(m.version, model.version + 1);
    assert.equal(m.proceduralized, true, 'a rename keeps the grammar');
    const t = (await http(d, 'GET', `/api/v1/models/${model.id}/tree`)).json;
    assert.equal(t.version, m.version);
    model = m;
  });

  it('cancelling a proceduralize job: cancelled, version unchanged', async () => {
    const blocker = await occupyWorker();
    const r = await proceduralize(model.id);
    assert.equal(r.status, 202, r.text);
    const del = await http(d, 'DELETE', `/api/v1/jobs/${r.json.id}`);
    assert.equal(del.status, 200, del.text);
    await release(blocker);
    const job = await waitJob(d, r.json.id);
    assert.equal(job.status, 'cancelled', JSON.stringify(job));
    assert.equal(job.result, null);
    assert.equal((await getModel()).version, model.version);
  });

  it('deleting a proceduralized model leaves no grammar, terminal or file behind', async () => {
    const del = await http(d, 'DELETE', `/api/v1/models/${model.id}`, { headers: { 'If-Match': `"${model.version}"` } });
    assert.equal(del.status, 204, del.text);
    await W.next('gone');
    await d.stop();
    assert.deepEqual(sql(d.db, 'select count(*) from grammars'), [['0']]);
    assert.deepEqual(sql(d.db, 'select count(*) from terminals'), [['0']]);
    assert.deepEqual(sql(d.db, 'select count(*) from blobs where id not in (select mesh_blob from models) ' +
      'and id not in (select source_blob from models where source_blob is not null)'), [['0']]);
    d = null;
  });
});
