// The PLY terminals a point model keeps in the store: proceduralizing a cloud again keeps only
// the terminals some kept version's grammar names (the earlier run's go once no version can
// come back to them), so proceduralizing twice does not grow the terminal store; undo and
// restore still find every terminal their version names. Counted with sqlite3 on the database.
import assert from 'node:assert/strict';
import { after, before, describe, it } from 'node:test';
import { http, removeDir, sql, startDaemon, waitJob } from './harness.js';
import { buildingPly, windowBox } from './points_building.js';

const box6 = (s) => s.split(',').map(Number);

describe('point model terminals in the store', () => {
  let d;
  let id;
  before(async () => {
    d = await startDaemon();
  });
  after(async () => {
    if (d) { try { await d.stop(); } finally { await d.kill(); removeDir(d.dir); } }
  });
  const count = () => Number(sql(d.db, `SELECT count(*) FROM terminals WHERE model_id = ${id}`)[0][0]);
  const paths = () => new Set(sql(d.db, `SELECT path FROM terminals WHERE model_id = ${id}`).map((r) => r[0]));
  const named = (text) => new Set([...text.matchAll(/"(terminals\/[0-9a-f]{16}\.ply)"/g)].map((m) => m[1]));
  const proceduralize = async (body) => {
    const r = await http(d, 'POST', `/api/v1/models/${id}/proceduralize`, { body });
    assert.equal(r.status, 202, r.text);
    const job = await waitJob(d, r.json.id, { timeout: 120000 });
    assert.equal(job.status, 'succeeded', JSON.stringify(job.error));
    return (await http(d, 'GET', `/api/v1/models/${id}/grammar`)).text;
  };

  it('proceduralizing again does not grow the terminal store', async () => {
    const q = new URLSearchParams({ name: 'house', format: 'ply' });
    const up = await http(d, 'POST', `/api/v1/models?${q}`, { body: buildingPly(30000).bytes, headers: { 'Content-Type': 'application/octet-stream' }, timeout: 120000 });
    id = (await waitJob(d, up.json.id, { timeout: 120000 })).result.model;
    const g1 = await proceduralize({});
    const n1 = count();
    console.log(`# first run: ${n1} terminals stored, ${named(g1).size} named`);
    assert.deepEqual(paths(), named(g1));
    const g2 = await proceduralize({ templates: [box6(windowBox(2))], auto: false });
    assert.notEqual(g2, g1, 'a template changes the model');
    const n2 = count();
    // every terminal stored is named by a version that restore can come back to, and back
    const keptNames = () => {
      const all = new Set();
      for (const [text] of sql(d.db, `SELECT grammar FROM model_states WHERE model_id = ${id} AND grammar IS NOT NULL UNION ALL SELECT text FROM grammars WHERE model_id = ${id}`)) {
        for (const p of named(text)) all.add(p);
      }
      return all;
    };
    assert.deepEqual(paths(), new Set([...named(g1), ...named(g2)]));
    assert.deepEqual(paths(), keptNames());
    // the first run's options again, twice: the same terminals, nothing more stored
    const g3 = await proceduralize({});
    assert.equal(g3, g1);
    assert.equal(count(), n2);
    await proceduralize({});
    assert.equal(count(), n2);
    assert.deepEqual(paths(), keptNames());
    console.log(`# terminals stored: ${n1} after the first run, ${n2} after a run with a template, ${count()} after two more runs as the first`);
    // the template run's version restored: its terminals are there, its cloud derives
    const v = (await http(d, 'GET', `/api/v1/models/${id}`)).json.version;
    const r = await http(d, 'POST', `/api/v1/models/${id}/ops`, { body: { op: { kind: 'restore', version: 3 } }, headers: { 'If-Match': `"${v}"` }, timeout: 60000 });
    assert.equal(r.status, 200, r.text);
    assert.equal((await http(d, 'GET', `/api/v1/models/${id}/grammar`)).text, g2);
    const dr = await http(d, 'GET', `/api/v1/models/${id}/derived.ply`, { timeout: 60000 });
    assert.equal(dr.status, 200, dr.text.slice(0, 300));
    assert.equal(count(), n2);
    assert.deepEqual(sql(d.db, 'PRAGMA integrity_check'), [['ok']]);
  });
});
