// Import an OBJ (raw body and multipart), follow the job, read the model and its GLB.
import assert from 'node:assert/strict';
import { after, before, describe, it } from 'node:test';
import {
  fixture, http, parseGlb, removeDir, startDaemon, upload, waitJob,
} from './harness.js';

// tests/data/http/two_boxes.obj: 13 vertices, 18 triangles, groups walls (12) and roof (6);
// file bounds (y up) x 0..4, y 0..5, z 0..6.
const OBJ = fixture('two_boxes.obj');
const STATS = { vertices: 13, triangles: 18, components: 2, groups: 2 };
const GROUP_TRIANGLES = { walls: 12, roof: 6 };

function near(actual, expected, what) {
  assert.equal(actual.length, expected.length, what);
  for (let i = 0; i < expected.length; i++) {
    assert.ok(Math.abs(actual[i] - expected[i]) < 1e-4, `${what}: got ${JSON.stringify(actual)}, expected ${JSON.stringify(expected)}`);
  }
}

function checkModel(m, id, name) {
  assert.equal(m.id, id);
  assert.equal(m.name, name);
  assert.equal(m.kind, 'mesh');
  assert.ok(Number.isInteger(m.version) && m.version >= 1, `version ${m.version}`);
  assert.equal(m.href, `/api/v1/models/${id}`);
  assert.equal(m.mesh, `/api/v1/models/${id}/mesh.glb`);
  assert.equal(typeof m.created_at, 'string');
  assert.equal(typeof m.updated_at, 'string');
  for (const [k, v] of Object.entries(STATS)) assert.equal(m.stats?.[k], v, `stats.${k}: ${JSON.stringify(m.stats)}`);
}

// GLB positions are y up: (x, z, -y) of archgram's z-up coordinates.
function checkGlb(buf, m, glbMin, glbMax) {
  const g = parseGlb(buf);
  assert.equal(g.magic, 'glTF');
  assert.equal(g.version, 2);
  assert.equal(g.length, buf.length, 'GLB length field');
  assert.equal(g.jsonType, 0x4e4f534a, 'first chunk is JSON');
  assert.ok(g.bin && g.bin.length > 0, 'BIN chunk');
  const j = g.json;
  assert.equal(j.asset?.version, '2.0');
  assert.equal(j.nodes.length, m.stats.components, 'one node per component');
  const comps = j.nodes.map((n) => n.extras?.component).sort();
  assert.deepEqual(comps, [...Array(m.stats.components).keys()], 'extras.component of the nodes');
  const min = [Infinity, Infinity, Infinity];
  const max = [-Infinity, -Infinity, -Infinity];
  let triangles = 0;
  for (const n of j.nodes) {
    assert.ok(Number.isInteger(n.mesh), `node ${JSON.stringify(n)} has no mesh`);
    let t = 0;
    for (const prim of j.meshes[n.mesh].primitives) {
      assert.ok(prim.mode === undefined || prim.mode === 4, 'triangles');
      const pos = j.accessors[prim.attributes.POSITION];
      const count = prim.indices !== undefined ? j.accessors[prim.indices].count : pos.count;
      assert.equal(count % 3, 0);
      t += count / 3;
      // The BIN chunk's floats must agree with the accessor's declared min/max.
      assert.equal(pos.componentType, 5126, 'float positions');
      const view = j.bufferViews[pos.bufferView];
      const at = (view.byteOffset ?? 0) + (pos.byteOffset ?? 0);
      const stride = view.byteStride ?? 12;
      const lo = [Infinity, Infinity, Infinity];
      const hi = [-Infinity, -Infinity, -Infinity];
      for (let v = 0; v < pos.count; v++) {
        for (let k = 0; k < 3; k++) {
          const x = g.bin.readFloatLE(at + v * stride + 4 * k);
          lo[k] = Math.min(lo[k], x);
          hi[k] = Math.max(hi[k], x);
        }
      }
      near(lo, pos.min, 'POSITION min vs BIN data');
      near(hi, pos.max, 'POSITION max vs BIN data');
      // Nodes may carry a translation (positions stored relative to a centre).
      const tr = n.translation ?? [0, 0, 0];
      assert.equal(n.rotation, undefined, 'no node rotation expected');
      assert.equal(n.scale, undefined, 'no node scale expected');
      assert.equal(n.matrix, undefined, 'no node matrix expected');
      for (let k = 0; k < 3; k++) {
        min[k] = Math.min(min[k], pos.min[k] + tr[k]);
        max[k] = Math.max(max[k], pos.max[k] + tr[k]);
      }
    }
    triangles += t;
    assert.ok(n.extras.group in GROUP_TRIANGLES, `extras.group ${n.extras.group}`);
    assert.equal(t, GROUP_TRIANGLES[n.extras.group], `triangles of group ${n.extras.group}`);
  }
  assert.equal(triangles, m.stats.triangles);
  near(min, glbMin, 'GLB position min');
  near(max, glbMax, 'GLB position max');
}

describe('upload and read back', () => {
  let d;
  before(async () => { d = await startDaemon(); });
  after(async () => {
    if (d) { try { await d.stop(); } finally { await d.kill(); removeDir(d.dir); } }
  });

  it('raw OBJ body (z up) → 202 job → succeeded → model, GLB, ETags', async () => {
    const job = await upload(d, OBJ, { name: 'block z', up: 'z' });
    assert.equal(job.kind, 'import');
    assert.ok(['queued', 'running', 'succeeded'].includes(job.status), job.status);
    assert.ok(job.progress >= 0 && job.progress <= 1);
    assert.equal(job.href, `/api/v1/jobs/${job.id}`);

    const done = await waitJob(d, job.id);
    assert.equal(done.status, 'succeeded', JSON.stringify(done));
    assert.equal(done.error, null);
    assert.equal(done.progress, 1);
    assert.ok(Number.isInteger(done.result.model));
    assert.equal(done.result.href, `/api/v1/models/${done.result.model}`);

    const r = await http(d, 'GET', done.result.href);
    assert.equal(r.status, 200, r.text);
    const m = r.json;
    checkModel(m, done.result.model, 'block z');
    // z up: the file's coordinates are kept.
    near(m.stats.bounds.min, [0, 0, 0], 'bounds.min');
    near(m.stats.bounds.max, [4, 5, 6], 'bounds.max');
    assert.equal(r.headers.get('etag'), `"${m.version}"`);

    const g = await http(d, 'GET', m.mesh);
    assert.equal(g.status, 200);
    assert.match(g.headers.get('content-type'), /^model\/gltf-binary/);
    checkGlb(g.body, m, [0, 0, -5], [4, 6, 0]);
    const etag = g.headers.get('etag');
    assert.ok(etag, 'mesh.glb has an ETag');

    const again = await http(d, 'GET', m.mesh, { headers: { 'If-None-Match': etag } });
    assert.equal(again.status, 304);
    assert.equal(again.body.length, 0);
    assert.equal(again.headers.get('etag'), etag);
    const other = await http(d, 'GET', m.mesh, { headers: { 'If-None-Match': '"no-such-tag"' } });
    assert.equal(other.status, 200);
    assert.ok(other.body.equals(g.body), 'same GLB bytes');
  });

  it('default up axis is y: the model comes out z up', async () => {
    const job = await upload(d, OBJ, { name: 'block y' });
    const done = await waitJob(d, job.id);
    assert.equal(done.status, 'succeeded', JSON.stringify(done));
    const m = (await http(d, 'GET', done.result.href)).json;
    checkModel(m, done.result.model, 'block y');
    // (x, y, z) y up → (x, -z, y) z up.
    near(m.stats.bounds.min, [0, -6, 0], 'bounds.min');
    near(m.stats.bounds.max, [4, 0, 5], 'bounds.max');
    const g = await http(d, 'GET', m.mesh);
    assert.equal(g.status, 200);
    checkGlb(g.body, m, [0, 0, 0], [4, 5, 6]);
  });

  it('multipart/form-data upload with file and name parts', async () => {
    const form = new FormData();
    form.append('name', 'from a form');
    form.append('file', new Blob([OBJ], { type: 'model/obj' }), 'two_boxes.obj');
    const r = await http(d, 'POST', '/api/v1/models?format=obj', { body: form });
    assert.equal(r.status, 202, r.text);
    assert.equal(r.headers.get('location'), `/api/v1/jobs/${r.json.id}`);
    const done = await waitJob(d, r.json.id);
    assert.equal(done.status, 'succeeded', JSON.stringify(done));
    const m = (await http(d, 'GET', done.result.href)).json;
    checkModel(m, done.result.model, 'from a form');
  });
});
