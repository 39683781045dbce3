// Uploads never read the server's files: a glTF, GLB, Collada or FBX that names another file
// (by absolute or relative path, or file: URI) fails its import job with a 422
// external-reference problem naming it, and no model is stored; inline data: URIs still
// import; an OBJ's mtllib is ignored (the mesh imports, the library is not opened). The CLI,
// reading the user's own file, resolves the same references next to it.
import assert from 'node:assert/strict';
import { spawnSync } from 'node:child_process';
import fs from 'node:fs';
import path from 'node:path';
import { after, before, describe, it } from 'node:test';
import {
  http, listModels, PROBLEM, REPO, removeDir, startDaemon, tempDir, upload, waitJob,
} from './harness.js';

const CLI = process.env.ARCHGRAM ? path.resolve(process.env.ARCHGRAM) : path.join(REPO, 'build', 'archgram');

// The triangle (0,0,0) (1,0,0) (0,2,0): 9 floats, 3 uint16 indices, padded to 44 bytes.
function triangleBytes() {
  const b = Buffer.alloc(44);
  [0, 0, 0, 1, 0, 0, 0, 2, 0].forEach((v, i) => b.writeFloatLE(v, 4 * i));
  [0, 1, 2].forEach((v, i) => b.writeUInt16LE(v, 36 + 2 * i));
  return b;
}
const DATA_URI = `data:application/octet-stream;base64,${triangleBytes().toString('base64')}`;

// glTF 2: the triangle from buffer `uri`; `image` adds a material textured by that image;
// `glbExtra`: buffer 0 is a GLB's BIN chunk and the indices come from buffer 1 at `uri`.
function gltf2(uri, { image, glbExtra = false } = {}) {
  const g = {
    asset: { version: '2.0' },
    scene: 0,
    scenes: [{ nodes: [0] }],
    nodes: [{ name: 'W', mesh: 0 }],
    meshes: [{ primitives: [{ attributes: { POSITION: 0 }, indices: 1 }] }],
    buffers: glbExtra ? [{ byteLength: 44 }, { byteLength: 44, uri }] : [{ byteLength: 44, uri }],
    bufferViews: [{ buffer: 0, byteOffset: 0, byteLength: 36 },
      { buffer: glbExtra ? 1 : 0, byteOffset: 36, byteLength: 6 }],
    accessors: [
      { bufferView: 0, componentType: 5126, count: 3, type: 'VEC3', min: [0, 0, 0], max: [1, 2, 0] },
      { bufferView: 1, componentType: 5123, count: 3, type: 'SCALAR' }],
  };
  if (image) {
    g.images = [{ uri: image }];
    g.textures = [{ source: 0 }];
    g.materials = [{ pbrMetallicRoughness: { baseColorTexture: { index: 0 } } }];
    g.meshes[0].primitives[0].material = 0;
  }
  return JSON.stringify(g);
}

function glb(uri) {
  let json = Buffer.from(gltf2(uri, { glbExtra: true }));
  json = Buffer.concat([json, Buffer.alloc((4 - (json.length % 4)) % 4, 0x20)]);
  const bin = triangleBytes();
  const head = Buffer.alloc(12);
  head.write('glTF', 0);
  head.writeUInt32LE(2, 4);
  head.writeUInt32LE(12 + 8 + json.length + 8 + bin.length, 8);
  const chunk = (type, data) => {
    const h = Buffer.alloc(8);
    h.writeUInt32LE(data.length, 0);
    h.write(type, 4, 'latin1');
    return Buffer.concat([h, data]);
  };
  return Buffer.concat([head, chunk('JSON', json), chunk('BIN\0', bin)]);
}

function dae(image) {
  return `<?xml version="1.0" encoding="utf-8"?>
<COLLADA xmlns="http://www.collada.org/2005/11/COLLADASchema" version="1.4.1">
<asset><unit name="meter" meter="1"/><up_axis>Z_UP</up_axis></asset>
<library_images><image id="img0"><init_from>${image}</init_from></image></library_images>
<library_effects><effect id="fx"><profile_COMMON>
<newparam sid="surf"><surface type="2D"><init_from>img0</init_from></surface></newparam>
<newparam sid="samp"><sampler2D><source>surf</source></sampler2D></newparam>
<technique sid="common"><lambert><diffuse><texture texture="samp" texcoord="UV0"/></diffuse></lambert></technique>
</profile_COMMON></effect></library_effects>
<library_materials><material id="mat" name="mat"><instance_effect url="#fx"/></material></library_materials>
<library_geometries><geometry id="g" name="g"><mesh>
<source id="g-pos"><float_array id="g-pos-array" count="9">0 0 0 1 0 0 0 2 0</float_array>
<technique_common><accessor source="#g-pos-array" count="3" stride="3"><param name="X" type="float"/><param name="Y" type="float"/><param name="Z" type="float"/></accessor></technique_common></source>
<vertices id="g-vtx"><input semantic="POSITION" source="#g-pos"/></vertices>
<triangles count="1" material="m"><input semantic="VERTEX" source="#g-vtx" offset="0"/><p>0 1 2</p></triangles>
</mesh></geometry></library_geometries>
<library_visual_scenes><visual_scene id="s" name="s"><node id="Door" name="Door"><instance_geometry url="#g"><bind_material><technique_common><instance_material symbol="m" target="#mat"/></technique_common></bind_material></instance_geometry></node></visual_scene></library_visual_scenes>
<scene><instance_visual_scene url="#s"/></scene>
</COLLADA>
`;
}

const obj = (lib) => `# exported\nmtllib ${lib}\nv 0 0 0\nv 1 0 0\nv 0 2 0\nf 1 2 3\n`;

describe('uploads never read the server\'s files', () => {
  let d;
  let dir; // holds tri.bin, a valid buffer: reading it would make an import succeed
  before(async () => {
    d = await startDaemon();
    dir = tempDir();
    fs.writeFileSync(path.join(dir, 'tri.bin'), triangleBytes());
  });
  after(async () => {
    if (d) { try { await d.stop(); } finally { await d.kill(); removeDir(d.dir); } }
    removeDir(dir);
  });

  async function refused(body, format, ref, what) {
    const before = await listModels(d);
    const job = await upload(d, body, { name: what, format });
    const done = await waitJob(d, job.id);
    assert.equal(done.status, 'failed', `${what}: ${JSON.stringify(done)}`);
    assert.equal(done.result, null, what);
    const e = done.error;
    assert.equal(e?.type, `${PROBLEM}external-reference`, `${what}: ${JSON.stringify(e)}`);
    assert.equal(e.status, 422, `${what}: ${JSON.stringify(e)}`);
    assert.ok(e.detail.includes(`"${ref}"`), `${what}: the detail should name "${ref}": ${e.detail}`);
    assert.match(e.detail, /not allowed in an upload/, what);
    const after = await listModels(d);
    assert.deepEqual(after.map((m) => m.id), before.map((m) => m.id), `${what}: a model was created`);
    return e;
  }

  it('a glTF buffer at /etc/passwd → 422 external-reference naming it, no model', async () => {
    await refused(gltf2('/etc/passwd'), 'gltf', '/etc/passwd', 'gltf /etc/passwd');
  });

  it('relative, absolute and file: references to a real, valid buffer are refused too', async () => {
    const abs = path.join(dir, 'tri.bin');
    await refused(gltf2('../../etc/passwd'), 'gltf', '../../etc/passwd', 'gltf ../../etc/passwd');
    await refused(gltf2(abs), 'gltf', abs, 'gltf absolute');
    await refused(gltf2(`file://${abs}`), 'gltf', `file://${abs}`, 'gltf file: URI');
    await refused(glb(abs), 'glb', abs, 'glb second buffer');
    await refused(gltf2(DATA_URI, { image: '../textures/wall.png' }), 'gltf', '../textures/wall.png', 'gltf image');
  });

  // The probe: a file whose access time lies before its change time, which the kernel
  // (relatime) moves forward on the next read of it. The test reads it once itself to show the
  // probe sees a read; the server's import must leave it where it was.
  function accessProbe(name) {
    const file = path.join(dir, name);
    fs.writeFileSync(file, 'newmtl probe\nKd 1 0 0\n');
    const reset = () => fs.utimesSync(file, new Date('2001-01-01T00:00:00Z'), new Date());
    const atime = () => fs.statSync(file).atimeMs;
    reset();
    const before = atime();
    fs.readFileSync(file);
    assert.notEqual(atime(), before, 'the probe must see a read (access times recorded here)');
    reset();
    return { file, untouched: () => atime() === before };
  }

  it('an OBJ mtllib is ignored: the mesh imports and the named file is never opened', async () => {
    const probe = accessProbe('lib.mtl');
    const rel = path.relative(d.dir, probe.file); // from the daemon's working folder: ../..
    for (const [what, lib] of [['absolute', probe.file], ['relative', rel],
      ['etc/passwd', '../../etc/passwd'], ['absolute system file', '/etc/passwd']]) {
      const job = await upload(d, obj(lib), { name: `mtllib ${what}`, format: 'obj' });
      const done = await waitJob(d, job.id);
      assert.equal(done.status, 'succeeded', `${what}: ${JSON.stringify(done)}`);
      const m = (await http(d, 'GET', done.result.href)).json;
      assert.equal(m.stats.triangles, 1, what);
      assert.equal(m.stats.vertices, 3, what);
      assert.ok(probe.untouched(), `${what}: the server read ${probe.file}`);
    }
  });

  it('a Collada file with an external image → 422 naming it', async () => {
    await refused(dae('/etc/passwd'), 'dae', '/etc/passwd', 'dae image');
    await refused(dae('file:///etc/shadow'), 'dae', '/etc/shadow', 'dae file: image');
  });

  it('a glTF with its buffer as a data: URI still imports', async () => {
    const job = await upload(d, gltf2(DATA_URI), { name: 'inline', format: 'gltf' });
    const done = await waitJob(d, job.id);
    assert.equal(done.status, 'succeeded', JSON.stringify(done));
    const m = (await http(d, 'GET', done.result.href)).json;
    assert.equal(m.stats.triangles, 1);
    assert.equal(m.stats.vertices, 3);
    // glTF is y up: the triangle's height 2 ends up along z
    assert.deepEqual(m.stats.bounds.max.map((v) => Math.round(v * 1e6) / 1e6 + 0), [1, 0, 2]);
    const g = await http(d, 'GET', m.mesh);
    assert.equal(g.status, 200);
  });

  it('the CLI reading a local file resolves its buffer next to it', () => {
    const file = path.join(dir, 'local.gltf');
    fs.writeFileSync(file, gltf2('tri.bin'));
    // from another working directory: the reference is relative to the file
    const r = spawnSync(CLI, ['info', file, '--json'], { encoding: 'utf8', timeout: 20000, cwd: REPO });
    assert.equal(r.status, 0, r.stderr);
    const info = JSON.parse(r.stdout);
    assert.equal(info.triangles, 1);
    const missing = path.join(dir, 'missing.gltf');
    fs.writeFileSync(missing, gltf2('no-such.bin'));
    const bad = spawnSync(CLI, ['info', missing], { encoding: 'utf8', timeout: 20000, cwd: REPO });
    assert.equal(bad.status, 1);
    assert.ok(bad.stderr.includes(missing), bad.stderr);
  });
});
