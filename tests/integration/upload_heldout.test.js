// What the held-out sweep (tests/heldout/service_sweep.js) found in the upload path: a file
// read in the import sandbox (PLY, STL, glTF, ...) reports the up axis its content decided,
// not an empty "convention" verdict; an STL without ?format= is recognised (ASCII, and binary
// whose header begins with "solid"). Geometry is checked against the generated input.
import assert from 'node:assert/strict';
import { after, before, describe, it } from 'node:test';
import { http, removeDir, startDaemon, waitJob } from './harness.js';
import { building, measure, plyText, stlAscii, stlBinary, yUp } from '../heldout/generate.js';

async function post(d, body, format) {
  const q = new URLSearchParams({ name: 'held-out' });
  if (format) q.set('format', format);
  const res = await http(d, 'POST', `/api/v1/models?${q}`, { body, headers: { 'Content-Type': 'application/octet-stream' }, timeout: 60000 });
  assert.equal(res.status, 202, res.text);
  const done = await waitJob(d, res.json.id, { timeout: 60000 });
  assert.equal(done.status, 'succeeded', JSON.stringify(done));
  return (await http(d, 'GET', done.result.href)).json;
}

describe('held-out uploads', () => {
  let d;
  before(async () => { d = await startDaemon(); });
  after(async () => {
    if (d) { try { await d.stop(); } finally { await d.kill(); removeDir(d.dir); } }
  });

  it('a PLY read in the sandbox reports the axis its content decided, with the evidence', async () => {
    const B = building(); // z up: 20 x 10 m, 13 m high with its roof
    for (const [mesh, axis] of [[B, 'z'], [yUp(B), 'y']]) {
      const model = await post(d, plyText(mesh, { format: 'binary_little_endian' }), 'ply');
      assert.equal(model.up.axis, axis, JSON.stringify(model.up));
      assert.equal(model.up.decided, 'content', JSON.stringify(model.up));
      assert.ok(Math.abs(model.up.evidence.score) > 0.1, JSON.stringify(model.up));
      // turned z up either way: 13 m along z (the bounds the service stored)
      const b = model.stats.bounds;
      assert.ok(Math.abs(b.max[2] - b.min[2] - 13) < 1e-5, JSON.stringify(b));
    }
  });

  it('an STL without ?format= is recognised: ASCII, binary, binary with a "solid" header', async () => {
    const B = building();
    const want = measure(B.v, B.f);
    for (const body of [stlAscii(B), stlBinary(B, false), stlBinary(B, true)]) {
      const model = await post(d, body, undefined);
      assert.equal(model.stats.triangles, 162);
      const b = model.stats.bounds;
      [0, 1, 2].forEach((k) => assert.ok(Math.abs(b.max[k] - b.min[k] - want.extent[k]) < 1e-5, JSON.stringify(b)));
    }
  });
});
