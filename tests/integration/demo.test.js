// --demo: two generated buildings in an empty database, and only then.
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

  it('--demo loads two buildings into an empty database, once', async () => {
    d = await startDaemon({ dir, args: ['--demo'] });
    const first = await models(2);
    assert.equal(first.length, 2, JSON.stringify(first));
    for (const m of first) {
      assert.ok(m.stats.triangles > 0 && m.stats.components > 1, `demo model ${m.id}: ${JSON.stringify(m.stats)}`);
      const g = await http(d, 'GET', m.mesh);
      assert.equal(g.status, 200);
      const glb = parseGlb(g.body);
      assert.equal(glb.magic, 'glTF');
      assert.equal(glb.json.nodes.length, m.stats.components);
    }
    await d.stop();

    d = await startDaemon({ dir, db: d.db, args: ['--demo'] });
    await sleep(500); // time for a wrongly repeated demo load to show
    assert.deepEqual((await listModels(d)).map((m) => m.id), first.map((m) => m.id));
    await d.stop();
    d = null;
  });
});
