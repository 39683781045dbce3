// `archgram part save | compose | info` on generated buildings, as a pipeline runs them.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { spawnSync } from 'node:child_process';
import fs from 'node:fs';
import path from 'node:path';
import { REPO, tempDir, removeDir, windowWallObj } from './harness.js';

const CLI = process.env.ARCHGRAM ? path.resolve(process.env.ARCHGRAM) : path.join(REPO, 'build', 'archgram');
const run = (...args) => spawnSync(CLI, args, { encoding: 'utf8', timeout: 60000 });

function proceduralized(dir, name, opt) {
  const { obj, slots } = windowWallObj(opt);
  const file = path.join(dir, `${name}.obj`);
  fs.writeFileSync(file, obj);
  const out = path.join(dir, name);
  const r = run('proceduralize', file, '--up', 'z', '--out', out);
  assert.equal(r.status, 0, r.stderr);
  const tree = JSON.parse(fs.readFileSync(path.join(out, 'tree.json'), 'utf8'));
  const near = (a, b) => a.every((x, i) => Math.abs(x - b[i]) < 1e-6);
  const nodeOf = (slot) => tree.nodes.find((nd) => nd.kind === 'component' && near(nd.box, slot)).id;
  return { out, slots, nodeOf };
}

test('a window saved from one building replaces every window of another', () => {
  const dir = tempDir();
  try {
    const a = proceduralized(dir, 'a', { cols: 3, rows: 2, ww: 1.2, wh: 1.8, frame: 0.08, mullions: 1 });
    const b = proceduralized(dir, 'b', { cols: 4, rows: 2, ww: 1.6, wh: 2.0, frame: 0.12, mullions: 2 });
    const bundle = path.join(dir, 'window.agpart');
    let r = run('part', 'save', a.out, '--node', String(a.nodeOf(a.slots[1])), '--name', 'sash window',
      '--tag', 'window', '--tag', 'timber', '--description', 'one mullion', '--out', bundle);
    assert.equal(r.status, 0, r.stderr);
    const doc = JSON.parse(fs.readFileSync(bundle, 'utf8'));
    assert.equal(doc.format, 'archgram-part-bundle');
    assert.deepEqual(doc.parts[0].tags, ['window', 'timber']);
    assert.equal(doc.parts[0].provenance.source, 'a');
    r = run('part', 'info', bundle);
    assert.equal(r.status, 0, r.stderr);
    assert.match(r.stdout, /sash window \(version 1\): one mullion/);
    r = run('part', 'info', bundle, '--json');
    assert.equal(JSON.parse(r.stdout)[0].visible, 7);

    const out = path.join(dir, 'b2');
    r = run('part', 'compose', b.out, '--part', bundle, '--target', String(b.nodeOf(b.slots[3])),
      '--mode', 'replace', '--scope', 'rule', '--out', out);
    assert.equal(r.status, 0, r.stderr);
    const summary = JSON.parse(fs.readFileSync(path.join(out, 'summary.json'), 'utf8'));
    assert.equal(summary.instances, b.slots.length);
    assert.equal(summary.op.scope, 'rule');
    // canonical text, and it derives: the windows' pieces are A's (7 per slot), fitted
    const fmt = run('fmt', path.join(out, 'grammar.txt'));
    assert.equal(fmt.status, 0, fmt.stderr);
    assert.equal(fmt.stdout, fs.readFileSync(path.join(out, 'grammar.txt'), 'utf8'));
    const tree = JSON.parse(fs.readFileSync(path.join(out, 'tree.json'), 'utf8'));
    const inSlot = (nd, s) => nd.box.every((x, i) => (i < 3 ? x >= s[i] - 1e-6 : x <= s[i] + 1e-6));
    for (const s of b.slots) {
      const pieces = tree.nodes.filter((nd) => nd.kind === 'component' && inSlot(nd, s));
      assert.equal(pieces.length, 7);
      const jambs = pieces.filter((nd) => Math.abs(nd.box[3] - nd.box[0] - 0.08) < 1e-6);
      assert.equal(jambs.length, 2); // the frame keeps its 0.08 m in the 1.6 m slot
    }
    // and it can be edited and composed again: node ids are those of its tree.json
    r = run('part', 'compose', out, '--part', bundle, '--target', String(tree.nodes.find((nd) => nd.kind === 'component' && inSlot(nd, b.slots[0])).id),
      '--mode', 'replace', '--out', path.join(dir, 'b3'));
    assert.equal(r.status, 0, r.stderr);
  } finally {
    removeDir(dir);
  }
});

test('bad bundles and bad arguments are refused and write nothing', () => {
  const dir = tempDir();
  try {
    const a = proceduralized(dir, 'a', { cols: 2, rows: 1, ww: 1.2, wh: 1.8, frame: 0.08, mullions: 1 });
    const bundle = path.join(dir, 'w.agpart');
    let r = run('part', 'save', a.out, '--node', String(a.nodeOf(a.slots[0])), '--name', 'w', '--out', bundle);
    assert.equal(r.status, 0, r.stderr);
    const doc = JSON.parse(fs.readFileSync(bundle, 'utf8'));
    const bad = path.join(dir, 'bad.agpart');
    const out = path.join(dir, 'never');
    const compose = (file) => run('part', 'compose', a.out, '--part', file, '--target', '1', '--mode', 'replace', '--out', out);

    fs.writeFileSync(bad, JSON.stringify(doc).slice(0, 200));
    r = compose(bad);
    assert.equal(r.status, 1);
    assert.match(r.stderr, /bad\.agpart: bundle: line 1 column \d+/);

    const missing = structuredClone(doc);
    const key = Object.keys(missing.terminals)[0];
    delete missing.terminals[key];
    fs.writeFileSync(bad, JSON.stringify(missing));
    r = compose(bad);
    assert.equal(r.status, 1);
    assert.match(r.stderr, new RegExp(`parts\\[0\\]\\.grammar: terminal '\\w+' needs terminals\\.${key}`));
    assert.equal(fs.existsSync(out), false);

    r = run('part', 'compose', a.out, '--part', bundle, '--target', '99999', '--mode', 'replace', '--out', out);
    assert.equal(r.status, 1);
    assert.match(r.stderr, /99999/);
    assert.equal(fs.existsSync(out), false);

    r = run('part', 'save', a.out, '--node', 'x7', '--name', 'w', '--out', path.join(dir, 'x.agpart'));
    assert.equal(r.status, 2);
    r = run('part', 'compose', a.out, '--part', bundle, '--target', '1', '--mode', 'sideways', '--out', out);
    assert.equal(r.status, 2);
    r = run('part', 'save', a.out, '--node', '99999', '--name', 'w', '--out', path.join(dir, 'y.agpart'));
    assert.equal(r.status, 1);
    assert.equal(fs.existsSync(path.join(dir, 'y.agpart')), false);
  } finally {
    removeDir(dir);
  }
});

// A georeferenced model (web-mercator reaches 2e7 m): the part it saves is the same file
// `part info` and `part compose` read; past the bound every bundle reader keeps, save refuses
// naming the coordinate and writes nothing.
test('a part saved 2e7 m from the origin reads back and composes; past 1e8 m save refuses', () => {
  const dir = tempDir();
  try {
    const origin = [2.0e7, -1.5e7, 40];
    const win = { ww: 1.2, wh: 1.8, frame: 0.08, mullions: 1, origin };
    const a = proceduralized(dir, 'a', { cols: 2, rows: 1, ...win });
    const b = proceduralized(dir, 'b', { cols: 3, rows: 1, ...win, ww: 1.6 });
    const bundle = path.join(dir, 'far.agpart');
    let r = run('part', 'save', a.out, '--node', String(a.nodeOf(a.slots[0])), '--name', 'far', '--out', bundle);
    assert.equal(r.status, 0, r.stderr);
    const doc = JSON.parse(fs.readFileSync(bundle, 'utf8'));
    // the box is where the window stood, checked against the wall's own slot
    doc.parts[0].box.forEach((x, i) => assert.ok(Math.abs(x - a.slots[0][i]) < 1e-6, `box[${i}] ${x}`));
    r = run('part', 'info', bundle, '--json');
    assert.equal(r.status, 0, r.stderr);
    assert.equal(JSON.parse(r.stdout)[0].visible, 7);
    const out = path.join(dir, 'b2');
    r = run('part', 'compose', b.out, '--part', bundle, '--target', String(b.nodeOf(b.slots[1])),
      '--mode', 'replace', '--scope', 'rule', '--out', out);
    assert.equal(r.status, 0, r.stderr);
    const tree = JSON.parse(fs.readFileSync(path.join(out, 'tree.json'), 'utf8'));
    const inSlot = (nd, s) => nd.box.every((x, i) => (i < 3 ? x >= s[i] - 1e-6 : x <= s[i] + 1e-6));
    for (const s of b.slots)
      assert.equal(tree.nodes.filter((nd) => nd.kind === 'component' && inSlot(nd, s)).length, 7);

    const c = proceduralized(dir, 'c', { cols: 2, rows: 1, ...win, origin: [1.5e8, 0, 0] });
    const refused = path.join(dir, 'beyond.agpart');
    r = run('part', 'save', c.out, '--node', String(c.nodeOf(c.slots[0])), '--name', 'beyond', '--out', refused);
    assert.equal(r.status, 1, r.stderr);
    assert.match(r.stderr, /box: min x = 150000000\.9 m is beyond the \+-1e\+08 m a part can hold/);
    assert.equal(fs.existsSync(refused), false);
  } finally {
    removeDir(dir);
  }
});
