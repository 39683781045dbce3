// Point models through the archgram CLI, as a pipeline runs them: proceduralize a cloud into a
// grammar with PLY terminals (templates, summary.json with stages, counts and completion), derive
// it back into a cloud, edit it (a resize by a box from tree.json doubles the windows of a
// facade), segment --template, the hard-case fixtures and bad grammars with precise errors, the
// CGAL building and every AHN3 building cut from crop 1.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { spawnSync } from 'node:child_process';
import fs from 'node:fs';
import path from 'node:path';
import { REPO, tempDir, removeDir } from './harness.js';
import { ORIGIN, countWindows, windowBox, writeBuilding } from './points_building.js';

const CLI = process.env.ARCHGRAM ? path.resolve(process.env.ARCHGRAM) : path.join(REPO, 'build', 'archgram');
const POINTS = path.join(REPO, 'tests', 'data', 'points');
const SHARED = path.join(REPO, '..', 'shared', 'data');
const run = (...args) => spawnSync(CLI, args, { encoding: 'utf8', timeout: 120000 });

const SIZES = { char: 1, uchar: 1, short: 2, ushort: 2, int: 4, uint: 4, float: 4, double: 8,
  int8: 1, uint8: 1, int16: 2, uint16: 2, int32: 4, uint32: 4, float32: 4, float64: 8 };
const GET = { char: 'getInt8', uchar: 'getUint8', short: 'getInt16', ushort: 'getUint16', int: 'getInt32',
  uint: 'getUint32', float: 'getFloat32', double: 'getFloat64', int8: 'getInt8', uint8: 'getUint8',
  int16: 'getInt16', uint16: 'getUint16', int32: 'getInt32', uint32: 'getUint32', float32: 'getFloat32',
  float64: 'getFloat64' };

// A binary little-endian PLY's vertices with absolute coordinates (the offset comment added).
function readCloud(file) {
  const buf = fs.readFileSync(file);
  const end = buf.indexOf('end_header\n');
  const header = buf.toString('latin1', 0, end).split('\n');
  assert.match(header[1], /binary_little_endian/);
  let n = 0;
  const props = [];
  let offset = [0, 0, 0];
  for (const line of header) {
    const t = line.trim().split(/\s+/);
    if (t[0] === 'element' && t[1] === 'vertex') n = Number(t[2]);
    if (t[0] === 'property') props.push([t[2], t[1]]);
    if (t[0] === 'comment' && t[1] === 'offset') offset = t.slice(2, 5).map(Number);
  }
  const view = new DataView(buf.buffer, buf.byteOffset + end + 11);
  const out = Object.fromEntries(props.map(([name]) => [name, new Float64Array(n)]));
  let at = 0;
  for (let i = 0; i < n; i++) {
    for (const [name, type] of props) {
      out[name][i] = view[GET[type]](at, true);
      at += SIZES[type];
    }
  }
  for (let i = 0; i < n; i++) {
    out.x[i] += offset[0]; out.y[i] += offset[1]; out.z[i] += offset[2];
  }
  return { n, props: out };
}

test('proceduralize, derive and edit a point cloud building with a template', () => {
  const dir = tempDir();
  try {
    const cloud = path.join(dir, 'house.ply');
    writeBuilding(cloud);
    const model = path.join(dir, 'model');
    let r = run('proceduralize', cloud, '--out', model, '--template', windowBox(2), '--no-auto', '--json');
    assert.equal(r.status, 0, r.stderr);
    const out = JSON.parse(r.stdout);
    assert.equal(out.points, 60000);
    const summary = JSON.parse(fs.readFileSync(path.join(model, 'summary.json'), 'utf8'));
    assert.equal(summary.kind, 'pointcloud');
    for (const s of ['segment', 'repeat', 'absorb', 'consensus', 'tree', 'grammar', 'total'])
      assert.equal(typeof summary.seconds[s], 'number', s);
    // the template found the ten windows and their consensus merged them
    assert.equal(summary.repetition.templates.length, 1);
    assert.equal(summary.repetition.templates[0].matches, 10, JSON.stringify(summary.repetition));
    const label = summary.completion.find((c) => c.members === 10);
    assert.ok(label, JSON.stringify(summary.completion));
    assert.ok(label.merged >= 9 && label.points_after > 0, JSON.stringify(label));
    // the grammar names PLY terminals that are there
    const grammar = fs.readFileSync(path.join(model, 'grammar.txt'), 'utf8');
    const names = [...grammar.matchAll(/"(terminals\/[0-9a-f]{16}\.ply)"/g)].map((m) => m[1]);
    assert.ok(names.length >= 5);
    for (const t of names) assert.ok(fs.existsSync(path.join(model, t)), t);
    // derived back into the cloud, in its coordinates
    const derived = path.join(dir, 'derived.ply');
    r = run('derive', path.join(model, 'grammar.txt'), '--out', derived, '--compare', cloud);
    assert.equal(r.status, 0, r.stderr);
    const cover = Number(r.stdout.match(/compared with .*?: ([0-9.]+) of its/)[1]);
    assert.ok(cover >= 0.97, r.stdout);
    const d = readCloud(derived);
    assert.ok(d.n > 55000 && d.n < 66000, String(d.n));
    assert.ok('label' in d.props && 'segment' in d.props);
    assert.equal(countWindows(d), 10);
    // the front wall's node from tree.json (input coordinates), twice as wide
    const tree = JSON.parse(fs.readFileSync(path.join(model, 'tree.json'), 'utf8'));
    const front = tree.nodes.find((nd) => nd.kind === 'component' && nd.box[3] - nd.box[0] > 14 &&
      nd.box[4] - nd.box[1] < 0.6 && Math.abs(nd.box[1] - ORIGIN[1]) < 0.2 && nd.box[5] - nd.box[2] > 6);
    assert.ok(front, 'a front wall node');
    const box = [...front.box];
    box[3] = box[0] + 2 * (box[3] - box[0]);
    const op = path.join(dir, 'op.json');
    fs.writeFileSync(op, JSON.stringify({ kind: 'resize', node: front.id, box }));
    r = run('edit', model, '--op', op, '--out', path.join(dir, 'wide'));
    assert.equal(r.status, 0, r.stderr);
    assert.match(r.stdout, /equations/);
    r = run('derive', path.join(dir, 'wide', 'grammar.txt'), '--out', path.join(dir, 'wide.ply'));
    assert.equal(r.status, 0, r.stderr);
    const w = readCloud(path.join(dir, 'wide.ply'));
    // twice as wide: the far side wall at x = 32, hardly a point past it
    let far = 0, past = 0;
    for (let i = 0; i < w.n; i++) {
      const x = w.props.x[i] - ORIGIN[0], y = w.props.y[i] - ORIGIN[1];
      far += x > 31.8 && x < 32.2 && y > 1 && y < 7;
      past += x > 32.5;
    }
    assert.ok(far > 3000, `${far} points of the far side wall at x = 32`);
    assert.ok(past < 0.01 * w.n, `${past} points past x = 32.5`);
    assert.equal(countWindows(w), 20);
    // the side wall moved with the front's end: nothing is left of it in the middle
    let middle = 0;
    for (let i = 0; i < w.n; i++) {
      const x = w.props.x[i] - ORIGIN[0], y = w.props.y[i] - ORIGIN[1], z = w.props.z[i] - ORIGIN[2];
      middle += x > 15.8 && x < 16.2 && y > 1 && y < 7 && z < 6.8; /* below the roof */
    }
    assert.ok(middle < 50, `${middle} points of a side wall left at x = 16`);
    // a bad node is named
    fs.writeFileSync(op, JSON.stringify({ kind: 'resize', node: 99999, scale: [2, 1, 1] }));
    r = run('edit', model, '--op', op, '--out', path.join(dir, 'bad'));
    assert.equal(r.status, 1);
    assert.match(r.stderr, /op\.json.*node.*99999/);
  } finally {
    removeDir(dir);
  }
});

test('segment --template gives the copies of a window its label', () => {
  const dir = tempDir();
  try {
    const cloud = path.join(dir, 'house.ply');
    const b = writeBuilding(cloud);
    let r = run('segment', cloud, '--out', path.join(dir, 'seg.ply'), '--template', windowBox(7), '--json');
    assert.equal(r.status, 0, r.stderr);
    const s = JSON.parse(r.stdout);
    assert.equal(s.template_matches, 10);
    const seg = readCloud(path.join(dir, 'seg.ply'));
    const tl = new Map();
    for (let i = 0; i < seg.n; i++) if (b.window[i] >= 0) tl.set(seg.props.label[i], (tl.get(seg.props.label[i]) || 0) + 1);
    const top = Math.max(...tl.values());
    const total = b.window.filter((w) => w >= 0).length;
    assert.ok(top >= 0.9 * total, `${top} of ${total}`);
    // a template in the air, a bad box
    r = run('segment', cloud, '--out', path.join(dir, 'x.ply'), '--template', '0,0,100,1,1,101');
    assert.equal(r.status, 1);
    assert.match(r.stderr, /--template 0,0,100,1,1,101: .*point/);
    r = run('segment', cloud, '--out', path.join(dir, 'x.ply'), '--template', '1,2,3');
    assert.equal(r.status, 2);
    assert.match(r.stderr, /--template takes XMIN,YMIN,ZMIN,XMAX,YMAX,ZMAX/);
  } finally {
    removeDir(dir);
  }
});

test('hard clouds and bad point grammars give precise errors', () => {
  const dir = tempDir();
  try {
    let r = run('proceduralize', path.join(POINTS, 'nan.ply'), '--out', path.join(dir, 'n'));
    assert.equal(r.status, 1);
    assert.match(r.stderr, /nan\.ply:10: point 3 has x = nan, not a finite number/);
    r = run('proceduralize', path.join(POINTS, 'empty.ply'), '--out', path.join(dir, 'e'));
    assert.equal(r.status, 1);
    assert.match(r.stderr, /empty\.ply: .*(no points|empty)/i);
    r = run('proceduralize', path.join(POINTS, 'one_point.ply'), '--out', path.join(dir, 'o'));
    assert.equal(r.status, 1);
    assert.match(r.stderr, /one_point\.ply: .*1 point/);
    r = run('proceduralize', path.join(POINTS, 'lying_count.las'), '--out', path.join(dir, 'l'));
    assert.equal(r.status, 1);
    assert.match(r.stderr, /lying_count\.las: the header says 1000 points/);
    // collinear points: a model of the line, or a precise refusal; never a crash
    r = run('proceduralize', path.join(POINTS, 'collinear.xyz'), '--out', path.join(dir, 'c'));
    assert.ok(r.status === 0 || (r.status === 1 && /collinear\.xyz: /.test(r.stderr)), r.stderr);
    // duplicates and huge coordinates make models that derive back in place
    for (const f of ['duplicates.ply', 'huge_coords.xyz']) {
      const m = path.join(dir, f);
      r = run('proceduralize', path.join(POINTS, f), '--out', m);
      assert.equal(r.status, 0, `${f}: ${r.stderr}`);
      r = run('derive', path.join(m, 'grammar.txt'), '--out', path.join(dir, `${f}.ply`), '--compare', path.join(POINTS, f));
      assert.equal(r.status, 0, `${f}: ${r.stderr}`);
      const cover = Number(r.stdout.match(/compared with .*?: ([0-9.]+) of its/)[1]);
      assert.ok(cover >= 0.95, `${f}: ${r.stdout}`);
    }
    // a point grammar whose terminal is missing, leaves its folder, or lies outside its box
    const m = path.join(dir, 'huge_coords.xyz');
    const g = fs.readFileSync(path.join(m, 'grammar.txt'), 'utf8');
    const first = g.match(/"(terminals\/[0-9a-f]{16}\.ply)"/)[1];
    const bad = path.join(dir, 'bad');
    fs.mkdirSync(path.join(bad, 'terminals'), { recursive: true });
    fs.writeFileSync(path.join(bad, 'grammar.txt'), g);
    r = run('derive', path.join(bad, 'grammar.txt'), '--out', path.join(dir, 'b.ply'));
    assert.equal(r.status, 1);
    assert.match(r.stderr, /terminals\/[0-9a-f]{16}\.ply/);
    fs.writeFileSync(path.join(bad, 'grammar.txt'), g.replace(first, '../../etc/passwd.ply'));
    r = run('derive', path.join(bad, 'grammar.txt'), '--out', path.join(dir, 'b.ply'));
    assert.equal(r.status, 1);
    assert.match(r.stderr, /passwd\.ply/);
    for (const t of fs.readdirSync(path.join(m, 'terminals')))
      fs.copyFileSync(path.join(m, 'terminals', t), path.join(bad, 'terminals', t));
    fs.writeFileSync(path.join(bad, 'grammar.txt'), g.replace(/(terminal T1 "[^"]+" size) ([0-9.e+-]+) ([0-9.e+-]+) ([0-9.e+-]+)/,
      (all, head, a, b, c) => `${head} ${Number(a) / 4} ${Number(b) / 4} ${Number(c) / 4}`));
    r = run('derive', path.join(bad, 'grammar.txt'), '--out', path.join(dir, 'b.ply'));
    assert.equal(r.status, 1);
    assert.match(r.stderr, /T1|terminals\//);
  } finally {
    removeDir(dir);
  }
});

test('the CGAL building proceduralizes and derives back', { skip: !fs.existsSync(path.join(SHARED, 'pointcloud_cgal_building')) && 'the shared CGAL data is absent' }, () => {
  const dir = tempDir();
  try {
    const cloud = path.join(SHARED, 'pointcloud_cgal_building', 'building.ply');
    let r = run('proceduralize', cloud, '--out', path.join(dir, 'm'), '--json');
    assert.equal(r.status, 0, r.stderr);
    const out = JSON.parse(r.stdout);
    assert.ok(out.segments >= 19 && out.coverage >= 0.98, r.stdout);
    r = run('derive', path.join(dir, 'm', 'grammar.txt'), '--out', path.join(dir, 'd.ply'), '--compare', cloud);
    assert.equal(r.status, 0, r.stderr);
    assert.ok(Number(r.stdout.match(/compared with .*?: ([0-9.]+) of its/)[1]) >= 0.98, r.stdout);
  } finally {
    removeDir(dir);
  }
});

test('every building cut from AHN3 crop 1 proceduralizes', { skip: !fs.existsSync(path.join(SHARED, 'pointcloud_ahn3_delft')) && 'the shared AHN3 data is absent' }, () => {
  const dir = tempDir();
  try {
    const d = path.join(SHARED, 'pointcloud_ahn3_delft');
    let r = run('cut', path.join(d, 'ahn3_cropped_1.laz'), '--footprints', path.join(d, 'bgt_pand_footprints.geojson'), '--out', path.join(dir, 'cut'));
    assert.equal(r.status, 0, r.stderr);
    const clouds = fs.readdirSync(path.join(dir, 'cut')).filter((f) => f.endsWith('.ply'));
    assert.ok(clouds.length >= 100, String(clouds.length));
    const failed = [];
    let worst = 1;
    for (const f of clouds) {
      r = run('proceduralize', path.join(dir, 'cut', f), '--out', path.join(dir, 'm', f), '--json');
      if (r.status !== 0) { failed.push(`${f}: ${r.stderr}`); continue; }
      worst = Math.min(worst, JSON.parse(r.stdout).coverage);
    }
    assert.deepEqual(failed, []);
    assert.ok(worst >= 0.9, `worst coverage ${worst}`);
  } finally {
    removeDir(dir);
  }
});
