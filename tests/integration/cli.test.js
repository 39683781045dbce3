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
