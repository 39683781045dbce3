// The point cloud commands of the archgram CLI, run as a pipeline would: segment, cut, info
// and convert on generated clouds and the hard-case fixtures, exit codes and messages.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { spawnSync } from 'node:child_process';
import fs from 'node:fs';
import path from 'node:path';
import { REPO, tempDir, removeDir } from './harness.js';
import { boxCloud, planesFound, readPly, rng, writePly } from './clouds.js';

const CLI = process.env.ARCHGRAM ? path.resolve(process.env.ARCHGRAM) : path.join(REPO, 'build', 'archgram');
const POINTS = path.join(REPO, 'tests', 'data', 'points');
const SHARED = path.join(REPO, '..', 'shared', 'data');
const run = (...args) => spawnSync(CLI, args, { encoding: 'utf8', timeout: 60000 });

test('segment writes every input point in order with segment, label and the input properties', () => {
  const dir = tempDir();
  try {
    const b = boxCloud(20000);
    const input = path.join(dir, 'box.ply');
    writePly(input, [['x', 'float', b.x], ['y', 'float', b.y], ['z', 'float', b.z],
      ['classification', 'uchar', b.cls], ['plane', 'int', b.plane]]);
    const out = path.join(dir, 'seg.ply');
    const r = run('segment', input, '--out', out, '--json');
    assert.equal(r.status, 0, r.stderr);
    const summary = JSON.parse(r.stdout);
    assert.equal(summary.points, 20000);
    assert.ok(summary.planes >= 5);
    for (const stage of ['index', 'normals', 'coarse', 'refine', 'components', 'cluster', 'label']) {
      assert.equal(typeof summary.seconds[stage], 'number', stage);
    }
    const seg = readPly(out);
    assert.equal(seg.n, 20000);
    assert.equal(seg.types.segment, 'int');
    assert.equal(seg.types.label, 'int');
    for (let i = 0; i < seg.n; i += 97) {
      assert.ok(Math.abs(seg.props.x[i] - b.x[i]) < 1e-5);
      assert.equal(seg.props.classification[i], 6);
      assert.equal(seg.props.plane[i], b.plane[i]);
    }
    assert.equal(planesFound(b.plane, seg.props.segment), 5);
    assert.ok(seg.props.nx, 'normals computed and written');
  } finally {
    removeDir(dir);
  }
});

test('segment --roi and --threshold are checked and applied', () => {
  const dir = tempDir();
  try {
    const b = boxCloud(10000);
    const input = path.join(dir, 'box.ply');
    writePly(input, [['x', 'float', b.x], ['y', 'float', b.y], ['z', 'float', b.z]]);
    let r = run('segment', input, '--out', path.join(dir, 's.ply'), '--roi', '1,2,3');
    assert.equal(r.status, 2);
    assert.match(r.stderr, /--roi takes XMIN,YMIN,ZMIN,XMAX,YMAX,ZMAX/);
    r = run('segment', input, '--out', path.join(dir, 's.ply'), '--threshold', '3');
    assert.equal(r.status, 2);
    assert.match(r.stderr, /fraction of the diagonal/);
    r = run('segment', input, '--out', path.join(dir, 's.obj'));
    assert.equal(r.status, 2);
    r = run('segment', input, '--out', path.join(dir, 's.ply'), '--threshold', '0.005',
      '--roi', '-1,-1,-1,6,9,7');
    assert.equal(r.status, 0, r.stderr);
    const seg = readPly(path.join(dir, 's.ply'));
    assert.equal(seg.n, 10000);
  } finally {
    removeDir(dir);
  }
});

test('bad clouds give precise errors and exit 1, hard cases give sane results', () => {
  const dir = tempDir();
  try {
    let r = run('segment', path.join(POINTS, 'nan.ply'), '--out', path.join(dir, 'x.ply'));
    assert.equal(r.status, 1);
    assert.match(r.stderr, /nan\.ply:10: point 3 has x = nan, not a finite number/);
    r = run('info', path.join(POINTS, 'lying_count.las'));
    assert.equal(r.status, 1);
    assert.match(r.stderr, /lying_count\.las: the header says 1000 points of 28 bytes/);
    for (const f of ['empty.ply', 'one_point.ply', 'collinear.xyz', 'duplicates.ply', 'huge_coords.xyz']) {
      r = run('segment', path.join(POINTS, f), '--out', path.join(dir, `${f}.ply`), '--json');
      assert.equal(r.status, 0, `${f}: ${r.stderr}`);
      const s = JSON.parse(r.stdout);
      const out = readPly(path.join(dir, `${f}.ply`));
      assert.equal(out.n, s.points, f);
    }
    // huge coordinates are written as float plus the offset comment, or as doubles
    r = run('convert', path.join(POINTS, 'huge_coords.xyz'), path.join(dir, 'h.ply'));
    assert.equal(r.status, 0, r.stderr);
    const h = readPly(path.join(dir, 'h.ply'));
    assert.ok(h.comments.includes('offset 548875 4176972 0'), h.comments.join('|'));
    assert.ok(Math.abs(h.props.x[0] + 548875 - 548875.201) < 1e-4);
  } finally {
    removeDir(dir);
  }
});

test('info and convert handle clouds: PLY to LAS and back keeps points and properties', () => {
  const dir = tempDir();
  try {
    const b = boxCloud(3000, [84808, 447412, 0]);
    const input = path.join(dir, 'rd.ply');
    writePly(input, [['x', 'double', b.x], ['y', 'double', b.y], ['z', 'double', b.z],
      ['classification', 'uchar', b.cls], ['plane', 'int', b.plane]]);
    let r = run('info', input, '--json');
    assert.equal(r.status, 0, r.stderr);
    const info = JSON.parse(r.stdout);
    assert.equal(info.kind, 'pointcloud');
    assert.equal(info.points, 3000);
    assert.deepEqual(info.offset, [84808, 447412, 0]);
    assert.ok(info.properties.some((p) => p.name === 'plane' && p.type === 'int32'));
    const las = path.join(dir, 'rd.las');
    r = run('convert', input, las);
    assert.equal(r.status, 0, r.stderr);
    const lasInfo = JSON.parse(run('info', las, '--json').stdout);
    assert.equal(lasInfo.format, 'las');
    assert.equal(lasInfo.points, 3000);
    const back = path.join(dir, 'back.ply');
    r = run('convert', las, back);
    assert.equal(r.status, 0, r.stderr);
    const p = readPly(back);
    assert.equal(p.n, 3000);
    const off = p.comments.find((c) => c.startsWith('offset')).split(' ').slice(1).map(Number);
    for (let i = 0; i < p.n; i += 37) {
      assert.ok(Math.abs(p.props.x[i] + off[0] - b.x[i]) < 2e-3); // LAS millimetres, float
      assert.equal(p.props.classification[i], 6);
      assert.equal(p.props.plane[i], b.plane[i]); // an extra-bytes property
    }
    r = run('convert', las, path.join(dir, 'x.laz'));
    assert.equal(r.status, 2);
    assert.match(r.stderr, /writing LAZ is not supported/);
  } finally {
    removeDir(dir);
  }
});

test('cut writes one cloud per footprint in the tile coordinate system and a report', () => {
  const dir = tempDir();
  try {
    // ground and two buildings at RD New coordinates, with a classification
    const r0 = rng(3);
    const x = [], y = [], z = [], cls = [];
    const O = [85000, 447500];
    for (let i = 0; i < 30000; i++) {
      const k = i % 3;
      if (k === 0) { x.push(O[0] + r0() * 60); y.push(O[1] + r0() * 30); z.push(0.1 * r0()); cls.push(2); continue; }
      const bx = k === 1 ? 10 : 35;
      x.push(O[0] + bx + r0() * 15); y.push(O[1] + 10 + r0() * 10); z.push(7 + r0() * 0.1); cls.push(6);
    }
    const tile = path.join(dir, 'tile.ply');
    writePly(tile, [['x', 'double', x], ['y', 'double', y], ['z', 'double', z], ['classification', 'uchar', cls]]);
    const ring = (bx) => [[O[0] + bx, O[1] + 10], [O[0] + bx + 15, O[1] + 10], [O[0] + bx + 15, O[1] + 20], [O[0] + bx, O[1] + 20], [O[0] + bx, O[1] + 10]];
    const geo = {
      type: 'FeatureCollection',
      features: [
        { type: 'Feature', id: 'west/1', properties: { bag: 'W1' }, geometry: { type: 'Polygon', coordinates: [ring(10)] } },
        { type: 'Feature', id: 'east', properties: { bag: 'E2' }, geometry: { type: 'Polygon', coordinates: [ring(35)] } },
        { type: 'Feature', id: 'empty', properties: { bag: 'X' }, geometry: { type: 'Polygon', coordinates: [ring(100)] } },
      ],
    };
    const fp = path.join(dir, 'fp.geojson');
    fs.writeFileSync(fp, JSON.stringify(geo));
    const out = path.join(dir, 'out');
    let r = run('cut', tile, '--footprints', fp, '--out', out);
    assert.equal(r.status, 0, r.stderr);
    const report = JSON.parse(fs.readFileSync(path.join(out, 'report.json'), 'utf8'));
    assert.equal(report.footprints, 3);
    assert.equal(report.with_points, 2);
    assert.equal(report.ground, 'class');
    assert.deepEqual(report.empty, ['empty']);
    const west = report.buildings.find((b) => b.id === 'west/1');
    assert.equal(west.file, 'west_1.ply'); // a file name never makes a path
    assert.equal(west.points, 10000);
    const w = readPly(path.join(out, 'west_1.ply'));
    assert.equal(w.n, 10000);
    const off = w.comments.find((c) => c.startsWith('offset')).split(' ').slice(1).map(Number);
    for (let i = 0; i < w.n; i++) {
      const ax = w.props.x[i] + off[0];
      assert.ok(ax >= O[0] + 10 - 0.5 && ax <= O[0] + 25.5);
      assert.equal(w.props.classification[i], 6);
    }
    // named by a property, absolute doubles
    r = run('cut', tile, '--footprints', fp, '--out', out, '--id-property', 'bag', '--double');
    assert.equal(r.status, 0, r.stderr);
    const e2 = readPly(path.join(out, 'E2.ply'));
    assert.equal(e2.types.x, 'double');
    assert.ok(e2.props.x[0] > O[0] + 34);
    r = run('cut', tile, '--footprints', path.join(dir, 'missing.geojson'), '--out', out);
    assert.equal(r.status, 1);
    r = run('cut', tile, '--out', out);
    assert.equal(r.status, 2);
  } finally {
    removeDir(dir);
  }
});

test('cut of the AHN3 tile by its BGT footprints', { skip: !fs.existsSync(path.join(SHARED, 'pointcloud_ahn3_delft')) && 'the shared AHN3 data is absent' }, () => {
  const dir = tempDir();
  try {
    const r = run('cut', path.join(SHARED, 'pointcloud_ahn3_delft', 'ahn3_cropped_1.laz'), '--footprints',
      path.join(SHARED, 'pointcloud_ahn3_delft', 'bgt_pand_footprints.geojson'), '--out', dir,
      '--id-property', 'identificatiebagpnd');
    assert.equal(r.status, 0, r.stderr);
    const report = JSON.parse(fs.readFileSync(path.join(dir, 'report.json'), 'utf8'));
    assert.equal(report.points, 640510);
    assert.equal(report.footprints, 160);
    assert.equal(report.ground, 'class');
    assert.ok(report.with_points >= 130);
    let share = 0, total = 0;
    for (const b of report.buildings.slice(0, 20)) {
      const p = readPly(path.join(dir, b.file));
      assert.equal(p.n, b.points);
      total += p.n;
      share += p.props.classification.filter((c) => c === 6).length;
    }
    assert.ok(share / total >= 0.95, `${share} of ${total} class 6`);
  } finally {
    removeDir(dir);
  }
});

test('segment on the CGAL building finds its labelled planes', { skip: !fs.existsSync(path.join(SHARED, 'pointcloud_cgal_building')) && 'the shared CGAL data is absent' }, () => {
  const dir = tempDir();
  try {
    const out = path.join(dir, 'seg.ply');
    const r = run('segment', path.join(SHARED, 'pointcloud_cgal_building', 'building.ply'), '--out', out);
    assert.equal(r.status, 0, r.stderr);
    const seg = readPly(out);
    assert.equal(seg.n, 100000);
    const found = planesFound(seg.props.segment_index, seg.props.segment);
    const labelled = new Set(seg.props.segment_index.filter((t) => t >= 0)).size;
    assert.equal(labelled, 19);
    assert.ok(found >= 17, `${found} planes found`);
  } finally {
    removeDir(dir);
  }
});
