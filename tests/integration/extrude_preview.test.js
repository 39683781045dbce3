// POST /api/v1/extrusions/preview: one building description in, its shell as GLB out, nothing stored.
import assert from 'node:assert/strict';
import fs from 'node:fs';
import path from 'node:path';
import { after, before, describe, it } from 'node:test';
import { assertProblem, http, parseGlb, REPO, removeDir, startDaemon } from './harness.js';

const plan = JSON.parse(fs.readFileSync(path.join(REPO, 'tests', 'data', 'extrude_service', 'hip_plan.json'), 'utf8'));
const post = (d, body) => http(d, 'POST', '/api/v1/extrusions/preview', {
  body: typeof body === 'string' ? body : JSON.stringify(body),
  headers: { 'Content-Type': 'application/json' },
});
// Height of the shell: glTF is y-up and each node is translated to its component's centre,
// so the largest translation.y + POSITION max y over the nodes.
const topOf = (glb) => Math.max(...glb.json.nodes.filter((n) => n.mesh !== undefined).flatMap((n) =>
  glb.json.meshes[n.mesh].primitives.map((p) =>
    (n.translation ? n.translation[1] : 0) + glb.json.accessors[p.attributes.POSITION].max[1])));

describe('extrusion preview', () => {
  let d;
  before(async () => { d = await startDaemon({ args: ['--workers', '1', '--no-web'] }); });
  after(async () => { if (d) { try { await d.stop(); } finally { await d.kill(); removeDir(d.dir); } } });

  it('returns the shell as GLB and stores nothing', async () => {
    const before = (await http(d, 'GET', '/api/v1/models')).json.items.length;
    const r = await post(d, plan);
    assert.equal(r.status, 200, r.text);
    assert.match(r.headers.get('content-type'), /^model\/gltf-binary/);
    const glb = parseGlb(r.body);
    assert.equal(glb.magic, 'glTF');
    assert.ok(glb.bin && glb.bin.length > 0);
    assert.equal((await http(d, 'GET', '/api/v1/models')).json.items.length, before);
  });

  it('follows the plan: a taller wall profile gives a taller shell', async () => {
    const low = parseGlb((await post(d, plan)).body);
    const tall = structuredClone(plan);
    tall.profiles.hip.points = [[0, 0], [0, 6], [1, 7]];
    const high = parseGlb((await post(d, tall)).body);
    assert.ok(Math.abs(topOf(high) - topOf(low) - 3) < 1e-6, `${topOf(low)} → ${topOf(high)}`);
  });

  it('answers 422 with the reason for a self-crossing ring, 400 for an empty or broken body', async () => {
    const bad = structuredClone(plan);
    bad.loops[0].points = [[0, 0], [10, 0], [10, 6], [2, -3], [0, 6]];
    const r = await post(d, bad);
    assertProblem(r, 422, null, 'bowtie');
    assert.match(r.json.detail, /intersect|cross/i);
    assertProblem(await post(d, ''), 400, null, 'empty');
    const broken = await post(d, '{"loops": [');
    assert.ok(broken.status === 400 || broken.status === 422, broken.text);
  });

  it('refuses a description that names mesh files: a client cannot make the server read its disk', async () => {
    const sneaky = structuredClone(plan);
    sneaky.meshes = { win: '/etc/passwd' };
    sneaky.anchors = [{ name: 'a', edge: 0, relative: 0.5, height: 1, mesh: 'win' }];
    const r = await post(d, sneaky);
    assert.ok(r.status === 400 || r.status === 422, r.text);
    assert.match(r.json.detail, /meshes\.win: mesh files can only be named in a plan read from a file/);
  });
});
