// What the held-out sweep (tests/heldout) found on inputs shaped like other people's data,
// each as it must behave now: PLY meshes in double at UTM coordinates keep their precision,
// `derive --compare` judges a default model within the tolerance it was made with and with
// the input cut as proceduralize cuts it, OBJ comments after the data are comments.
// Results are checked independently: areas and extents of the derived OBJ, computed here.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { spawnSync } from 'node:child_process';
import fs from 'node:fs';
import path from 'node:path';
import { REPO, tempDir, removeDir } from './harness.js';
import { building, measure, offset, rotZ, plyText, stlBinary, gltf, objText, cloudPoints, las, readExtrusion } from '../heldout/generate.js';

const CLI = process.env.ARCHGRAM ? path.resolve(process.env.ARCHGRAM) : path.join(REPO, 'build', 'archgram');
const run = (...args) => spawnSync(CLI, args, { encoding: 'utf8', timeout: 60000 });

// area and sorted extents of an OBJ's faces
function objMeasure(file) {
  const v = [], f = [];
  for (const line of fs.readFileSync(file, 'utf8').split('\n')) {
    const t = line.trim().split(/\s+/);
    if (t[0] === 'v') v.push(t.slice(1, 4).map(Number));
    else if (t[0] === 'f') f.push(t.slice(1).map((s) => parseInt(s, 10) - 1));
  }
  const m = measure(v, f);
  return { area: m.area, extent: m.extent.slice().sort((a, b) => a - b) };
}
const sorted = (e) => e.slice().sort((a, b) => a - b);

test('PLY meshes with double coordinates at UTM offsets keep their precision (ascii, both binaries)', () => {
  const dir = tempDir();
  try {
    const B = building();
    const want = measure(B.v, B.f);
    for (const format of ['ascii', 'binary_little_endian', 'binary_big_endian']) {
      const ply = path.join(dir, `utm-${format}.ply`);
      fs.writeFileSync(ply, plyText(offset(B, [678088, 5403784, 413]), { format, double: true }));
      const out = path.join(dir, `p-${format}`);
      let r = run('proceduralize', ply, '--out', out);
      assert.equal(r.status, 0, r.stderr);
      // the twelve windows are copies again: one label for them (floats made them differ)
      assert.match(r.stdout, / 0 unmatched/);
      const back = path.join(dir, `back-${format}.obj`);
      r = run('derive', path.join(out, 'grammar.txt'), '--out', back, '--compare', ply);
      assert.equal(r.status, 0, r.stdout + r.stderr);
      const got = objMeasure(back);
      assert.ok(Math.abs(got.area - want.area) < 1e-6 * want.area, `${format}: area ${got.area} vs ${want.area}`);
      sorted(want.extent).forEach((x, i) => assert.ok(Math.abs(got.extent[i] - x) < 1e-6, `${format}: extents ${got.extent} vs ${want.extent}`));
    }
  } finally {
    removeDir(dir);
  }
});

test('derive --compare: default models of float inputs (GLB turned by a node, STL at RD) compare clean; a moved input does not', () => {
  const dir = tempDir();
  try {
    const B = building();
    const inputs = {
      'turned.glb': gltf(B, { binary: true, node: { translation: [5, 0, 3], rotation: [0, Math.sin(Math.PI / 12), 0, Math.cos(Math.PI / 12)] } }),
      'rd.stl': stlBinary(offset(rotZ(B, 30), [85000, 445000, 0]), false),
    };
    for (const [name, data] of Object.entries(inputs)) {
      const file = path.join(dir, name);
      fs.writeFileSync(file, data);
      const out = path.join(dir, `p-${name}`);
      let r = run('proceduralize', file, '--out', out);
      assert.equal(r.status, 0, r.stderr);
      const back = path.join(dir, `back-${name}.obj`);
      r = run('derive', path.join(out, 'grammar.txt'), '--out', back, '--compare', file);
      assert.equal(r.status, 0, `${name}: ${r.stdout}${r.stderr}`);
      const tol = JSON.parse(fs.readFileSync(path.join(out, 'summary.json'), 'utf8')).labeling.tolerance;
      const m = r.stdout.match(/(\d+) of 162 input triangles unmatched within (\S+) m/);
      assert.ok(m, r.stdout);
      assert.equal(Number(m[1]), 0);
      assert.ok(Math.abs(Number(m[2]) - tol) <= 1e-3 * tol, `the label tolerance ${tol} is the comparison's: ${r.stdout}`);
      // an explicit tolerance is the one used
      r = run('derive', path.join(out, 'grammar.txt'), '--out', back, '--compare', file, '--tolerance', '0.02');
      assert.equal(r.status, 0, r.stdout + r.stderr);
      assert.match(r.stdout, /unmatched within 0\.02 m/);
    }
    // an --exact grammar derives the input as it was: compared at 1e-5 of the diagonal
    const rd = path.join(dir, 'rd.stl'), ex = path.join(dir, 'exact');
    let e = run('proceduralize', rd, '--out', ex, '--exact');
    assert.equal(e.status, 0, e.stderr);
    e = run('derive', path.join(ex, 'grammar.txt'), '--out', path.join(dir, 'ex.obj'), '--compare', rd);
    assert.equal(e.status, 0, e.stdout + e.stderr);
    const diag = Math.hypot(...measure(rotZ(B, 30).v, B.f).extent);
    const within = Number(e.stdout.match(/unmatched within (\S+) m/)[1]);
    assert.ok(Math.abs(within - 1e-5 * diag) < 5e-3 * within, `${within} vs ${1e-5 * diag}`);
    // the same grammar against the building moved by half a metre: unmatched, exit 1
    const moved = path.join(dir, 'moved.stl');
    fs.writeFileSync(moved, stlBinary(offset(rotZ(B, 30), [85000.5, 445000, 0]), false));
    const r = run('derive', path.join(dir, 'p-rd.stl', 'grammar.txt'), '--out', path.join(dir, 'x.obj'), '--compare', moved);
    assert.equal(r.status, 1, r.stdout + r.stderr);
    const m = r.stdout.match(/(\d+) of 162 input triangles unmatched/);
    assert.ok(m && Number(m[1]) > 0, r.stdout);
    const bad = run('derive', path.join(dir, 'p-rd.stl', 'grammar.txt'), '--out', path.join(dir, 'x.obj'), '--compare', moved, '--tolerance', 'abc');
    assert.equal(bad.status, 2);
    assert.match(bad.stderr, /--tolerance must be a positive number of metres, not 'abc'/);
  } finally {
    removeDir(dir);
  }
});

test('OBJ: comments after the data are comments; the model is the one without them', () => {
  const dir = tempDir();
  try {
    const B = building();
    const plain = path.join(dir, 'plain.obj'), noted = path.join(dir, 'noted.obj');
    fs.writeFileSync(plain, objText(B));
    fs.writeFileSync(noted, objText(B, { midComments: true }));
    const a = run('proceduralize', plain, '--out', path.join(dir, 'a'));
    const b = run('proceduralize', noted, '--out', path.join(dir, 'b'));
    assert.equal(a.status, 0, a.stderr);
    assert.equal(b.status, 0, b.stderr);
    assert.equal(fs.readFileSync(path.join(dir, 'a', 'grammar.txt'), 'utf8'), fs.readFileSync(path.join(dir, 'b', 'grammar.txt'), 'utf8'));
    assert.match(b.stdout, /^\S+: 162 triangles/);
  } finally {
    removeDir(dir);
  }
});

test('cut: a tile in a local site frame (coordinates near 0, 0) is refused as degrees, and cut with --metres', () => {
  const dir = tempDir();
  try {
    const P = cloudPoints(); // a building on [0, 20] x [0, 10] (class 6) and ground (class 2)
    const tile = path.join(dir, 'site.las'), fp = path.join(dir, 'fp.geojson');
    fs.writeFileSync(tile, las(P, { minor: 4, format: 6 }));
    const ring = [[-0.5, -0.5], [20.5, -0.5], [20.5, 10.5], [-0.5, 10.5], [-0.5, -0.5]];
    fs.writeFileSync(fp, JSON.stringify({ type: 'FeatureCollection', features: [{ type: 'Feature', properties: { id: 'b1' }, geometry: { type: 'Polygon', coordinates: [ring] } }] }));
    let r = run('cut', tile, '--footprints', fp, '--out', path.join(dir, 'a'));
    assert.equal(r.status, 1);
    assert.match(r.stderr, /site\.las: the tile looks like longitude\/latitude; .*--metres for a local frame/);
    r = run('cut', tile, '--footprints', fp, '--out', path.join(dir, 'b'), '--metres');
    assert.equal(r.status, 0, r.stderr);
    // the building's points, counted here: every class 6 point, no ground point (class 2)
    const building = P.filter((p) => p[3] === 6).length;
    const head = fs.readFileSync(path.join(dir, 'b', 'b1.ply')).subarray(0, 2000).toString('latin1');
    assert.equal(Number(head.match(/element vertex (\d+)/)[1]), building);
    // a tile never classified: --ground class has nothing to remove and says so; plane works
    const plain = path.join(dir, 'plain.las');
    fs.writeFileSync(plain, las(P.map(([x, y, z]) => [x, y, z, 1]), { minor: 2, format: 1 }));
    r = run('cut', plain, '--footprints', fp, '--out', path.join(dir, 'c'), '--metres', '--ground', 'class');
    assert.equal(r.status, 1);
    assert.match(r.stderr, /plain\.las: --ground class, but no point has classification 2/);
    r = run('cut', plain, '--footprints', fp, '--out', path.join(dir, 'd'), '--metres', '--ground', 'plane');
    assert.equal(r.status, 0, r.stderr);
  } finally {
    removeDir(dir);
  }
});

test('extrude: a footprint with a spike a few micrometres wide builds as styled, closed, with its base area', () => {
  const dir = tempDir();
  try {
    // a 20 x 10 m block at RD with a 15 m spike: 2e-7 m wide (removed by validation), 4e-6
    // and 1e-5 m (kept; thinner than the building check's probe near the tip)
    for (const w of [2e-7, 4e-6, 1e-5]) {
      const ring = [[0, 0], [20, 0], [20, 10], [10 + w / 2, 10], [10, 25], [10 - w / 2, 10], [0, 10], [0, 0]].map(([x, y]) => [x + 85000, y + 445000]);
      const fp = path.join(dir, `spike-${w}.geojson`);
      fs.writeFileSync(fp, JSON.stringify({ type: 'FeatureCollection', features: [{ type: 'Feature', properties: { height: 9 }, geometry: { type: 'Polygon', coordinates: [ring] } }] }));
      const out = path.join(dir, `spike-${w}.obj`), rep = path.join(dir, `spike-${w}.json`);
      const r = run('extrude', fp, '--style', 'hip', '--out', out, '--report', rep);
      assert.equal(r.status, 0, r.stdout + r.stderr);
      const report = JSON.parse(fs.readFileSync(rep, 'utf8'));
      assert.equal(report.succeeded, 1, `${w}: ${r.stdout}${r.stderr}`);
      assert.deepEqual(report.fallbacks, [], `${w}: ${r.stderr}`);
      const { v, weld, groups } = readExtrusion(out);
      const T = [...groups.values()].flat();
      const use = new Map();
      for (const t of T) for (let k = 0; k < 3; k++) { const key = `${weld[t[k]]},${weld[t[(k + 1) % 3]]}`; use.set(key, (use.get(key) || 0) + 1); }
      for (const [key, n] of use) {
        const [a, b] = key.split(',');
        assert.ok(a !== b && n === 1 && use.get(`${b},${a}`) === 1, `${w}: edge ${key} used ${n} times, its reverse ${use.get(`${b},${a}`)}`);
      }
      let base = 0;
      for (const t of T) {
        const [A, B, C] = t.map((i) => v[i]);
        if (Math.max(A[2], B[2], C[2]) < 1e-9) base -= ((B[0] - A[0]) * (C[1] - A[1]) - (B[1] - A[1]) * (C[0] - A[0])) / 2;
      }
      assert.ok(Math.abs(base - 200) <= 15 * w / 2 + 1e-6, `${w}: base ${base} m²`);
      assert.ok(Math.max(...v.map((p) => p[2])) <= 9 + 5 + 1e-6, `${w}: a roof above the block's 45° rise`);
    }
  } finally {
    removeDir(dir);
  }
});
