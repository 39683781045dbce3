// `archgram proceduralize` flags as a pipeline uses them: --up (auto, y, z, and a bad value),
// --exact, and what summary.json and the output lines say about the axis and the labels.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { spawnSync } from 'node:child_process';
import fs from 'node:fs';
import path from 'node:path';
import { REPO, tempDir, removeDir, facadeObj } from './harness.js';

const CLI = process.env.ARCHGRAM ? path.resolve(process.env.ARCHGRAM) : path.join(REPO, 'build', 'archgram');
const run = (...args) => spawnSync(CLI, args, { encoding: 'utf8', timeout: 60000 });
const summary = (dir) => JSON.parse(fs.readFileSync(path.join(dir, 'summary.json'), 'utf8'));

test('--up: the content decides by default and says so; a request overrides it; a bad value is a usage error', () => {
  const dir = tempDir();
  try {
    const obj = path.join(dir, 'facade.obj');
    fs.writeFileSync(obj, facadeObj(4, 2)); // a y-up facade slab: it stands on its long side
    for (const [flag, axis, decided] of [[[], 'y', 'content'], [['--up', 'auto'], 'y', 'content'],
      [['--up', 'y'], 'y', 'request'], [['--up', 'z'], 'z', 'request']]) {
      const out = path.join(dir, `p_${flag.join('')}`);
      const r = run('proceduralize', obj, '--out', out, ...flag);
      assert.equal(r.status, 0, r.stderr);
      const up = summary(out).input.up;
      assert.equal(up.axis, axis, JSON.stringify(up));
      assert.equal(up.decided, decided, JSON.stringify(up));
      assert.equal(typeof up.evidence.score, 'number');
      assert.match(r.stdout, new RegExp(`up axis ${axis} \\(${decided}, score -?[0-9.]+\\); label tolerance [0-9.e-]+ m`));
    }
    const bad = run('proceduralize', obj, '--out', path.join(dir, 'bad'), '--up', 'x');
    assert.equal(bad.status, 2);
    assert.match(bad.stderr, /--up takes auto, y or z/);
  } finally {
    removeDir(dir);
  }
});

test('--exact shares terminals between exact copies only and derives the input back', () => {
  const dir = tempDir();
  try {
    const obj = path.join(dir, 'facade.obj');
    fs.writeFileSync(obj, facadeObj(4, 2));
    const byDefault = path.join(dir, 'd'), exact = path.join(dir, 'e');
    assert.equal(run('proceduralize', obj, '--out', byDefault).status, 0);
    const r = run('proceduralize', obj, '--out', exact, '--exact');
    assert.equal(r.status, 0, r.stderr);
    assert.match(r.stdout, /, exact copies\n/);
    const d = summary(byDefault), e = summary(exact);
    assert.equal(d.labeling.exact_copies, false);
    assert.equal(e.labeling.exact_copies, true);
    assert.ok(e.labeling.share < d.labeling.share, JSON.stringify(e.labeling));
    assert.ok(d.labeling.tolerance > 0 && d.labeling.tolerance <= 0.005, JSON.stringify(d.labeling));
    assert.equal(e.fidelity.unmatched, 0);
    assert.ok(e.fidelity.relative <= 1e-6, JSON.stringify(e.fidelity));
    assert.ok(d.fidelity.max_error <= 0.01, JSON.stringify(d.fidelity));
    // the copies of this facade are exact: both ways share one terminal per window
    assert.equal(e.terminals, d.terminals);
  } finally {
    removeDir(dir);
  }
});

test('--unit names the file\'s length unit: reported as the request\'s, the tolerance cap follows it; a bad name is a usage error', () => {
  const dir = tempDir();
  try {
    // the facade in centimetres: its size does not tell (taken as metres unless named)
    const obj = path.join(dir, 'facade_cm.obj');
    fs.writeFileSync(obj, facadeObj(4, 2).replace(/^v (\S+) (\S+) (\S+)/gm,
      (_, x, y, z) => `v ${x * 100} ${y * 100} ${z * 100}`));
    const decided = path.join(dir, 'd'), named = path.join(dir, 'n');
    assert.equal(run('proceduralize', obj, '--out', decided).status, 0);
    const r = run('proceduralize', obj, '--out', named, '--unit', 'cm');
    assert.equal(r.status, 0, r.stderr);
    const d = summary(decided).labeling, n = summary(named).labeling;
    assert.equal(d.units.decided, 'content');
    assert.equal(n.units.unit, 'cm');
    assert.equal(n.units.metres_per_unit, 0.01);
    assert.equal(n.units.decided, 'request');
    assert.match(r.stdout, /units cm, request/);
    // the cap of 5 mm is 0.5 cm: never more than that in the file's unit
    assert.ok(n.tolerance <= 0.5 + 1e-12, JSON.stringify(n));
    const bad = run('proceduralize', obj, '--out', path.join(dir, 'bad'), '--unit', 'yd');
    assert.equal(bad.status, 2);
    assert.match(bad.stderr, /--unit takes m, dm, cm, mm, ft or in/);
  } finally {
    removeDir(dir);
  }
});
