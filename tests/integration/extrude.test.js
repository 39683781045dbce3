// Extrusions as a service: POST /api/v1/extrusions (a job with per-footprint progress and a
// report), models of kind "extrusion", GET …/plan, and plan/profile ops that re-extrude,
// reach the room and are refused whole when invalid.
import assert from 'node:assert/strict';
import fs from 'node:fs';
import path from 'node:path';
import { after, before, describe, it } from 'node:test';
import {
  assertProblem, http, parseGlb, PROBLEM, REPO, removeDir, startDaemon, waitJob, WsClient,
} from './harness.js';

const DATA = path.join(REPO, 'tests', 'data', 'extrude_service');
const readJson = (name) => JSON.parse(fs.readFileSync(path.join(DATA, name), 'utf8'));

describe('extrusions over REST and websockets', () => {
  let d;
  let hip; // the model made from hip_plan.json
  let city; // the model made from batch.geojson
  const clients = [];

  const open = async () => { const c = await WsClient.open(d.wsUrl); clients.push(c); return c; };
  const getModel = async (id) => {
    const r = await http(d, 'GET', `/api/v1/models/${id}`);
    assert.equal(r.status, 200, r.text);
    return r.json;
  };
  const extrude = async (body, query, headers = {}) => {
    const q = new URLSearchParams(query);
    const r = await http(d, 'POST', `/api/v1/extrusions?${q}`, {
      body: typeof body === 'string' ? body : JSON.stringify(body),
      headers: { 'Content-Type': 'application/json', ...headers },
    });
    assert.equal(r.status, 202, r.text);
    assert.equal(r.json.kind, 'extrude');
    assert.equal(r.headers.get('location'), `/api/v1/jobs/${r.json.id}`);
    return waitJob(d, r.json.id);
  };
  const modelCount = async () => (await http(d, 'GET', '/api/v1/models')).json.items.length;

  before(async () => {
    d = await startDaemon({ args: ['--workers', '1', '--no-web'] });
  });
  after(async () => {
    for (const c of clients) await c.close().catch(() => {});
    if (d) { try { await d.stop(); } finally { await d.kill(); removeDir(d.dir); } }
  });

  it('a hip plan becomes a job, then a model of kind extrusion with a non-empty mesh', async () => {
    const W = await open();
    const r = await http(d, 'POST', '/api/v1/extrusions?name=hip&style=hip', {
      body: fs.readFileSync(path.join(DATA, 'hip_plan.json')), headers: { 'Content-Type': 'application/json' },
    });
    assert.equal(r.status, 202, r.text);
    W.send({ type: 'watch', job: r.json.id });
    const job = await waitJob(d, r.json.id);
    assert.equal(job.status, 'succeeded', JSON.stringify(job));
    const done = await W.next((m) => m.type === 'job.done' && m.job === r.json.id, 10000, 'job.done');
    assert.equal(done.status, 'succeeded');
    const rep = job.result.report;
    assert.equal(rep.footprints, 1);
    assert.equal(rep.succeeded, 1);
    assert.deepEqual(rep.failed, []);
    assert.equal(rep.not_watertight, 0);
    assert.ok(rep.triangles > 0 && typeof rep.seconds === 'number', JSON.stringify(rep));
    assert.equal(job.result.href, `/api/v1/models/${job.result.model}`);

    hip = await getModel(job.result.model);
    assert.equal(hip.kind, 'extrusion');
    assert.equal(hip.name, 'hip');
    assert.equal(hip.stats.triangles, rep.triangles);
    assert.equal(hip.stats.components, 1);
    // 10 × 6 rectangle, 3 m walls then 45°: the ridge at 3 + 6/2
    assert.ok(Math.abs(hip.stats.bounds.max[2] - 6) < 1e-6, JSON.stringify(hip.stats.bounds));
    const glb = await http(d, 'GET', `/api/v1/models/${hip.id}/mesh.glb`);
    assert.equal(glb.status, 200);
    const g = parseGlb(glb.body);
    assert.equal(g.magic, 'glTF');
    assert.ok(g.bin && g.bin.length > 0, 'the GLB has geometry');
    assert.ok(g.json.meshes.length >= 1);
  });

  it('GET plan returns the stored description with the version as ETag', async () => {
    const r = await http(d, 'GET', `/api/v1/models/${hip.id}/plan`);
    assert.equal(r.status, 200, r.text);
    assert.equal(r.headers.get('etag'), `"${hip.version}"`);
    const sent = readJson('hip_plan.json');
    assert.deepEqual(r.json.loops, sent.loops);
    assert.deepEqual(r.json.profiles, sent.profiles);
    assert.equal(r.json.default_profile, 'hip');
  });

  it('GET plan of a model that is not an extrusion is a 404 problem', async () => {
    const up = await http(d, 'POST', '/api/v1/models?name=box&format=obj', {
      body: 'v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n', headers: { 'Content-Type': 'application/octet-stream' },
    });
    assert.equal(up.status, 202, up.text);
    const job = await waitJob(d, up.json.id);
    assert.equal(job.status, 'succeeded', JSON.stringify(job));
    const r = await http(d, 'GET', `/api/v1/models/${job.result.model}/plan`);
    assertProblem(r, 404, 'not-found', 'plan of a mesh model');
    assert.match(r.json.detail, /not an extrusion/);
    assertProblem(await http(d, 'GET', '/api/v1/models/999999/plan'), 404, 'not-found');
    // a plan op on it is refused and the version stays
    const m = await getModel(job.result.model);
    const op = await http(d, 'POST', `/api/v1/models/${m.id}/ops`, {
      body: { cid: 'p-mesh', op: { kind: 'plan', building: 0, plan: readJson('hip_plan.json') } },
      headers: { 'If-Match': `"${m.version}"` },
    });
    assertProblem(op, 400, 'invalid', 'plan op on a mesh model');
    assert.equal((await getModel(m.id)).version, m.version);
  });

  it('a GeoJSON batch with a self-intersecting footprint: it is reported failed, the others succeed', async () => {
    const job = await extrude(fs.readFileSync(path.join(DATA, 'batch.geojson'), 'utf8'),
      { name: 'city', style: 'hip', lonlat: 'false', height_property: 'height' },
      { 'Content-Type': 'application/geo+json' });
    assert.equal(job.status, 'succeeded', JSON.stringify(job));
    const rep = job.result.report;
    assert.equal(rep.footprints, 3);
    assert.equal(rep.succeeded, 2);
    assert.equal(rep.failed.length, 1);
    assert.equal(rep.failed[0].id, 'bowtie');
    assert.match(rep.failed[0].reason, /cross/);
    city = await getModel(job.result.model);
    assert.equal(city.kind, 'extrusion');
    assert.equal(city.stats.components, 2);
    assert.deepEqual([...city.stats.group_names].sort(), ['house-a', 'house-c']);
    const plan = (await http(d, 'GET', `/api/v1/models/${city.id}/plan`)).json;
    assert.equal(plan.format, 'geojson');
    assert.equal(plan.style, 'hip');
    assert.deepEqual(plan.buildings.map((b) => [b.id, b.status, b.component]),
      [['house-a', 'ok', 0], ['bowtie', 'failed', null], ['house-c', 'ok', 1]]);
    assert.match(plan.buildings[1].reason, /cross/);
    assert.ok(plan.buildings[0].plan.loops, 'a stored description per footprint');
  });

  it('bad input fails the job with a precise problem and stores nothing', async () => {
    const before = await modelCount();
    const notJson = await extrude('{"loops": [', { name: 'broken' });
    assert.equal(notJson.status, 'failed');
    assert.equal(notJson.error.type, `${PROBLEM}parse`);
    assert.match(notJson.error.detail, /line 1/);
    const crossing = await extrude({ ...readJson('hip_plan.json'), loops: [[[0, 0], [15, 0], [0, 10], [10, 12]]] }, { name: 'crossing' });
    assert.equal(crossing.status, 'failed');
    assert.match(crossing.error.detail, /crosses or touches/);
    const allBad = await extrude({
      type: 'FeatureCollection',
      features: [{ type: 'Feature', id: 'x', properties: {}, geometry: { type: 'Polygon', coordinates: [[[0, 0], [15, 0], [0, 10], [10, 12], [0, 0]]] } }],
    }, { name: 'allbad', lonlat: 'false' });
    assert.equal(allBad.status, 'failed');
    assert.match(allBad.error.detail, /"x"/);
    assert.equal(await modelCount(), before, 'no model was stored');
    assertProblem(await http(d, 'POST', '/api/v1/extrusions?style=gothic', { body: '{}' }), 400, 'invalid');
    assertProblem(await http(d, 'POST', '/api/v1/extrusions?format=shp', { body: '{}' }), 415, 'unsupported');
  });

  it('a plan op moving a corner re-extrudes, raises the version and reaches a second client', async () => {
    const A = await open();
    const B = await open();
    const wa = await A.request({ type: 'hello', model: hip.id, user: 'ana' }, 'welcome');
    await B.request({ type: 'hello', model: hip.id, user: 'bo' }, 'welcome');
    assert.equal(wa.version, hip.version);
    const plan = (await http(d, 'GET', `/api/v1/models/${hip.id}/plan`)).json;
    plan.loops[0].points[1] = [14, 0]; // the corner (10, 0) moves out to (14, 0)
    plan.loops[0].points[2] = [14, 6];
    const op = { kind: 'plan', building: 0, plan };
    const ack = await A.request({ type: 'op', base: hip.version, cid: 'move-1', op }, (m) => (m.type === 'ack' || m.type === 'nack') && m.cid === 'move-1');
    assert.equal(ack.type, 'ack', JSON.stringify(ack));
    assert.equal(ack.version, hip.version + 1);
    const seen = await B.next((m) => m.type === 'op' && m.cid === 'move-1', 5000, 'the plan op');
    assert.equal(seen.version, hip.version + 1);
    assert.equal(seen.author, 'ana');
    assert.deepEqual(seen.op.plan.loops, plan.loops);
    const m = await getModel(hip.id);
    assert.equal(m.version, hip.version + 1);
    assert.ok(Math.abs(m.stats.bounds.max[0] - 14) < 1e-6, `bounds moved: ${JSON.stringify(m.stats.bounds)}`);
    assert.ok(Math.abs(hip.stats.bounds.max[0] - 10) < 1e-6);
    const stored = await http(d, 'GET', `/api/v1/models/${hip.id}/plan`);
    assert.equal(stored.headers.get('etag'), `"${m.version}"`);
    assert.deepEqual(stored.json.loops, plan.loops);
    hip = m;
  });

  it('an invalid plan op is nacked with the reason and nothing changes', async () => {
    const A = await open();
    await A.request({ type: 'hello', model: hip.id, user: 'ana' }, 'welcome');
    const before = (await http(d, 'GET', `/api/v1/models/${hip.id}/plan`)).text;
    const plan = JSON.parse(before);
    plan.loops[0].points = [[0, 0], [15, 0], [0, 10], [10, 12]]; // crossing edges
    const nack = await A.request({ type: 'op', base: hip.version, cid: 'bad-1', op: { kind: 'plan', building: 0, plan } },
      (m) => (m.type === 'ack' || m.type === 'nack') && m.cid === 'bad-1');
    assert.equal(nack.type, 'nack', JSON.stringify(nack));
    assert.equal(nack.version, hip.version);
    assert.equal(nack.problem.type, `${PROBLEM}parse`);
    assert.match(nack.problem.detail, /crosses or touches/);
    const outOfRange = await A.request({ type: 'op', base: hip.version, cid: 'bad-2', op: { kind: 'plan', building: 3, plan: JSON.parse(before) } },
      (m) => (m.type === 'ack' || m.type === 'nack') && m.cid === 'bad-2');
    assert.equal(outOfRange.type, 'nack');
    assert.match(outOfRange.problem.detail, /no building 3/);
    // REST: 422 with the reason
    const r = await http(d, 'POST', `/api/v1/models/${hip.id}/ops`, {
      body: { cid: 'bad-3', op: { kind: 'profile', name: 'hip', profile: [[0, 0], [0, 3], [1, 2]] } },
      headers: { 'If-Match': `"${hip.version}"` },
    });
    assert.ok(r.status === 422 || r.status === 400, r.text);
    assert.match(r.json.detail, /profile/);
    assert.equal((await getModel(hip.id)).version, hip.version);
    assert.equal((await http(d, 'GET', `/api/v1/models/${hip.id}/plan`)).text, before);
  });

  it('a profile op changes the roof of the buildings that use it', async () => {
    // the hip profile as a steeper roof: 3 m walls, then 2 m up per metre inwards
    const r = await http(d, 'POST', `/api/v1/models/${hip.id}/ops`, {
      body: { cid: 'steep', op: { kind: 'profile', name: 'hip', profile: { points: [[0, 0], [0, 3], [1, 5]], tag: 'roof' } } },
      headers: { 'If-Match': `"${hip.version}"`, 'X-Archgram-User': 'cy' },
    });
    assert.equal(r.status, 200, r.text);
    assert.equal(r.json.version, hip.version + 1);
    const m = await getModel(hip.id);
    // 14 × 6 now: the ridge at 3 + 2 × 3 = 9 instead of 6
    assert.ok(Math.abs(m.stats.bounds.max[2] - 9) < 1e-6, JSON.stringify(m.stats.bounds));
    assert.ok(Math.abs(hip.stats.bounds.max[2] - 6) < 1e-6);
    const plan = (await http(d, 'GET', `/api/v1/models/${hip.id}/plan`)).json;
    assert.deepEqual(plan.profiles.hip.points, [[0, 0], [0, 3], [1, 5]]);
    const log = (await http(d, 'GET', `/api/v1/models/${hip.id}/ops`)).json.items;
    assert.deepEqual(log.map((o) => o.op.kind).slice(-2), ['plan', 'profile']);
    assert.equal(log.at(-1).author, 'cy');
    // a profile nobody uses is refused
    const none = await http(d, 'POST', `/api/v1/models/${hip.id}/ops`, {
      body: { op: { kind: 'profile', name: 'nobody', profile: [[0, 0], [0, 2]] } },
      headers: { 'If-Match': `"${m.version}"` },
    });
    assertProblem(none, 400, 'invalid');
    assert.match(none.json.detail, /nobody/);
    // in a batch, only the buildings with the profile are rebuilt; the failed one stays failed
    const before = (await http(d, 'GET', `/api/v1/models/${city.id}/plan`)).json;
    const name = Object.keys(before.buildings[0].plan.profiles)[0];
    const c = await http(d, 'POST', `/api/v1/models/${city.id}/ops`, {
      body: { op: { kind: 'profile', name, profile: [[0, 0], [0, 1]] } },
      headers: { 'If-Match': `"${city.version}"` },
    });
    assert.equal(c.status, 200, c.text);
    const after = (await http(d, 'GET', `/api/v1/models/${city.id}/plan`)).json;
    assert.equal(after.buildings[1].status, 'failed');
    assert.equal((await getModel(city.id)).stats.components, 2);
  });
});
