// --demo: two generated buildings (proceduralized by jobs) and an extruded street in an empty
// database, and only then.
import assert from 'node:assert/strict';
import { after, describe, it } from 'node:test';
import { http, listModels, parseGlb, removeDir, sleep, startDaemon, tempDir } from './harness.js';

describe('demo content', () => {
  const dir = tempDir();
  let d;
  after(async () => {
    if (d) await d.kill();
    removeDir(dir);
  });

  async function models(n) {
    const t0 = Date.now();
    for (;;) {
      const items = await listModels(d);
      if (items.length >= n || Date.now() - t0 > 30000) return items;
      await sleep(50);
    }
  }

  it('--demo loads two proceduralized buildings and an extruded street into an empty database, once', async () => {
    d = await startDaemon({ dir, args: ['--demo'] });
    const t0 = Date.now();
    let first;
    for (;;) { // the jobs proceduralize the buildings (version 2) and make the street
      first = await models(3);
      const ready = first.length === 3 && first.filter((m) => m.kind === 'mesh').every((m) => m.proceduralized);
      if (ready || Date.now() - t0 > 30000) break;
      await sleep(50);
    }
    assert.equal(first.length, 3, JSON.stringify(first));
    const buildings = first.filter((m) => m.kind === 'mesh');
    assert.equal(buildings.length, 2, JSON.stringify(first));
    for (const m of buildings) {
      assert.ok(m.stats.triangles > 0 && m.stats.components > 1, `demo model ${m.id}: ${JSON.stringify(m.stats)}`);
      assert.equal(m.proceduralized, true, `demo model ${m.id} is proceduralized`);
      const g = await http(d, 'GET', m.mesh);
      assert.equal(g.status, 200);
      const glb = parseGlb(g.body);
      assert.equal(glb.magic, 'glTF');
      assert.equal(glb.json.nodes.length, m.stats.components);
      const tree = await http(d, 'GET', `/api/v1/models/${m.id}/tree`);
      assert.equal(tree.status, 200, tree.text);
    }
    const street = first.find((m) => m.kind === 'extrusion');
    assert.ok(street, JSON.stringify(first));
    const plan = await http(d, 'GET', `/api/v1/models/${street.id}/plan`);
    assert.equal(plan.status, 200, plan.text);
    assert.ok(street.stats.components >= 6, JSON.stringify(street.stats));
    await d.stop();

    d = await startDaemon({ dir, db: d.db, args: ['--demo'] });
    await sleep(500); // time for a wrongly repeated demo load to show
    assert.deepEqual((await listModels(d)).map((m) => m.id), first.map((m) => m.id));
    await d.stop();
    d = null;
  });
});
