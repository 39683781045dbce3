// Point clouds in the service: uploads of PLY, LAS, LAZ and XYZ (named and sniffed) make
// models of kind pointcloud whose points.ply gives the input's points and properties back;
// bad clouds fail their job with a precise problem; points.glb holds a budget of points that
// is a prefix of one order, the same on every request; the segment job reports its stages
// and finds the planes; ROI refinement and template marking are ops logged with a report,
// seen by a second client, undone and redone exactly; tree, grammar and structural edits of a
// cloud not proceduralized answer precise problems; and the AHN3 crop goes through the service.
// Clouds are written by the test's own writers (clouds.js), not archgram's.
import assert from 'node:assert/strict';
import fs from 'node:fs';
import path from 'node:path';
import { after, before, describe, it } from 'node:test';
import {
  assertProblem, http, parseGlb, PROBLEM, REPO, removeDir, startDaemon, waitJob, WsClient,
} from './harness.js';
import { boxCloud, lasBytes, parsePly, planesFound, plyBytes, rng, xyzBytes } from './clouds.js';

const POINTS = path.join(REPO, 'tests', 'data', 'points');
const SHARED = path.join(REPO, '..', 'shared', 'data');
const RD = [84808, 447412, 3]; // RD New, metres
const OFF = [RD[0], RD[1], 0]; // the local origin archgram picks for it (z stays within 10 km)

// POST a file to /api/v1/models, with ?format= only when one is given (else it is sniffed);
// returns the job.
async function post(d, body, { name, format }) {
  const q = new URLSearchParams({ name });
  if (format) q.set('format', format);
  const res = await http(d, 'POST', `/api/v1/models?${q}`, { body, headers: { 'Content-Type': 'application/octet-stream' }, timeout: 120000 });
  assert.equal(res.status, 202, `upload → ${res.status} ${res.text.slice(0, 400)}`);
  return res.json;
}

// Uploads a cloud and waits for its job; returns {job, model}.
async function uploadCloud(d, body, opts) {
  const job = await waitJob(d, (await post(d, body, opts)).id, { timeout: 120000 });
  assert.equal(job.status, 'succeeded', JSON.stringify(job.error));
  const model = (await http(d, 'GET', job.result.href)).json;
  return { job, model };
}

async function pointsPly(d, id) {
  const r = await http(d, 'GET', `/api/v1/models/${id}/points.ply`, { timeout: 60000 });
  assert.equal(r.status, 200, r.text.slice(0, 300));
  assert.equal(r.headers.get('content-type'), 'application/x-ply');
  return parsePly(r.body);
}

function offsetOf(ply) {
  const c = ply.comments.find((x) => x.startsWith('offset'));
  return c ? c.split(' ').slice(1).map(Number) : [0, 0, 0];
}

// The attribute `name` of the only primitive of a points GLB, as numbers.
function glbAttribute(glb, name) {
  const prim = glb.json.meshes[0].primitives[0];
  const acc = glb.json.accessors[prim.attributes[name]];
  assert.ok(acc, `no ${name} in ${JSON.stringify(prim.attributes)}`);
  const view = glb.json.bufferViews[acc.bufferView];
  const per = { SCALAR: 1, VEC3: 3, VEC4: 4 }[acc.type];
  const out = [];
  for (let i = 0; i < acc.count * per; i++) {
    out.push(acc.componentType === 5126 ? glb.bin.readFloatLE(view.byteOffset + 4 * i) : glb.bin[view.byteOffset + i]);
  }
  return { values: out, count: acc.count, acc };
}

// GLB points back in model coordinates (glTF is y-up: archgram (x, y, z) = (gx, -gz, gy)).
function glbPoints(glb) {
  const pos = glbAttribute(glb, 'POSITION').values;
  const t = glb.json.nodes[0].translation;
  const out = [];
  for (let i = 0; i < pos.length; i += 3) out.push([pos[i] + t[0], -(pos[i + 2] + t[2]), pos[i + 1] + t[1]]);
  return out;
}

// Points by place, to find the input point a shown (float) point is: the nearest within 1 mm.
class PointIndex {
  constructor() {
    this.cells = new Map();
  }

  static cell(p) {
    return p.map((v) => Math.floor(v * 100));
  }

  add(p, i) {
    const c = PointIndex.cell(p).join(',');
    if (!this.cells.has(c)) this.cells.set(c, []);
    this.cells.get(c).push([p, i]);
  }

  find(p) {
    const [cx, cy, cz] = PointIndex.cell(p);
    let best = null, bd = 1e-3;
    for (let a = -1; a <= 1; a++) for (let b = -1; b <= 1; b++) for (let e = -1; e <= 1; e++) {
      for (const [q, i] of this.cells.get(`${cx + a},${cy + b},${cz + e}`) ?? []) {
        const dd = Math.hypot(q[0] - p[0], q[1] - p[1], q[2] - p[2]);
        if (dd < bd) { bd = dd; best = i; }
      }
    }
    return best;
  }
}

// A facade at RD New coordinates turned by `turn` degrees: a 24 x 9 m wall with 6 x 3 window
// openings of 1.2 x 1.5 m (centres 2 + 4c, 1.5 + 3r along and up it), sampled evenly.
function facade(n, turn, seed = 5) {
  const r = rng(seed);
  const a = (turn * Math.PI) / 180;
  const u = [Math.cos(a), Math.sin(a), 0];
  const out = [Math.sin(a), -Math.cos(a), 0];
  const x = [], y = [], z = [];
  const hole = (s, t) => [0, 1, 2, 3, 4, 5].some((c) => Math.abs(s - (2 + 4 * c)) < 0.6) &&
    [0, 1, 2].some((w) => Math.abs(t - (1.5 + 3 * w)) < 0.75);
  while (x.length < n) {
    const s = r() * 24, t = r() * 9;
    if (hole(s, t)) continue;
    const e = (r() - 0.5) * 0.01;
    x.push(RD[0] + s * u[0] + e * out[0]);
    y.push(RD[1] + s * u[1] + e * out[1]);
    z.push(RD[2] + t);
  }
  const centre = (c, w) => [RD[0] + (2 + 4 * c) * u[0], RD[1] + (2 + 4 * c) * u[1], RD[2] + 1.5 + 3 * w];
  return { x, y, z, u, out, centre };
}

describe('point clouds in the service', () => {
  let d;
  const box = boxCloud(20000, RD);
  const models = {};
  before(async () => {
    d = await startDaemon();
  });
  after(async () => {
    if (d) { try { await d.stop(); } finally { await d.kill(); removeDir(d.dir); } }
  });

  it('PLY, LAS, LAZ and XYZ uploads make pointcloud models whose points.ply gives every point and property back', async () => {
    const intensity = box.x.map((_, i) => (i * 37) % 4000);
    const ply = plyBytes([['x', 'double', box.x], ['y', 'double', box.y], ['z', 'double', box.z],
      ['classification', 'uchar', box.cls], ['plane', 'int', box.plane], ['intensity', 'ushort', intensity]]);
    for (const format of ['ply', undefined]) {
      const { job, model } = await uploadCloud(d, ply, { name: 'box ply', format });
      assert.equal(model.kind, 'pointcloud');
      assert.equal(model.stats.points, 20000);
      assert.equal(job.result.points, `/api/v1/models/${model.id}/points.glb`);
      assert.deepEqual(model.stats.offset, OFF);
      assert.deepEqual(model.stats.properties.map((p) => `${p.name}:${p.type}`), ['classification:uint8', 'plane:int32', 'intensity:uint16']);
      assert.equal(model.stats.segmented, false);
      assert.equal(model.source_format, 'ply');
      const back = await pointsPly(d, model.id);
      assert.equal(back.n, 20000);
      const off = offsetOf(back);
      for (let i = 0; i < back.n; i++) {
        assert.ok(Math.abs(back.props.x[i] + off[0] - box.x[i]) < 1e-4, `x of point ${i}`);
        assert.ok(Math.abs(back.props.y[i] + off[1] - box.y[i]) < 1e-4, `y of point ${i}`);
        assert.ok(Math.abs(back.props.z[i] + off[2] - box.z[i]) < 1e-4, `z of point ${i}`);
        assert.equal(back.props.classification[i], box.cls[i]);
        assert.equal(back.props.plane[i], box.plane[i]);
        assert.equal(back.props.intensity[i], intensity[i]);
      }
      models.ply = model;
    }
    // LAS point format 2 at millimetres, named and sniffed
    const red = box.x.map((_, i) => (i * 911) % 65536), green = box.x.map((_, i) => (i * 7) % 65536);
    const blue = box.plane.map((p) => p * 10000);
    const las = lasBytes({ ...box, classification: box.cls, intensity, red, green, blue }, [84000, 447000, 0]);
    for (const format of ['las', undefined]) {
      const { model } = await uploadCloud(d, las, { name: 'box las', format });
      assert.equal(model.kind, 'pointcloud');
      assert.equal(model.source_format, 'las');
      assert.deepEqual(model.stats.scale, [0.001, 0.001, 0.001]);
      assert.equal(model.stats.positions, 'i32', 'LAS integers kept as such');
      const back = await pointsPly(d, model.id);
      assert.equal(back.n, 20000);
      const off = offsetOf(back);
      for (let i = 0; i < back.n; i++) {
        assert.ok(Math.abs(back.props.x[i] + off[0] - box.x[i]) < 6e-4, `x of point ${i}`); // mm grid
        assert.ok(Math.abs(back.props.z[i] + off[2] - box.z[i]) < 6e-4, `z of point ${i}`);
        assert.equal(back.props.classification[i], box.cls[i]);
        assert.equal(back.props.intensity[i], intensity[i]);
        assert.equal(back.props.red[i], red[i]);
        assert.equal(back.props.green[i], green[i]);
        assert.equal(back.props.blue[i], blue[i]);
      }
      models.las = model;
    }
    // LAZ (LASzip, format 3) against the same points uncompressed
    const lazFile = fs.readFileSync(path.join(POINTS, 'box_walls.laz'));
    const lasFile = fs.readFileSync(path.join(POINTS, 'box_walls.las'));
    const fromLaz = await uploadCloud(d, lazFile, { name: 'walls laz', format: 'laz' });
    const sniffed = await uploadCloud(d, lazFile, { name: 'walls laz sniffed', format: undefined });
    const fromLas = await uploadCloud(d, lasFile, { name: 'walls las', format: 'las' });
    assert.equal(fromLaz.model.source_format, 'laz');
    assert.equal(sniffed.model.source_format, 'laz');
    assert.equal(fromLaz.model.stats.points, 3000);
    const a = await pointsPly(d, fromLaz.model.id), b = await pointsPly(d, sniffed.model.id), c = await pointsPly(d, fromLas.model.id);
    assert.deepEqual(a.props, c.props);
    assert.deepEqual(b.props, c.props);
    assert.deepEqual(offsetOf(a), [85100, 446200, 0]);
    assert.ok(a.props.gps_time && a.props.red && a.props.classification, Object.keys(a.props).join());
    models.laz = fromLaz.model;
    // XYZ text
    const xyz = await uploadCloud(d, xyzBytes(box.x, box.y, box.z), { name: 'box xyz', format: 'xyz' });
    assert.equal(xyz.model.stats.points, 20000);
    const xb = await pointsPly(d, xyz.model.id);
    const xo = offsetOf(xb);
    for (let i = 0; i < xb.n; i += 13) assert.ok(Math.abs(xb.props.y[i] + xo[1] - box.y[i]) < 1e-4);
    // a PLY with faces is a mesh
    const mesh = await uploadCloud(d, Buffer.from('ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n' +
      'property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n'), { name: 'tri', format: 'ply' });
    assert.equal(mesh.model.kind, 'mesh');
    models.mesh = mesh.model;
  });

  it('bad clouds fail their job with a precise problem and store nothing', async () => {
    const before = (await http(d, 'GET', '/api/v1/models?page_size=200')).json.items.length;
    const fail = async (body, format, status, slug, detail) => {
      const job = await waitJob(d, (await post(d, body, { name: 'bad', format })).id);
      assert.equal(job.status, 'failed', JSON.stringify(job));
      assert.equal(job.error.status, status, JSON.stringify(job.error));
      assert.equal(job.error.type, PROBLEM + slug, JSON.stringify(job.error));
      assert.match(job.error.detail, detail);
    };
    await fail(fs.readFileSync(path.join(POINTS, 'nan.ply')), 'ply', 422, 'parse', /point 3 has x = nan/);
    await fail(fs.readFileSync(path.join(POINTS, 'lying_count.las')), 'las', 422, 'parse', /header says 1000 points/);
    const laz = fs.readFileSync(path.join(POINTS, 'box_walls.laz'));
    await fail(laz.subarray(0, Math.floor(laz.length / 2)), 'laz', 422, 'parse', /./);
    await fail(fs.readFileSync(path.join(POINTS, 'empty.ply')), 'ply', 422, 'empty', /holds no points/);
    await fail(Buffer.from('ply\nformat ascii 1.0\nend_header\n'), 'las', 422, 'parse', /LAS|LASF|signature/i);
    // a header that claims more points than the service takes: refused before it is read
    await fail(Buffer.from('ply\nformat binary_little_endian 1.0\nelement vertex 30000000\nproperty float x\n' +
      'property float y\nproperty float z\nend_header\n'), 'ply', 413, 'too-large', /30000000 points; archgram takes at most 20000000/);
    const after = (await http(d, 'GET', '/api/v1/models?page_size=200')).json.items.length;
    assert.equal(after, before);
  });

  it('points.glb holds a budget of points: a prefix of one order, the same on every request', async () => {
    const id = models.ply.id;
    const get = (q, headers) => http(d, 'GET', `/api/v1/models/${id}/points.glb${q}`, { headers });
    const small = await get('?budget=1000');
    assert.equal(small.status, 200);
    assert.equal(small.headers.get('content-type'), 'model/gltf-binary');
    const g = parseGlb(small.body);
    assert.equal(g.magic, 'glTF');
    assert.equal(g.json.meshes[0].primitives[0].mode, 0);
    assert.equal(glbAttribute(g, 'POSITION').count, 1000);
    assert.deepEqual(g.json.nodes[0].extras.offset, OFF);
    assert.equal(g.json.nodes[0].extras.points, 20000);
    assert.equal(g.json.nodes[0].extras.shown, 1000);
    // the same bytes again, and 304 for the ETag
    const again = await get('?budget=1000');
    assert.ok(again.body.equals(small.body));
    assert.equal(again.headers.get('etag'), small.headers.get('etag'));
    assert.equal((await get('?budget=1000', { 'If-None-Match': small.headers.get('etag') })).status, 304);
    // a larger budget starts with the smaller one's points
    const big = glbPoints(parseGlb((await get('?budget=5000')).body));
    const few = glbPoints(g);
    assert.equal(big.length, 5000);
    // (each GLB is centred on its own points: the floats differ in their last bits)
    for (let i = 0; i < few.length; i++) {
      for (let k = 0; k < 3; k++) assert.ok(Math.abs(big[i][k] - few[i][k]) < 1e-5, `point ${i}: ${big[i]} vs ${few[i]}`);
    }
    // every point shown is a point of the cloud, none twice, and the five faces all get their share
    const local = new PointIndex();
    for (let i = 0; i < box.x.length; i++) local.add([box.x[i] - OFF[0], box.y[i] - OFF[1], box.z[i] - OFF[2]], i);
    const seen = new Set(), faces = [0, 0, 0, 0, 0];
    for (const p of big) {
      const i = local.find(p);
      assert.ok(i !== null, `shown point ${p} is not in the cloud`);
      assert.ok(!seen.has(i));
      seen.add(i);
      faces[box.plane[i]]++;
    }
    // the faces have as many points each but not as much area: an even subsample follows the
    // area (12 x 6, 12 x 8 and 8 x 6 m), a random one would give each a fifth
    const area = [72, 48, 72, 48, 96], total = 336;
    for (let k = 0; k < 5; k++) {
      assert.ok(Math.abs(faces[k] / big.length - area[k] / total) < 0.04, `faces ${faces} for areas ${area}`);
    }
    // a budget past the points gives them all; bad budgets are refused
    const all = parseGlb((await get('?budget=50000000')).body);
    assert.equal(glbAttribute(all, 'POSITION').count, 20000);
    assertProblem(await get('?budget=0'), 400, 'invalid', 'budget 0');
    assertProblem(await get('?budget=lots'), 400, 'invalid', 'budget lots');
    // the LAS model's colour comes along; mesh.glb of a cloud is its points
    const las = parseGlb((await http(d, 'GET', `/api/v1/models/${models.las.id}/points.glb?budget=100`)).body);
    assert.equal(glbAttribute(las, 'COLOR_0').count, 100);
    assert.equal(glbAttribute(las, '_CLASSIFICATION').count, 100);
    const mesh = parseGlb((await http(d, 'GET', `/api/v1/models/${id}/mesh.glb`)).body);
    assert.equal(glbAttribute(mesh, 'POSITION').count, 20000);
    // a mesh has no points
    assertProblem(await http(d, 'GET', `/api/v1/models/${models.mesh.id}/points.ply`), 404, 'not-found', 'points of a mesh');
  });

  it('the segment job reports its stages, finds the box planes and logs a segment op', async () => {
    const id = models.ply.id;
    const W = await WsClient.open(d.wsUrl);
    try {
      await W.request({ type: 'hello', model: id, user: 'ana' }, 'welcome');
      assertProblem(await http(d, 'POST', `/api/v1/models/${id}/segment`, { body: { threshold: 3 } }), 400, 'invalid', 'threshold 3');
      assertProblem(await http(d, 'POST', `/api/v1/models/${id}/segment`, { body: { thresh: 0.1 } }), 400, 'invalid', 'unknown member');
      assertProblem(await http(d, 'POST', `/api/v1/models/${id}/segment`, { body: {}, headers: { 'If-Match': '"7"' } }), 412, 'stale', 'stale');
      assertProblem(await http(d, 'POST', `/api/v1/models/${models.mesh.id}/segment`, { body: {} }), 409, 'conflict', 'a mesh');
      const res = await http(d, 'POST', `/api/v1/models/${id}/segment`, { body: {}, headers: { 'X-Archgram-User': 'ana' } });
      assert.equal(res.status, 202, res.text);
      W.send({ type: 'watch', job: res.json.id });
      const done = await W.next((m) => m.type === 'job.done' && m.job === res.json.id, 60000, 'job.done');
      assert.equal(done.status, 'succeeded', JSON.stringify(done));
      const stages = new Set(W.all.filter((m) => m.type === 'job.progress' && m.job === res.json.id).map((m) => m.stage));
      const op = await W.next((m) => m.type === 'op' && m.op.kind === 'segment', 10000, 'the segment op');
      assert.equal(op.version, done.result.version);
      assert.ok(op.op.report.planes >= 5, JSON.stringify(op.op.report));
      for (const s of ['index', 'normals', 'coarse', 'refine', 'label']) assert.equal(typeof op.op.report.seconds[s], 'number', s);
      console.log(`# segment job: stages seen over the websocket ${[...stages].join(', ')}; ${op.op.report.segments} segments in ${op.op.report.seconds.total.toFixed(2)} s`);
      assert.ok(stages.size >= 2, [...stages].join());
      const seg = await pointsPly(d, id);
      assert.equal(seg.types.segment, 'int');
      assert.equal(planesFound(box.plane, seg.props.segment), 5);
      for (let i = 0; i < seg.n; i++) assert.equal(seg.props.plane[i], box.plane[i]); // properties kept
      const m = (await http(d, 'GET', `/api/v1/models/${id}`)).json;
      assert.equal(m.version, op.version);
      assert.equal(m.stats.segmented, true);
      assert.equal(m.stats.segments, op.op.report.segments);
      assert.equal(m.stats.normals, true);
      // the GLB's segments are those of points.ply
      const g = parseGlb((await http(d, 'GET', `/api/v1/models/${id}/points.glb?budget=2000`)).body);
      const pts = glbPoints(g), segs = glbAttribute(g, '_SEGMENT').values, labels = glbAttribute(g, '_LABEL').values;
      const off = offsetOf(seg);
      const at = new PointIndex();
      for (let i = 0; i < seg.n; i++) at.add([seg.props.x[i] + off[0] - OFF[0], seg.props.y[i] + off[1] - OFF[1], seg.props.z[i] + off[2] - OFF[2]], i);
      for (let j = 0; j < pts.length; j++) {
        const i = at.find(pts[j]);
        assert.ok(i !== null, `shown point ${pts[j]} is not in the cloud`);
        assert.equal(segs[j], seg.props.segment[i]);
        assert.equal(labels[j], seg.props.label[i]);
      }
      models.ply = m;
    } finally {
      await W.close();
    }
  });

  it('ROI refinement and template marking are ops: logged with a report, seen by a second client, undone and redone', async () => {
    const f = facade(60000, 25);
    const { model } = await uploadCloud(d, plyBytes([['x', 'double', f.x], ['y', 'double', f.y], ['z', 'double', f.z]]), { name: 'facade', format: 'ply' });
    const id = model.id;
    const off = model.stats.offset;
    const seg = await waitJob(d, (await http(d, 'POST', `/api/v1/models/${id}/segment`, { body: {}, headers: { 'X-Archgram-User': 'ana' } })).json.id, { timeout: 60000 });
    assert.equal(seg.status, 'succeeded', JSON.stringify(seg.error));
    const A = await WsClient.open(d.wsUrl), B = await WsClient.open(d.wsUrl);
    try {
      await A.request({ type: 'hello', model: id, user: 'ana' }, 'welcome');
      await B.request({ type: 'hello', model: id, user: 'bo' }, 'welcome');
      const s0 = await pointsPly(d, id);
      let version = seg.result.version;
      const send = async (client, cid, op) => {
        const seen = (client === A ? B : A).next((m) => m.type === 'op' && m.cid === cid, 60000, `${cid} at the other client`);
        const reply = await client.request({ type: 'op', base: version, cid, op }, (m) => (m.type === 'ack' || m.type === 'nack') && m.cid === cid, 60000);
        assert.equal(reply.type, 'ack', JSON.stringify(reply));
        const other = await seen;
        assert.equal(other.version, reply.version);
        version = reply.version;
        return other;
      };
      // the wall: the segment with most points; a box around the window at column 2, row 1
      const count = new Map();
      for (const s of s0.props.segment) if (s >= 0) count.set(s, (count.get(s) ?? 0) + 1);
      const wall = [...count.entries()].sort((a, b) => b[1] - a[1])[0][0];
      const around = (c, w, su, sz, sn) => {
        const lo = [Infinity, Infinity, Infinity], hi = [-Infinity, -Infinity, -Infinity];
        const m = f.centre(c, w);
        for (const a of [-1, 1]) for (const b of [-1, 1]) for (const e of [-1, 1]) {
          for (let k = 0; k < 3; k++) {
            const p = m[k] + a * su * f.u[k] + e * sn * f.out[k] + (k === 2 ? b * sz : 0) - off[k];
            lo[k] = Math.min(lo[k], p);
            hi[k] = Math.max(hi[k], p);
          }
        }
        return [...lo, ...hi];
      };
      // ROI: a finer segmentation of one window's surroundings, only there
      const roi = around(4, 2, 1.5, 1.4, 0.5);
      const r1 = await send(A, 'roi-1', { kind: 'segment_roi', box: roi, threshold: 0.005 });
      assert.equal(r1.op.kind, 'segment_roi');
      assert.ok(r1.op.report.inside > 100, JSON.stringify(r1.op.report));
      const s1 = await pointsPly(d, id);
      const so = offsetOf(s1);
      const inBox = (i) => [0, 1, 2].every((k) => {
        const v = [s1.props.x, s1.props.y, s1.props.z][k][i] + so[k] - off[k];
        return v >= roi[k] - 1e-6 && v <= roi[3 + k] + 1e-6;
      });
      // outside the box every point keeps its segment id; inside, the new segments have ids
      // after every id there was
      const ids0 = r1.op.report.segments_before, ids1 = r1.op.report.segment_ids;
      assert.equal(ids0, Math.max(...s0.props.segment) + 1);
      assert.ok(ids1 > ids0, JSON.stringify(r1.op.report));
      let inside = 0;
      for (let i = 0; i < s1.n; i++) {
        if (!inBox(i)) {
          assert.equal(s1.props.segment[i], s0.props.segment[i], `point ${i} outside the box changed segment`);
        } else if (s1.props.segment[i] >= 0) {
          assert.ok(s1.props.segment[i] >= ids0, `point ${i} inside the box is in old segment ${s1.props.segment[i]}`);
          inside++;
        }
      }
      assert.ok(inside > 0);
      // the GLB's figures are the segments with points and the ids, as the report's
      const extras = parseGlb((await http(d, 'GET', `/api/v1/models/${id}/points.glb?budget=100`)).body).json.nodes[0].extras;
      assert.equal(extras.segments, r1.op.report.segments);
      assert.equal(extras.segment_ids, ids1);
      assert.equal(extras.segments, new Set(s1.props.segment.filter((s) => s >= 0)).size);

      // template: the wall around the window at column 1, row 1 (the wall kept its id); its
      // copies are the other windows
      const t = await send(A, 'tmpl-1', { kind: 'mark_template', segment: wall, box: around(1, 1, 1.2, 1.35, 0.5) });
      const rep = t.op.report;
      assert.equal(rep.template_segment, ids1); // the next id, read back from the store's ids

      assert.ok(rep.copies >= 13, JSON.stringify(rep));
      const hit = new Set();
      for (const cb of rep.copy_boxes) {
        const mid = [0, 1, 2].map((k) => 0.5 * (cb.min[k] + cb.max[k]) + off[k]);
        let best = Infinity, which = null;
        for (let c = 0; c < 6; c++) for (let w = 0; w < 3; w++) {
          const m = f.centre(c, w);
          const dd = Math.hypot(...[0, 1, 2].map((k) => mid[k] - m[k]));
          if (dd < best) { best = dd; which = `${c}/${w}`; }
        }
        assert.ok(best < 0.45, `a copy ${best.toFixed(2)} m from window ${which}`);
        assert.notEqual(which, '1/1');
        assert.ok(!hit.has(which), `window ${which} twice`);
        hit.add(which);
      }
      const s2 = await pointsPly(d, id);
      const labelled = new Set();
      for (let i = 0; i < s2.n; i++) if (s2.props.label[i] === rep.label) labelled.add(s2.props.segment[i]);
      assert.equal(labelled.size, rep.copies + 1);
      // every other point keeps its segment and its label; the marked ones have the new ids
      const label1 = new Map();
      for (let i = 0; i < s1.n; i++) if (s1.props.segment[i] >= 0) label1.set(s1.props.segment[i], s1.props.label[i]);
      for (let i = 0; i < s2.n; i++) {
        if (s2.props.segment[i] >= ids1) {
          assert.equal(s1.props.segment[i], wall, `point ${i} came to the template from segment ${s1.props.segment[i]}`);
          assert.equal(s2.props.label[i], rep.label);
        } else {
          assert.equal(s2.props.segment[i], s1.props.segment[i], `point ${i} changed segment`);
          if (s2.props.segment[i] >= 0 && s2.props.segment[i] !== wall) assert.equal(s2.props.label[i], label1.get(s2.props.segment[i]), `the label of segment ${s2.props.segment[i]}`);
        }
      }

      console.log(`# template marking through the service: ${rep.copies} copies of ${rep.template_points} points from ${rep.positions} positions`);
      // the log has both, with their reports
      const log = (await http(d, 'GET', `/api/v1/models/${id}/ops`)).json.items;
      assert.deepEqual(log.slice(-2).map((e) => [e.op.kind, e.author]), [['segment_roi', 'ana'], ['mark_template', 'ana']]);
      // bo has nothing of his own to undo
      const bo = await B.request({ type: 'op', base: version, cid: 'bo-undo', op: { kind: 'undo' } }, (m) => m.cid === 'bo-undo', 60000);
      assert.equal(bo.type, 'nack');
      assert.equal(bo.problem.type, `${PROBLEM}undo-conflict`);
      // ana's undo brings back the segmentation before the template, then before the ROI
      const u1 = await send(A, 'undo-1', { kind: 'undo' });
      assert.equal(u1.op.kind, 'restore');
      assert.deepEqual((await pointsPly(d, id)).props.segment, s1.props.segment);
      assert.deepEqual((await pointsPly(d, id)).props.label, s1.props.label);
      await send(A, 'undo-2', { kind: 'undo' });
      assert.deepEqual((await pointsPly(d, id)).props.segment, s0.props.segment);
      const m = (await http(d, 'GET', `/api/v1/models/${id}`)).json;
      const segmented = (await http(d, 'GET', `/api/v1/models/${id}/ops`)).json.items.find((e) => e.op.kind === 'segment');
      assert.equal(m.stats.segments, segmented.op.report.segments); // the figures come back too
      await send(A, 'redo-1', { kind: 'redo' });
      assert.deepEqual((await pointsPly(d, id)).props.segment, s1.props.segment);
      // ops that do not fit are refused, naming what is wrong
      const bad = async (op, slug, detail) => {
        const x = await A.request({ type: 'op', base: version, cid: `bad-${Math.random()}`, op }, (mm) => mm.type === 'nack' || mm.type === 'ack', 60000);
        assert.equal(x.type, 'nack', JSON.stringify(x));
        assert.equal(x.problem.type, PROBLEM + slug, JSON.stringify(x));
        assert.match(x.problem.detail, detail);
      };
      await bad({ kind: 'segment_roi', box: [1, 1, 1, 0, 2, 2] }, 'invalid', /box/);
      await bad({ kind: 'segment_roi', box: [1e6, 1e6, 1e6, 1e6 + 1, 1e6 + 1, 1e6 + 1] }, 'invalid', /no point of the cloud lies inside/);
      await bad({ kind: 'mark_template', segment: 9999, box: roi }, 'invalid', /segments 0 to/);
      await bad({ kind: 'mark_template', segment: 0, box: roi, report: {} }, 'invalid', /report/);
      // the segment op is the segment job's: a client's is refused, naming the REST call
      await bad({ kind: 'segment' }, 'invalid', /made by the server: POST \/api\/v1\/models\/\{id\}\/segment/);
    } finally {
      await A.close();
      await B.close();
    }
    // on a cloud that is not segmented, or a mesh
    const fresh = models.laz.id;
    let v = (await http(d, 'GET', `/api/v1/models/${fresh}`)).json.version;
    let r = await http(d, 'POST', `/api/v1/models/${fresh}/ops`, { body: { op: { kind: 'segment_roi', box: [0, 0, 0, 1, 1, 1] } }, headers: { 'If-Match': `"${v}"` } });
    assertProblem(r, 409, 'conflict', 'not segmented');
    assert.match(r.json.detail, /not segmented/);
    v = models.mesh.version;
    r = await http(d, 'POST', `/api/v1/models/${models.mesh.id}/ops`, { body: { op: { kind: 'segment_roi', box: [0, 0, 0, 1, 1, 1] } }, headers: { 'If-Match': `"${v}"` } });
    assertProblem(r, 409, 'conflict', 'a mesh');
    assert.match(r.json.detail, /not a point cloud/);
  });

  // (proceduralizing a cloud and editing its point model: points_model.test.js)
  it('tree, grammar and structural edits of a cloud not proceduralized answer precise problems', async () => {
    const id = models.ply.id;
    assertProblem(await http(d, 'GET', `/api/v1/models/${id}/tree`), 404, 'not-found', 'tree');
    assertProblem(await http(d, 'GET', `/api/v1/models/${id}/grammar`), 404, 'not-found', 'grammar');
    const v = (await http(d, 'GET', `/api/v1/models/${id}`)).json.version;
    const r = await http(d, 'POST', `/api/v1/models/${id}/ops`, { body: { op: { kind: 'resize', node: 'root', scale: [2, 1, 1] } }, headers: { 'If-Match': `"${v}"` } });
    assertProblem(r, 409, 'not-proceduralized', 'resize a cloud');
  });

  it('viewers read the points, editors segment', async () => {
    const id = models.las.id;
    const token = await d.makeAccount('vera', 'viewer');
    assert.equal((await http(d, 'PUT', `/api/v1/models/${id}/members/vera`, { body: { role: 'viewer' } })).status, 200);
    assert.equal((await http(d, 'GET', `/api/v1/models/${id}/points.ply`, { token })).status, 200);
    assert.equal((await http(d, 'GET', `/api/v1/models/${id}/points.glb?budget=10`, { token })).status, 200);
    assertProblem(await http(d, 'POST', `/api/v1/models/${id}/segment`, { body: {}, token }), 403, 'forbidden', 'a viewer segments');
    assertProblem(await http(d, 'GET', `/api/v1/models/${models.ply.id}/points.ply`, { token }), 404, 'not-found', 'a model not shared');
  });

  it('the AHN3 crop (640,510 points, LAZ) goes through the service', { skip: !fs.existsSync(path.join(SHARED, 'pointcloud_ahn3_delft')) && 'the shared AHN3 data is absent' }, async () => {
    const laz = fs.readFileSync(path.join(SHARED, 'pointcloud_ahn3_delft', 'ahn3_cropped_1.laz'));
    const t0 = Date.now();
    const { job, model } = await uploadCloud(d, laz, { name: 'ahn3 crop', format: undefined });
    const ms = Date.now() - t0;
    assert.equal(model.stats.points, 640510);
    assert.equal(model.source_format, 'laz');
    assert.ok(model.stats.properties.some((p) => p.name === 'classification'));
    assert.ok(model.stats.offset[0] > 80000 && model.stats.offset[1] > 440000, JSON.stringify(model.stats.offset));
    const g = parseGlb((await http(d, 'GET', `/api/v1/models/${model.id}/points.glb?budget=1000000`, { timeout: 60000 })).body);
    assert.equal(glbAttribute(g, 'POSITION').count, 640510);
    const cls = glbAttribute(g, '_CLASSIFICATION').values;
    assert.ok(cls.filter((c) => c === 6).length > 1000);
    console.log(`# AHN3 crop: upload → stored model in ${ms} ms (job ${job.id}), GLB of every point ${(g.length / 1e6).toFixed(1)} MB`);
  });
});
