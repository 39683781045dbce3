// Bad uploads: parse errors fail the job with the line and create no model; empty bodies
// and unknown formats are refused at once.
import assert from 'node:assert/strict';
import { after, before, describe, it } from 'node:test';
import {
  assertProblem, fixture, http, listModels, PROBLEM, removeDir, sql, startDaemon, upload, waitJob,
} from './harness.js';

describe('bad input', () => {
  let d;
  let stopped = false;
  before(async () => { d = await startDaemon(); });
  after(async () => {
    if (d) { try { if (!stopped) await d.stop(); } finally { await d.kill(); removeDir(d.dir); } }
  });

  async function failedImport(file, line, what) {
    const before = await listModels(d);
    const job = await upload(d, fixture(file), { name: file });
    const done = await waitJob(d, job.id);
    assert.equal(done.status, 'failed', `${file}: ${JSON.stringify(done)}`);
    assert.equal(done.result, null);
    const e = done.error;
    assert.ok(e && typeof e === 'object', `${file}: job.error ${JSON.stringify(e)}`);
    assert.equal(e.type, `${PROBLEM}parse`, `${file}: ${JSON.stringify(e)}`);
    assert.equal(e.status, 422, `${file}: ${JSON.stringify(e)}`);
    assert.equal(typeof e.title, 'string');
    assert.match(e.detail, new RegExp(`\\bline ${line}\\b`), `${file}: detail should name line ${line}: ${e.detail}`);
    if (what) assert.match(e.detail, what, `${file}: detail ${e.detail}`);
    assert.equal(e.line, line, `${file}: error.line`);
    const after = await listModels(d);
    assert.deepEqual(after.map((m) => m.id), before.map((m) => m.id), `${file}: a model was created`);
    return done;
  }

  it('a face index out of range on line 5 → job failed, 422, line 5, no model', async () => {
    await failedImport('bad_index_line5.obj', 5, /index|range|vertex/i);
  });

  it('a NaN coordinate → job failed with its line', async () => {
    await failedImport('nan_coordinate.obj', 3);
  });

  it('a truncated vertex line → job failed with its line', async () => {
    await failedImport('truncated_line.obj', 4);
  });

  it('a file without triangles → job failed, no model', async () => {
    const before = await listModels(d);
    const done = await waitJob(d, (await upload(d, fixture('no_triangles.obj'))).id);
    assert.equal(done.status, 'failed', JSON.stringify(done));
    assert.ok(done.error && done.error.type.startsWith(PROBLEM), JSON.stringify(done.error));
    assert.ok(done.error.status >= 400 && done.error.status < 500, JSON.stringify(done.error));
    assert.deepEqual((await listModels(d)).length, before.length);
  });

  it('an empty or missing body → 400 problem+json, no job', async () => {
    assertProblem(await http(d, 'POST', '/api/v1/models?name=e&format=obj', { body: '' }), 400, null, 'empty body');
    assertProblem(await http(d, 'POST', '/api/v1/models?name=e&format=obj'), 400, null, 'no body');
    const form = new FormData();
    form.append('name', 'no file part');
    assertProblem(await http(d, 'POST', '/api/v1/models?format=obj', { body: form }), 400, null, 'multipart without file');
  });

  it('an unknown format → 415 problem+json', async () => {
    // (xyz, once unknown here, is a point cloud format now)
    const r = await http(d, 'POST', '/api/v1/models?name=u&format=dwg', { body: fixture('two_boxes.obj') });
    assertProblem(r, 415, 'unsupported', 'format=dwg');
  });

  it('after shutdown the database holds no model and is intact', async () => {
    const n = (await listModels(d)).length;
    assert.equal(n, 0);
    await d.stop();
    stopped = true;
    assert.deepEqual(sql(d.db, 'select count(*) from models'), [['0']]);
    const failed = sql(d.db, "select count(*) from jobs where status = 'failed'");
    assert.ok(Number(failed[0][0]) >= 4, `failed jobs in the database: ${failed}`);
    assert.deepEqual(sql(d.db, 'pragma integrity_check'), [['ok']]);
  });
});
