// Unknown routes and wrong methods answer with problem+json.
import assert from 'node:assert/strict';
import { after, before, describe, it } from 'node:test';
import { assertProblem, http, removeDir, startDaemon } from './harness.js';

describe('routes', () => {
  let d;
  before(async () => { d = await startDaemon(); });
  after(async () => {
    if (d) { try { await d.stop(); } finally { await d.kill(); removeDir(d.dir); } }
  });

  it('an unknown API route is 404 problem+json', async () => {
    assertProblem(await http(d, 'GET', '/api/v1/no-such-thing'), 404, 'not-found', 'GET /api/v1/no-such-thing');
    assertProblem(await http(d, 'GET', '/api/v1/models/1/no-such-thing'), 404, 'not-found', 'GET /api/v1/models/1/no-such-thing');
    assertProblem(await http(d, 'GET', '/api/v2/health'), 404, 'not-found', 'GET /api/v2/health');
  });

  it('an unknown resource is 404 problem+json', async () => {
    assertProblem(await http(d, 'GET', '/api/v1/models/999999'), 404, 'not-found', 'GET model 999999');
    assertProblem(await http(d, 'GET', '/api/v1/models/999999/mesh.glb'), 404, 'not-found', 'GET mesh 999999');
    assertProblem(await http(d, 'GET', '/api/v1/jobs/999999'), 404, 'not-found', 'GET job 999999');
    assertProblem(await http(d, 'DELETE', '/api/v1/models/999999', { headers: { 'If-Match': '"1"' } }),
      404, 'not-found', 'DELETE model 999999');
  });

  it('a wrong method is 405 problem+json with Allow', async () => {
    const allowOf = (r) => (r.headers.get('allow') ?? '').split(',').map((s) => s.trim().toUpperCase()).filter(Boolean);

    let r = await http(d, 'PUT', '/api/v1/models', { body: {} });
    assertProblem(r, 405, 'method-not-allowed', 'PUT /api/v1/models');
    assert.ok(allowOf(r).includes('GET') && allowOf(r).includes('POST'), `Allow: ${r.headers.get('allow')}`);
    assert.ok(!allowOf(r).includes('PUT'), `Allow: ${r.headers.get('allow')}`);

    r = await http(d, 'DELETE', '/api/v1/health');
    assertProblem(r, 405, 'method-not-allowed', 'DELETE /api/v1/health');
    assert.ok(allowOf(r).includes('GET'), `Allow: ${r.headers.get('allow')}`);
    assert.ok(!allowOf(r).includes('DELETE'), `Allow: ${r.headers.get('allow')}`);

    r = await http(d, 'POST', '/api/v1/models/1/mesh.glb', { body: {} });
    assertProblem(r, 405, 'method-not-allowed', 'POST mesh.glb');
    assert.ok(allowOf(r).includes('GET'), `Allow: ${r.headers.get('allow')}`);
  });
});
