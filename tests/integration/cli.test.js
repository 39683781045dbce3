// The archgram command-line tool, run as a pipeline would: exit codes, messages, outputs.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { spawnSync } from 'node:child_process';
import fs from 'node:fs';
import path from 'node:path';
import { REPO, DATA, tempDir, removeDir } from './harness.js';

const CLI = process.env.ARCHGRAM ? path.resolve(process.env.ARCHGRAM) : path.join(REPO, 'build', 'archgram');
const run = (...args) => spawnSync(CLI, args, { encoding: 'utf8', timeout: 20000 });

test('info --json reports the counts of an OBJ file', () => {
  const r = run('info', path.join(DATA, 'two_boxes.obj'), '--json');
  assert.equal(r.status, 0, r.stderr);
  const info = JSON.parse(r.stdout);
  assert.equal(info.vertices, 13);
  assert.equal(info.triangles, 18);
  assert.equal(info.components, 2);
  assert.deepEqual(info.group_names, ['walls', 'roof']);
  assert.equal(info.bounds.min.length, 3);
});

test('a malformed file fails with file:line: message and exit 1', () => {
  const file = path.join(DATA, 'bad_index_line5.obj');
  const r = run('info', file);
  assert.equal(r.status, 1);
  assert.match(r.stderr, new RegExp(`${file.replace(/[.*+?^${}()|[\]\\]/g, '\\$&')}:5: face index`));
});

// assimp aborts on a PLY face without corners and segfaults on a Collada scene that instances
// itself: the CLI reads such files as the service does (in a child process, after its own PLY
// check), so every command that reads a mesh refuses them with a message and exit 1.
test('a file that would crash the importer fails with file: message and exit 1', () => {
  const dir = tempDir();
  try {
    const ply = path.join(dir, 'no_corners.ply');
    fs.writeFileSync(ply, 'ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n' +
      'property float y\nproperty float z\nelement face 2\nproperty list uchar int vertex_indices\n' +
      'end_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n0\n');
    const dae = path.join(REPO, 'tests', 'data', 'import_sandbox', 'recursive_scene.dae');
    const cases = [[ply, /no_corners\.ply:14: face 2 has no corners/],
      [dae, /recursive_scene\.dae: the importer crashed on this file/]];
    for (const [file, want] of cases) {
      for (const args of [['info', file], ['convert', file, path.join(dir, 'out.glb')],
        ['proceduralize', file, '--out', path.join(dir, 'out')]]) {
        const r = run(...args);
        assert.equal(r.signal, null, `${args.join(' ')}: killed by ${r.signal}`);
        assert.equal(r.status, 1, `${args.join(' ')}: ${r.stderr}`);
        assert.match(r.stderr, want, args.join(' '));
      }
    }
  } finally {
    removeDir(dir);
  }
});

test('convert writes a GLB that starts with the glTF header, and an OBJ that reads back the same', () => {
  const dir = tempDir();
  try {
    const glb = path.join(dir, 'out.glb');
    let r = run('convert', path.join(DATA, 'two_boxes.obj'), glb);
    assert.equal(r.status, 0, r.stderr);
    const bytes = fs.readFileSync(glb);
    assert.equal(bytes.toString('latin1', 0, 4), 'glTF');
    assert.equal(bytes.readUInt32LE(4), 2);
    assert.equal(bytes.readUInt32LE(8), bytes.length);

    const obj = path.join(dir, 'out.obj');
    r = run('convert', path.join(DATA, 'two_boxes.obj'), obj);
    assert.equal(r.status, 0, r.stderr);
    const again = JSON.parse(run('info', obj, '--json').stdout);
    assert.equal(again.triangles, 18);
    assert.equal(again.components, 2);
  } finally {
    removeDir(dir);
  }
});

test('usage errors exit 2 and say what is wrong', () => {
  let r = run('convert');
  assert.equal(r.status, 2);
  assert.match(r.stderr, /usage: archgram convert/);
  r = run('frob');
  assert.equal(r.status, 2);
  assert.match(r.stderr, /unknown command 'frob'/);
  r = run('convert', path.join(DATA, 'two_boxes.obj'), '/tmp/x.stl');
  assert.notEqual(r.status, 0);
  assert.match(r.stderr, /\.obj or \.glb|stl/i);
});
