// archgram extrude as a pipeline runs it: budgets that stop a building with a clear message,
// batches that fall back and say so in the report, validation fixes printed, refusals that
// name the edges, and Ctrl-C / SIGTERM that stop the work promptly.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { spawn, spawnSync } from 'node:child_process';
import fs from 'node:fs';
import path from 'node:path';
import { REPO, tempDir, removeDir } from './harness.js';

const CLI = process.env.ARCHGRAM ? path.resolve(process.env.ARCHGRAM) : path.join(REPO, 'build', 'archgram');
const run = (...args) => spawnSync(CLI, args, { encoding: 'utf8', timeout: 60000 });

// A plan that takes far longer than a small budget: a jittered circle of many corners.
function circlePlan(file, corners) {
  const pts = [];
  let seed = 7;
  const rnd = () => ((seed = (seed * 1103515245 + 12345) % 2147483648) / 2147483648);
  for (let i = 0; i < corners; i++) {
    const a = (2 * Math.PI * i) / corners, r = 50 + 0.01 * rnd();
    pts.push([r * Math.cos(a), r * Math.sin(a)]);
  }
  fs.writeFileSync(file, JSON.stringify({ profiles: { r: [[0, 0], [1, 1]] }, loops: [pts] }));
}

const feature = (id, type, coordinates) => ({ type: 'Feature', id, properties: { height: 5 }, geometry: { type, coordinates } });
function geojson(file, features) {
  fs.writeFileSync(file, JSON.stringify({
    type: 'FeatureCollection',
    crs: { type: 'name', properties: { name: 'urn:ogc:def:crs:EPSG::28992' } },
    features,
  }));
}

test('a plan stopped by its event budget fails with the budget named, nothing written', () => {
  const dir = tempDir();
  try {
    const plan = path.join(dir, 'circle.json'), out = path.join(dir, 'out.obj');
    circlePlan(plan, 3000);
    const r = run('extrude', '--plan', plan, '--out', out, '--max-events', '2000');
    assert.equal(r.status, 1, r.stdout);
    assert.match(r.stderr, /event budget \(2000 events\)/);
    assert.match(r.stderr, /raise --max-events or --timeout/);
    assert.equal(fs.existsSync(out), false);
  } finally {
    removeDir(dir);
  }
});

test('a plan stopped by its time budget fails promptly with the budget named', () => {
  const dir = tempDir();
  try {
    const plan = path.join(dir, 'circle.json'), out = path.join(dir, 'out.obj');
    circlePlan(plan, 20000);
    const t0 = Date.now();
    const r = run('extrude', '--plan', plan, '--out', out, '--timeout', '0.2');
    assert.equal(r.status, 1, r.stdout);
    assert.match(r.stderr, /time budget \(0\.2 s\)/);
    assert.ok(Date.now() - t0 < 20000, 'it stopped long before the full sweep');
  } finally {
    removeDir(dir);
  }
});

test('bad budget values are usage errors', () => {
  for (const args of [['--max-events', '-3'], ['--timeout', 'soon'], ['--threads', '1.5']]) {
    const r = run('extrude', '--plan', 'x.json', '--out', 'y.obj', ...args);
    assert.equal(r.status, 2, args.join(' '));
    assert.match(r.stderr, new RegExp(`${args[0]} needs a non-negative`));
  }
});

test('a batch reports fallbacks, fixes and refusals building by building', () => {
  const dir = tempDir();
  try {
    const input = path.join(dir, 'city.geojson'), out = path.join(dir, 'city.obj'), rep = path.join(dir, 'report.json');
    // a comb whose hip roof needs many events, a house with a counter-clockwise hole, a bow tie
    const comb = [[100, 0], [140, 0], [140, 3]];
    for (let x = 137; x > 100; x -= 6) comb.push([x, 3], [x, 9], [x - 3, 9], [x - 3, 3]);
    comb.push([100, 3], [100, 0]);
    geojson(input, [
      feature('comb', 'Polygon', [comb]),
      feature('court', 'Polygon', [[[0, 0], [10, 0], [10, 10], [0, 10], [0, 0]], [[3, 3], [7, 3], [7, 7], [3, 7], [3, 3]]]),
      feature('bowtie', 'Polygon', [[[200, 0], [210, 0], [200, 10], [210, 10], [200, 0]]]),
    ]);
    const r = run('extrude', input, '--style', 'hip', '--out', out, '--report', rep, '--max-events', '200');
    assert.equal(r.status, 0, r.stderr);
    const report = JSON.parse(fs.readFileSync(rep, 'utf8'));
    assert.equal(report.footprints, 3);
    assert.equal(report.succeeded, 1);
    assert.equal(report.not_watertight, 0);
    assert.equal(report.fallbacks.length, 1);
    assert.equal(report.fallbacks[0].id, 'comb');
    assert.match(report.fallbacks[0].reason, /event budget/);
    assert.ok(['flat', 'block'].includes(report.fallbacks[0].fallback));
    assert.equal(report.failed.length, 1);
    assert.equal(report.failed[0].id, 'bowtie');
    assert.match(report.failed[0].reason, /edge 1 crosses edge 3/);
    assert.ok(report.fixed.some((x) => x.id === 'court' && /hole 0 was counter-clockwise: reversed/.test(x.fixes)));
    assert.match(r.stdout, /fixed court: hole 0 was counter-clockwise: reversed/);
    assert.match(r.stderr, /fell back comb: (flat|block): .*event budget/);
    assert.match(r.stderr, /failed bowtie: .*edge 1 crosses edge 3/);
    // two buildings in the OBJ: one group each
    const groups = fs.readFileSync(out, 'utf8').split('\n').filter((l) => l.startsWith('g '));
    assert.deepEqual(groups.map((g) => g.slice(2)), ['comb', 'court']);
  } finally {
    removeDir(dir);
  }
});

test('SIGTERM stops a long extrusion within a second and writes nothing', async () => {
  const dir = tempDir();
  try {
    const plan = path.join(dir, 'circle.json'), out = path.join(dir, 'out.obj');
    circlePlan(plan, 20000);
    const child = spawn(CLI, ['extrude', '--plan', plan, '--out', out, '--timeout', '0'], { stdio: ['ignore', 'pipe', 'pipe'] });
    let stderr = '';
    child.stderr.on('data', (d) => { stderr += d; });
    await new Promise((resolve) => setTimeout(resolve, 700));
    const sent = Date.now();
    child.kill('SIGTERM');
    const code = await new Promise((resolve) => child.on('exit', (c) => resolve(c)));
    const took = Date.now() - sent;
    assert.equal(code, 1);
    assert.ok(took < 1000, `stopped ${took} ms after SIGTERM`);
    assert.match(stderr, /cancelled/);
    assert.equal(fs.existsSync(out), false);
  } finally {
    removeDir(dir);
  }
});
