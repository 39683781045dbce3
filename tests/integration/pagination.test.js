// GET /api/v1/models pages by id with an opaque next_page_token.
import assert from 'node:assert/strict';
import { after, before, describe, it } from 'node:test';
import { assertProblem, http, importModel, removeDir, startDaemon } from './harness.js';

const triangle = (k) => `# triangle ${k}\nv 0 0 0\nv ${k + 1} 0 0\nv 0 1 0\nf 1 2 3\n`;

describe('pagination', () => {
  let d;
  const ids = [];
  before(async () => {
    d = await startDaemon();
    for (let k = 0; k < 5; k++) ids.push((await importModel(d, triangle(k), { name: `t${k}` })).id);
  });
  after(async () => {
    if (d) { try { await d.stop(); } finally { await d.kill(); removeDir(d.dir); } }
  });

  it('page_size=2 gives 3 pages in id order, no duplicates, null token at the end', async () => {
    const pages = [];
    let token = null;
    for (let i = 0; i < 10; i++) {
      const q = new URLSearchParams({ page_size: '2' });
      if (token !== null) q.set('page_token', token);
      const r = await http(d, 'GET', `/api/v1/models?${q}`);
      assert.equal(r.status, 200, r.text);
      assert.ok(Array.isArray(r.json.items));
      assert.ok('next_page_token' in r.json);
      pages.push(r.json.items.map((m) => m.id));
      token = r.json.next_page_token;
      if (token === null) break;
      assert.equal(typeof token, 'string');
    }
    assert.deepEqual(pages.map((p) => p.length), [2, 2, 1], JSON.stringify(pages));
    const all = pages.flat();
    assert.equal(new Set(all).size, all.length, 'duplicates across pages');
    assert.deepEqual(all, [...ids].sort((a, b) => a - b));
  });

  it('default page holds all five with a null token; items are full model objects', async () => {
    const r = await http(d, 'GET', '/api/v1/models');
    assert.equal(r.status, 200);
    assert.deepEqual(r.json.items.map((m) => m.id), ids);
    assert.equal(r.json.next_page_token, null);
    assert.deepEqual(r.json.items.map((m) => m.name), ['t0', 't1', 't2', 't3', 't4']);
    for (const m of r.json.items) {
      assert.equal(m.href, `/api/v1/models/${m.id}`);
      assert.equal(m.stats.triangles, 1);
    }
  });

  it('a bad page_token or page_size is 400 problem+json', async () => {
    for (const q of ['page_token=not-a-token!', 'page_token=', 'page_size=0', 'page_size=201',
      'page_size=abc', 'page_size=2.5']) {
      assertProblem(await http(d, 'GET', `/api/v1/models?${q}`), 400, 'invalid', `GET /api/v1/models?${q}`);
    }
  });
});
