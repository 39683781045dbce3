// Bounded work: an op whose result would pass the limits is refused before it is made (the
// demo Tower's three resizes), an op past its time budget stops with nothing stored, one
// model's long edit does not hold up another model's, extrusion previews never hold up the HTTP
// threads and are dropped when their client goes away, and archgramd stops within a second of
// SIGTERM while work runs.
import assert from 'node:assert/strict';
import fs from 'node:fs';
import { after, before, describe, it } from 'node:test';
import {
  assertProblem, http, removeDir, sleep, sql, startDaemon, tempDir, waitJob, WsClient,
} from './harness.js';
import { plan838 } from './generated.js';

// Peak resident memory of a process (kB), from Linux's /proc.
function peakKb(pid) {
  const m = /VmHWM:\s+(\d+) kB/.exec(fs.readFileSync(`/proc/${pid}/status`, 'utf8'));
  return m ? Number(m[1]) : 0;
}

async function demoReady(d) {
  for (let i = 1; i <= 3; i++) {
    if ((await http(d, 'GET', `/api/v1/jobs/${i}`)).status === 200) {
      const done = await waitJob(d, i, { timeout: 60000 });
      assert.equal(done.status, 'succeeded', JSON.stringify(done));
    }
  }
}

async function resize(d, id, scale, node = 'root', timeout = 120000) {
  const v = (await http(d, 'GET', `/api/v1/models/${id}`)).json.version;
  return http(d, 'POST', `/api/v1/models/${id}/ops`, {
    body: { op: { kind: 'resize', node, scale } }, headers: { 'If-Match': `"${v}"` }, timeout,
  });
}


describe('bounded work', () => {
  const dir = tempDir();
  let d;
  before(async () => {
    d = await startDaemon({ dir, args: ['--no-web', '--demo'] });
    await demoReady(d);
  });
  after(async () => {
    if (d) { try { if (!d.exited) await d.stop(); } finally { await d.kill(); } }
    removeDir(dir);
  });

  it('the Tower\'s resizes: what would pass the limits is refused quickly, in bounded memory, storing nothing', async () => {
    const tower = 2;
    assert.equal((await resize(d, tower, [4, 1, 1])).status, 200);
    assert.equal((await resize(d, tower, [50, 1, 1])).status, 200);
    const before = (await http(d, 'GET', `/api/v1/models/${tower}`)).json;
    const t0 = Date.now();
    // windows keep their size, so the count grows with the facades' lengths and heights: this
    // one would place 3.7 million triangles
    const r = await resize(d, tower, [1000, 1000, 40]);
    const ms = Date.now() - t0;
    assertProblem(r, 422, 'too-large', 'resize [1000,1000,40]');
    assert.match(r.json.detail, /more than 2000000 triangles/);
    assert.ok(ms < 15000, `refused after ${ms} ms`);
    assert.ok(peakKb(d.proc.pid) < 1.5e6, `peak memory ${peakKb(d.proc.pid)} kB`);
    const after = (await http(d, 'GET', `/api/v1/models/${tower}`)).json;
    assert.equal(after.version, before.version, 'nothing was stored');
    assert.equal(after.stats.triangles, before.stats.triangles);
    // the model is still editable
    const again = await resize(d, tower, [1.2, 1, 1]);
    assert.equal(again.status, 200, again.text);
    const limits = (await http(d, 'GET', '/api/v1/health')).json.limits;
    assert.equal(limits.max_triangles, 2000000);
    assert.equal(limits.max_nodes, 200000);
  });

  it('one model\'s long edit does not hold up another model\'s', async () => {
    const tower = (await http(d, 'GET', '/api/v1/models/2')).json;
    const house = (await http(d, 'GET', '/api/v1/models/1')).json;
    const a = await WsClient.open(d.wsUrl);
    const b = await WsClient.open(d.wsUrl);
    try {
      await a.request({ type: 'hello', model: tower.id, user: 'ana' }, 'welcome');
      await b.request({ type: 'hello', model: house.id, user: 'bo' }, 'welcome');
      const order = [];
      const long = a.next((m) => m.cid === 'long', 120000, 'the Tower\'s answer').then((m) => { order.push('tower'); return m; });
      // about 1.3 million triangles made and stored: a long edit within the limits
      a.send({ type: 'op', cid: 'long', base: tower.version, op: { kind: 'resize', node: 'root', scale: [300, 300, 40] } });
      await sleep(50);
      const t0 = Date.now();
      const quick = await b.request({ type: 'op', cid: 'quick', base: house.version, op: { kind: 'resize', node: 'root', scale: [1.1, 1, 1] } },
        (m) => m.cid === 'quick', 60000, 'the house\'s answer');
      order.push('house');
      const houseMs = Date.now() - t0;
      assert.equal(quick.type, 'ack', JSON.stringify(quick));
      const tl = await long;
      assert.equal(tl.type, 'ack', JSON.stringify(tl));
      assert.deepEqual(order, ['house', 'tower'], `the house waited ${houseMs} ms`);
    } finally {
      await a.close();
      await b.close();
    }
  });

  it('eight concurrent previews of an 838-corner plan leave health fast, and all are answered', async () => {
    const body = JSON.stringify(plan838());
    let done = false;
    let worst = 0;
    const probe = (async () => {
      while (!done) {
        const t0 = performance.now();
        const h = await http(d, 'GET', '/api/v1/health');
        assert.equal(h.status, 200);
        worst = Math.max(worst, performance.now() - t0);
        await sleep(20);
      }
    })();
    const previews = await Promise.all([...Array(8).keys()].map(() => http(d, 'POST', '/api/v1/extrusions/preview', {
      body, headers: { 'Content-Type': 'application/json' }, timeout: 120000,
    })));
    done = true;
    await probe;
    for (const p of previews) assert.equal(p.status, 200, p.text.slice(0, 300));
    console.log(`# health under 8 previews: worst ${worst.toFixed(1)} ms`);
    assert.ok(worst < 500, `health took ${worst.toFixed(1)} ms`);
  });

  it('previews whose client went away are not run, or stop', async () => {
    const body = JSON.stringify(plan838());
    const before = (await http(d, 'GET', '/api/v1/health')).json.http.abandoned;
    // previews run on all but one task worker; the rest wait their turn, then their clients leave
    const ctls = [...Array(12).keys()].map(() => new AbortController());
    const auth = `Bearer ${await d.tokenFor()}`;
    const sent = ctls.map((ctl) => fetch(d.url('/api/v1/extrusions/preview'), {
      method: 'POST', body, headers: { 'Content-Type': 'application/json', Authorization: auth }, signal: ctl.signal,
    }).then((r) => r.arrayBuffer()).catch(() => null));
    let waiting = 0;
    for (let i = 0; i < 400 && waiting < 6; i++) {
      await sleep(10);
      waiting = (await http(d, 'GET', '/api/v1/health')).json.work.tasks_waiting;
    }
    assert.ok(waiting >= 6, `${waiting} previews waiting`);
    for (const c of ctls) c.abort();
    await Promise.all(sent);
    // the waiting ones are dropped when their turn comes, the running ones stop in their sweep
    const expected = waiting;
    let abandoned = before;
    for (let i = 0; i < 400 && abandoned - before < expected; i++) {
      await sleep(25);
      abandoned = (await http(d, 'GET', '/api/v1/health')).json.http.abandoned;
    }
    assert.ok(abandoned - before >= expected, `abandoned ${abandoned - before}, ${waiting} were waiting`);
    const h = (await http(d, 'GET', '/api/v1/health')).json;
    assert.equal(h.work.tasks_waiting, 0);
    const r = await http(d, 'POST', '/api/v1/extrusions/preview', { body, headers: { 'Content-Type': 'application/json' }, timeout: 60000 });
    assert.equal(r.status, 200);
  });

  it('an op or a preview past its time budget stops and stores nothing; SIGTERM while work runs stops within a second', async () => {
    await d.stop();
    d = await startDaemon({ dir, args: ['--no-web', '--op-seconds', '0.05', '--preview-seconds', '0.02'] });
    const tower = (await http(d, 'GET', '/api/v1/models/2')).json;
    const r = await resize(d, tower.id, [2, 2, 1]);
    assertProblem(r, 503, 'deadline', 'resize past its budget');
    assert.match(r.json.detail, /budget of 0.05 s/);
    assert.equal((await http(d, 'GET', `/api/v1/models/${tower.id}`)).json.version, tower.version);
    // an extrusion preview stops in its sweep
    const p = await http(d, 'POST', '/api/v1/extrusions/preview', {
      body: JSON.stringify(plan838()), headers: { 'Content-Type': 'application/json' },
    });
    assertProblem(p, 503, 'deadline', 'a preview past its budget');
    assert.match(p.json.detail, /extrusion preview ran longer than its budget of 0.02 s/);
    await d.stop();

    d = await startDaemon({ dir, args: ['--no-web'] });
    const t = (await http(d, 'GET', '/api/v1/models/2')).json;
    const pending = resize(d, t.id, [2, 2, 1]).catch((e) => ({ error: e }));
    await sleep(300);
    const { ms } = await d.stop(5000);
    console.log(`# SIGTERM during an edit: stopped in ${ms} ms`);
    assert.ok(ms < 1000, `stopped after ${ms} ms`);
    // answered (applied, or stopped by the shutdown) or cut off with the connection
    const answer = await pending;
    if (!answer.error) {
      assert.ok([200, 409, 503].includes(answer.status), `${answer.status} ${answer.text}`);
      if (answer.status !== 200) assert.match(answer.json.detail, /shutting down/);
    }
    assert.deepEqual(sql(d.db, 'PRAGMA integrity_check'), [['ok']]);
    const rows = sql(d.db, `SELECT version FROM models WHERE id = ${t.id}`);
    assert.ok(Number(rows[0][0]) === t.version || Number(rows[0][0]) === t.version + 1);
  });
});

// A binary PLY of one star-shaped polygon of n corners: assimp's triangulation takes quadratic
// time over it (32 000 corners, 0.5 MB: about 10 s).
function manySidedPly(n) {
  const head = Buffer.from(`ply\nformat binary_little_endian 1.0\nelement vertex ${n}\n`
    + 'property float x\nproperty float y\nproperty float z\nelement face 1\n'
    + 'property list int int vertex_indices\nend_header\n');
  const body = Buffer.alloc(12 * n + 4 + 4 * n);
  for (let i = 0; i < n; i++) {
    const r = i % 2 ? 0.5 : 1, a = (2 * Math.PI * i) / n;
    body.writeFloatLE(r * Math.cos(a), 12 * i);
    body.writeFloatLE(r * Math.sin(a), 12 * i + 4);
    body.writeUInt32LE(i, 12 * n + 4 + 4 * i);
  }
  body.writeInt32LE(n, 12 * n);
  return Buffer.concat([head, body]);
}

describe('uploads assimp cannot finish in time', () => {
  let d;
  after(async () => { if (d) { try { await d.stop(); } finally { await d.kill(); removeDir(d.dir); } } });

  it('a PLY that assimp takes many seconds over fails its job at --import-seconds; the service goes on', async () => {
    d = await startDaemon({ args: ['--no-web', '--import-seconds', '1', '--workers', '1'] });
    const slow = manySidedPly(32000);
    const t0 = Date.now();
    const up = await http(d, 'POST', '/api/v1/models?name=slow&format=ply', {
      body: slow, headers: { 'Content-Type': 'application/octet-stream' },
    });
    assert.equal(up.status, 202, up.text);
    const job = await waitJob(d, up.json.id, { timeout: 30000 });
    assert.equal(job.status, 'failed', JSON.stringify(job));
    assert.equal(job.error.type, 'urn:archgram:problem:deadline');
    assert.match(job.error.detail, /longer than 1 s/);
    assert.ok(Date.now() - t0 < 10000, `${Date.now() - t0} ms`);
    // the one worker is free again: a good PLY imports
    const good = fs.readFileSync(new URL('../data/proc/quad.ply', import.meta.url));
    const up2 = await http(d, 'POST', '/api/v1/models?name=quad&format=ply', {
      body: good, headers: { 'Content-Type': 'application/octet-stream' },
    });
    const job2 = await waitJob(d, up2.json.id, { timeout: 30000 });
    assert.equal(job2.status, 'succeeded', JSON.stringify(job2));
  });
});
