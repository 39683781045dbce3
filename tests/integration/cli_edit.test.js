// `archgram proceduralize` then `archgram edit` on a generated facade, as a pipeline runs them.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { spawnSync } from 'node:child_process';
import fs from 'node:fs';
import path from 'node:path';
import { REPO, tempDir, removeDir } from './harness.js';

const CLI = process.env.ARCHGRAM ? path.resolve(process.env.ARCHGRAM) : path.join(REPO, 'build', 'archgram');
const run = (...args) => spawnSync(CLI, args, { encoding: 'utf8', timeout: 60000 });

// A 12 m wall with a row of six 1 m windows in front of it, each part its own OBJ group.
function facadeObj() {
  const out = [];
  let nv = 0;
  const box = (name, a, b) => {
    out.push(`g ${name}`);
    for (let i = 0; i < 8; i++) {
      out.push(`v ${i & 1 ? b[0] : a[0]} ${i & 2 ? b[1] : a[1]} ${i & 4 ? b[2] : a[2]}`);
    }
    const faces = [[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]];
    for (const [p, q, r, s] of faces) {
      out.push(`f ${nv + p + 1} ${nv + q + 1} ${nv + r + 1}`, `f ${nv + p + 1} ${nv + r + 1} ${nv + s + 1}`);
    }
    nv += 8;
  };
  box('wall', [0, 0, 0], [12, 3, 0.3]);
  for (let i = 0; i < 6; i++) box(`window_${i}`, [0.5 + 2 * i, 1, -0.1], [1.5 + 2 * i, 2.2, 0]);
  return out.join('\n') + '\n';
}

// An 8 m wall on a plinth, no windows.
function bareWallObj() {
  const [wall] = facadeObj().split('\ng window_0');
  const plinth = ['g plinth'];
  for (let i = 0; i < 8; i++) plinth.push(`v ${i & 1 ? 8 : 0} ${i & 2 ? 0.2 : 0} ${i & 4 ? 0 : -0.4}`);
  const faces = [[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]];
  for (const [p, q, r, s] of faces) plinth.push(`f ${9 + p} ${9 + q} ${9 + r}`, `f ${9 + p} ${9 + r} ${9 + s}`);
  return `${wall.replace(/^v 12 /gm, 'v 8 ')}\n${plinth.join('\n')}\n`;
}

function proceduralized(dir) {
  const obj = path.join(dir, 'facade.obj');
  fs.writeFileSync(obj, facadeObj());
  const r = run('proceduralize', obj, '--out', path.join(dir, 'p'));
  assert.equal(r.status, 0, r.stderr);
  return path.join(dir, 'p');
}

function edit(dir, from, op, name) {
  const opFile = path.join(dir, `${name}.json`);
  fs.writeFileSync(opFile, JSON.stringify(op));
  const out = path.join(dir, name);
  const r = run('edit', from, '--op', opFile, '--out', out);
  return { r, out, summary: r.status === 0 ? JSON.parse(fs.readFileSync(path.join(out, 'summary.json'), 'utf8')) : null };
}

const windowLabel = (tree) => {
  const counts = {};
  for (const n of tree.nodes) if (n.label) counts[n.label] = (counts[n.label] || 0) + 1;
  // the windows are the most numerous label (a stretched wall may become two walls)
  return Object.keys(counts).sort((a, b) => counts[b] - counts[a])[0];
};

test('proceduralize writes tree.json whose ids edit ops can name', () => {
  const dir = tempDir();
  try {
    const p = proceduralized(dir);
    const tree = JSON.parse(fs.readFileSync(path.join(p, 'tree.json'), 'utf8'));
    assert.equal(typeof tree.root, 'number');
    const label = windowLabel(tree);
    assert.ok(label, 'the six windows share a label');
    assert.equal(tree.nodes.filter((n) => n.label === label).length, 6);
  } finally {
    removeDir(dir);
  }
});

test('stretching the facade to 2x gives about twelve windows of the original width', () => {
  const dir = tempDir();
  try {
    const p = proceduralized(dir);
    const { r, out, summary } = edit(dir, p, { kind: 'resize', node: 'root', scale: [2, 1, 1] }, 'wide');
    assert.equal(r.status, 0, r.stderr);
    assert.ok(summary.splits > 0);
    const tree = JSON.parse(fs.readFileSync(path.join(out, 'tree.json'), 'utf8'));
    const label = windowLabel(tree);
    const windows = tree.nodes.filter((n) => n.label === label);
    assert.ok(windows.length >= 11 && windows.length <= 13, `${windows.length} windows`);
    assert.equal(summary.instances_per_label[label], windows.length);
    for (const w of windows) {
      const width = w.box[3] - w.box[0];
      assert.ok(width > 0.85 && width < 1.15, `window width ${width}`);
    }
    // the edited model is itself editable: squeezing it back joins
    const back = edit(dir, out, { kind: 'resize', node: 'root', scale: [0.5, 1, 1] }, 'back');
    assert.equal(back.r.status, 0, back.r.stderr);
    assert.ok(back.summary.joins > 0, JSON.stringify(back.summary));
    assert.ok(fs.readFileSync(path.join(back.out, 'grammar.txt'), 'utf8').startsWith('archgram-grammar 1'));
    const again = run('fmt', path.join(back.out, 'grammar.txt'));
    assert.equal(again.status, 0, again.stderr);
  } finally {
    removeDir(dir);
  }
});

test('a local window resize solves attachments and keeps them to 1e-6 of the diagonal', () => {
  const dir = tempDir();
  try {
    const p = proceduralized(dir);
    const tree = JSON.parse(fs.readFileSync(path.join(p, 'tree.json'), 'utf8'));
    const w = tree.nodes.find((n) => n.label === windowLabel(tree));
    const box = [...w.box];
    box[5] += 0.2; // taller window
    const { r, summary } = edit(dir, p, { kind: 'resize', node: w.id, box, mode: 'local' }, 'tall');
    assert.equal(r.status, 0, r.stderr);
    assert.ok(summary.equations > 0 && summary.unknowns > 0);
    assert.ok(summary.max_residual_relative <= 1e-6, `residual ${summary.max_residual_relative}`);
    assert.equal(typeof summary.solve_ms, 'number');
  } finally {
    removeDir(dir);
  }
});

test('a malformed op fails naming its field, and an unknown node names the node', () => {
  const dir = tempDir();
  try {
    const p = proceduralized(dir);
    let { r } = edit(dir, p, { kind: 'resize', node: 1, scale: [2, 1] }, 'bad');
    assert.notEqual(r.status, 0);
    assert.match(r.stderr, /bad\.json: scale:/);
    assert.ok(!fs.existsSync(path.join(dir, 'bad', 'grammar.txt')));
    ({ r } = edit(dir, p, { kind: 'remove', nodes: [9999] }, 'gone'));
    assert.notEqual(r.status, 0);
    assert.match(r.stderr, /9999/);
  } finally {
    removeDir(dir);
  }
});

test('a paste from another proceduralized folder (source_dir) copies its window into this wall', () => {
  const dir = tempDir();
  try {
    const a = proceduralized(dir); // the facade with six windows
    // model B: a bare 8 m wall on a plinth, in its own folder
    const bdir = path.join(dir, 'b');
    fs.mkdirSync(bdir);
    const bobj = path.join(bdir, 'bare.obj');
    fs.writeFileSync(bobj, bareWallObj());
    const rb = run('proceduralize', bobj, '--out', path.join(bdir, 'p'));
    assert.equal(rb.status, 0, rb.stderr);
    const b = path.join(bdir, 'p');
    const treeA = JSON.parse(fs.readFileSync(path.join(a, 'tree.json'), 'utf8'));
    const treeB = JSON.parse(fs.readFileSync(path.join(b, 'tree.json'), 'utf8'));
    const grammarA = fs.readFileSync(path.join(a, 'grammar.txt'), 'utf8');
    const win = treeA.nodes.find((n) => n.label === windowLabel(treeA));
    const visibleB = treeB.nodes.filter((n) => n.kind === 'component');
    assert.equal(visibleB.length, 2, 'B is a wall and a plinth');
    const wallB = visibleB.sort((p, q) => (q.box[5] - q.box[2]) - (p.box[5] - p.box[2]))[0];
    // the op file lives in B's folder; source_dir is relative to it
    const opDir = path.join(dir, 'ops');
    fs.mkdirSync(opDir);
    const op = { kind: 'paste', source: [win.id], target: wallB.id, placement: 'insert', fit: 'fill', source_dir: '../p' };
    const opFile = path.join(opDir, 'paste.json');
    fs.writeFileSync(opFile, JSON.stringify(op));
    const out = path.join(dir, 'pasted');
    const r = run('edit', b, '--op', opFile, '--out', out);
    assert.equal(r.status, 0, r.stderr);
    const summary = JSON.parse(fs.readFileSync(path.join(out, 'summary.json'), 'utf8'));
    assert.equal(summary.op.source_dir, '../p');
    const tree = JSON.parse(fs.readFileSync(path.join(out, 'tree.json'), 'utf8'));
    const visible = tree.nodes.filter((n) => n.kind === 'component');
    assert.ok(visible.length >= 2 + 3, `B gained pasted windows: ${visible.length} visible nodes`);
    const total = Object.values(summary.instances_per_label).reduce((x, y) => x + y, 0);
    assert.equal(total, visible.length);
    // the pasted windows have the source window's height and sit on the wall's face
    const wallBox = wallB.box;
    const small = visible.filter((n) => n.box[3] - n.box[0] < 4);
    assert.ok(small.length >= 3, JSON.stringify(visible.map((n) => n.box)));
    for (const n of small) {
      assert.ok(n.box[0] >= wallBox[0] - 1e-6 && n.box[3] <= wallBox[3] + 1e-6, JSON.stringify(n.box));
      assert.ok(Math.abs((n.box[5] - n.box[2]) - (win.box[5] - win.box[2])) < 0.25 * (win.box[5] - win.box[2]) + 1e-6 ||
        n.box[5] - n.box[2] <= wallBox[5] - wallBox[2] + 1e-6, JSON.stringify(n.box));
    }
    // A is only read
    assert.equal(fs.readFileSync(path.join(a, 'grammar.txt'), 'utf8'), grammarA);
    assert.ok(run('fmt', path.join(out, 'grammar.txt')).status === 0);

    // precise errors: a folder that is missing, one that is not proceduralized, an unknown node
    const bad = (o, name) => {
      const f = path.join(opDir, `${name}.json`);
      fs.writeFileSync(f, JSON.stringify(o));
      return run('edit', b, '--op', f, '--out', path.join(dir, name));
    };
    let e = bad({ ...op, source_dir: '../nowhere' }, 'missing');
    assert.notEqual(e.status, 0);
    assert.match(e.stderr, /missing\.json: source_dir: .*nowhere is not a folder/);
    e = bad({ ...op, source_dir: '../b' }, 'plain');
    assert.notEqual(e.status, 0);
    assert.match(e.stderr, /source_dir: .* is not proceduralized/);
    e = bad({ ...op, source: [99999] }, 'unknown');
    assert.notEqual(e.status, 0);
    assert.match(e.stderr, /unknown\.json: .*source.*99999/);
    e = bad({ ...op, source_model: 3, source_dir: undefined }, 'svc');
    assert.notEqual(e.status, 0);
    assert.match(e.stderr, /svc\.json: source_model:/);
  } finally {
    removeDir(dir);
  }
});
