// ETag / If-Match on model PATCH and DELETE.
import assert from 'node:assert/strict';
import { after, before, describe, it } from 'node:test';
import { assertProblem, fixture, http, importModel, removeDir, startDaemon } from './harness.js';

describe('ETag and If-Match', () => {
  let d;
  let m;
  before(async () => {
    d = await startDaemon();
    m = await importModel(d, fixture('two_boxes.obj'), { name: 'before' });
  });
  after(async () => {
    if (d) { try { await d.stop(); } finally { await d.kill(); removeDir(d.dir); } }
  });

  it('PATCH: no If-Match 428, stale 412, current 200 with version+1 and a new ETag', async () => {
    const href = m.href;
    const v = m.version;
    assertProblem(await http(d, 'PATCH', href, { body: { name: 'x' } }), 428, 'precondition-required', 'PATCH without If-Match');
    assertProblem(await http(d, 'PATCH', href, { body: { name: 'x' }, headers: { 'If-Match': `"${v + 7}"` } }),
      412, 'stale', 'PATCH with a stale If-Match');
    let g = await http(d, 'GET', href);
    assert.equal(g.json.name, 'before', 'refused PATCHes changed nothing');
    assert.equal(g.json.version, v);

    const r = await http(d, 'PATCH', href, { body: { name: 'after' }, headers: { 'If-Match': `"${v}"` } });
    assert.equal(r.status, 200, r.text);
    assert.equal(r.json.name, 'after');
    assert.equal(r.json.version, v + 1);
    assert.equal(r.headers.get('etag'), `"${v + 1}"`);
    g = await http(d, 'GET', href);
    assert.equal(g.json.name, 'after');
    assert.equal(g.headers.get('etag'), `"${v + 1}"`);

    // The old ETag is now stale.
    assertProblem(await http(d, 'PATCH', href, { body: { name: 'again' }, headers: { 'If-Match': `"${v}"` } }),
      412, 'stale', 'PATCH with the previous ETag');
    m = g.json;
  });

  it('concurrent PATCHes on the same version: exactly one wins', async () => {
    const v = m.version;
    const rs = await Promise.all([...Array(10).keys()].map((i) =>
      http(d, 'PATCH', m.href, { body: { name: `racer ${i}` }, headers: { 'If-Match': `"${v}"` } })));
    const ok = rs.filter((r) => r.status === 200);
    assert.equal(ok.length, 1, rs.map((r) => r.status).join(' '));
    assert.ok(rs.every((r) => r.status === 200 || r.status === 412), rs.map((r) => r.status).join(' '));
    const g = await http(d, 'GET', m.href);
    assert.equal(g.json.version, v + 1);
    assert.equal(g.json.name, ok[0].json.name);
    m = g.json;
  });

  it('PATCH with an invalid name is 400 and changes nothing', async () => {
    for (const body of [{ name: '' }, { name: 'x'.repeat(201) }, { name: 5 }, {}]) {
      assertProblem(await http(d, 'PATCH', m.href, { body, headers: { 'If-Match': `"${m.version}"` } }),
        400, 'invalid', `PATCH ${JSON.stringify(body).slice(0, 40)}`);
    }
    const r = await http(d, 'PATCH', m.href, { body: 'not json', headers: { 'If-Match': `"${m.version}"`, 'Content-Type': 'application/json' } });
    assert.equal(r.status, 400, r.text);
    const g = await http(d, 'GET', m.href);
    assert.equal(g.json.version, m.version);
    assert.equal(g.json.name, m.name);
  });

  it('DELETE: no If-Match 428, stale 412, current 204, then GET 404', async () => {
    const href = m.href;
    const v = m.version;
    assertProblem(await http(d, 'DELETE', href), 428, 'precondition-required', 'DELETE without If-Match');
    assertProblem(await http(d, 'DELETE', href, { headers: { 'If-Match': `"${v - 1}"` } }), 412, 'stale', 'DELETE stale');
    assert.equal((await http(d, 'GET', href)).status, 200, 'refused DELETEs kept the model');
    const r = await http(d, 'DELETE', href, { headers: { 'If-Match': `"${v}"` } });
    assert.equal(r.status, 204, r.text);
    assert.equal(r.body.length, 0);
    assertProblem(await http(d, 'GET', href), 404, 'not-found', 'GET deleted model');
    assertProblem(await http(d, 'GET', `${href}/mesh.glb`), 404, 'not-found', 'GET deleted mesh');
    const list = await http(d, 'GET', '/api/v1/models');
    assert.deepEqual(list.json.items, []);
  });
});
