// Extrusions in the service are bounded and honest: a building over its budget (archgramd's
// --extrude-* flags) falls back and is reported with its id, the reason and the fallback
// (job result and GET …/plan, in the shape of `archgram extrude --report`), and SIGTERM
// while a long batch runs stops archgramd within a second with the job recorded cancelled.
import assert from 'node:assert/strict';
import { spawnSync } from 'node:child_process';
import { after, describe, it } from 'node:test';
import {
  DAEMON, http, removeDir, rng, sleep, sql, startDaemon, waitJob,
} from './harness.js';

// An irregular star of n corners (radius 60..100 m, angles jittered): many events per
// corner, so its straight skeleton takes a while.
function star(n, random, cx = 0, cy = 0) {
  const ring = [];
  for (let i = 0; i < n; i++) {
    const a = (2 * Math.PI * (i + 0.3 * random())) / n;
    const r = i % 2 ? 60 + 10 * random() : 90 + 10 * random();
    ring.push([cx + r * Math.cos(a), cy + r * Math.sin(a)]);
  }
  ring.push(ring[0]);
  return ring;
}

function city(count, corners, seed) {
  const random = rng(seed);
  return {
    type: 'FeatureCollection',
    features: Array.from({ length: count }, (_, i) => ({
      type: 'Feature',
      id: `star-${i}`,
      properties: { height: 6 },
      geometry: { type: 'Polygon', coordinates: [star(corners, random, 250 * (i % 8), 250 * Math.floor(i / 8))] },
    })),
  };
}

const square = (id, x) => ({
  type: 'Feature', id, properties: { height: 4 },
  geometry: { type: 'Polygon', coordinates: [[[x, 0], [x + 10, 0], [x + 10, 8], [x, 8], [x, 0]]] },
});

async function extrude(d, body, query) {
  const r = await http(d, 'POST', `/api/v1/extrusions?${new URLSearchParams(query)}`, {
    body: JSON.stringify(body), headers: { 'Content-Type': 'application/geo+json' }, timeout: 60000,
  });
  assert.equal(r.status, 202, r.text);
  return r.json.id;
}

describe('extrusion budgets in the service', () => {
  const started = [];
  after(async () => {
    for (const d of started) { await d.kill(); removeDir(d.dir); }
  });

  it('a building over its event budget falls back to a flat roof, reported with id and reason', async () => {
    const d = await startDaemon({ args: ['--workers', '1', '--no-web', '--extrude-max-events', '2000'] });
    started.push(d);
    const body = city(1, 400, 5);
    body.features.push(square('small', 400));
    const job = await waitJob(d, await extrude(d, body, { name: 'budget', style: 'hip', lonlat: 'false' }), { timeout: 60000 });
    assert.equal(job.status, 'succeeded', JSON.stringify(job));
    const rep = job.result.report;
    assert.equal(rep.footprints, 2);
    assert.equal(rep.succeeded, 1, JSON.stringify(rep));
    assert.deepEqual(rep.failed, []);
    assert.equal(rep.not_watertight, 0);
    assert.equal(rep.fallbacks.length, 1, JSON.stringify(rep));
    assert.equal(rep.fallbacks[0].id, 'star-0');
    assert.match(rep.fallbacks[0].fallback, /^(simplified|flat|block)$/);
    assert.match(rep.fallbacks[0].reason, /event budget \(2000 events\)/);
    assert.ok(rep.events > 0 && rep.triangles > 0, JSON.stringify(rep));

    const plan = (await http(d, 'GET', `/api/v1/models/${job.result.model}/plan`)).json;
    assert.deepEqual(plan.buildings.map((b) => [b.id, b.status, b.fallback ?? null]),
      [['star-0', 'ok', rep.fallbacks[0].fallback], ['small', 'ok', null]]);
    assert.match(plan.buildings[0].reason, /event budget/);
    assert.equal(plan.buildings[1].reason, undefined);
    // the stored plan is still the style's, so an edit works on what was asked for
    const corners = plan.buildings[0].plan.loops[0].points ?? plan.buildings[0].plan.loops[0];
    assert.ok(corners.length >= 390, `the styled description is kept (${corners.length} corners)`);
    const model = (await http(d, 'GET', `/api/v1/models/${job.result.model}`)).json;
    assert.equal(model.stats.components, 2, 'both buildings have geometry');
    await d.stop();
  });

  it('a building over its time budget falls back, and the report says which budget', async () => {
    const d = await startDaemon({ args: ['--workers', '1', '--no-web', '--extrude-timeout', '0.02'] });
    started.push(d);
    const job = await waitJob(d, await extrude(d, city(1, 3000, 9), { name: 'slow', style: 'mansard', lonlat: 'false' }), { timeout: 60000 });
    assert.equal(job.status, 'succeeded', JSON.stringify(job));
    const rep = job.result.report;
    assert.equal(rep.fallbacks.length, 1, JSON.stringify(rep));
    assert.match(rep.fallbacks[0].reason, /time budget/);
    await d.stop();
  });

  it('bad budget flags are refused with the flag named', () => {
    for (const args of [['--extrude-timeout', 'soon'], ['--extrude-max-events', '0'], ['--extrude-threads', '-2'], ['--extrude-max-memory', 'x']]) {
      const r = spawnSync(DAEMON, ['--db', ':memory:', ...args], { encoding: 'utf8', timeout: 10000 });
      assert.equal(r.status, 2, `archgramd ${args.join(' ')}: exit ${r.status}\n${r.stderr}`);
      assert.match(r.stderr, new RegExp(args[0]), r.stderr);
    }
  });

  it('SIGTERM while a long batch runs: exit within 1 s, the job recorded cancelled, nothing stored', { timeout: 120000 }, async (t) => {
    const d = await startDaemon({ args: ['--workers', '1', '--no-web', '--extrude-timeout', '0'] });
    started.push(d);
    const id = await extrude(d, city(8, 6000, 3), { name: 'long', style: 'hip', lonlat: 'false' });
    // wait until the buildings are being extruded
    const t0 = Date.now();
    for (;;) {
      const j = (await http(d, 'GET', `/api/v1/jobs/${id}`)).json;
      assert.ok(['queued', 'running'].includes(j.status), `job ${id} is ${j.status} before SIGTERM (${JSON.stringify(j)})`);
      if (j.status === 'running' && j.stage === 'extrude') break;
      assert.ok(Date.now() - t0 < 60000, 'the job never started extruding');
      await sleep(20);
    }
    await sleep(300);
    const { ms } = await d.stop(10000);
    t.diagnostic(`8 footprints of 6000 corners (seconds each); SIGTERM while extruding; exit after ${ms} ms`);
    assert.ok(ms < 1000, `archgramd took ${ms} ms to stop`);
    assert.deepEqual(sql(d.db, `select status from jobs where id = ${id}`), [['cancelled']]);
    assert.deepEqual(sql(d.db, 'select count(*) from models'), [['0']], 'no model for the interrupted batch');
    assert.deepEqual(sql(d.db, 'pragma integrity_check'), [['ok']]);
  });
});
