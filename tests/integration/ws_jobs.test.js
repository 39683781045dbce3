// Job progress over the websocket: watch → job.progress* → one job.done.
import assert from 'node:assert/strict';
import path from 'node:path';
import fs from 'node:fs';
import { after, before, describe, it } from 'node:test';
import {
  fixture, http, PROBLEM, removeDir, sleep, startDaemon, upload, waitJob, writeGridObj, WsClient,
} from './harness.js';

describe('jobs over the websocket', () => {
  let d;
  let W;
  before(async () => {
    d = await startDaemon();
    W = await WsClient.open(d.wsUrl);
  });
  after(async () => {
    if (W) await W.close().catch(() => {});
    if (d) { try { await d.stop(); } finally { await d.kill(); removeDir(d.dir); } }
  });

  it('a running import reports progress and finishes with one job.done', async (t) => {
    // Large enough (a few MB) that the job is usually still running when watched.
    const file = path.join(d.dir, 'grid.obj');
    const grid = writeGridObj(file, 6e6);
    const job = await upload(d, fs.readFileSync(file), { name: 'grid' });
    W.send({ type: 'watch', job: job.id });
    const done = await W.next((m) => m.type === 'job.done' && m.job === job.id, 60000, 'job.done');
    assert.equal(done.status, 'succeeded', JSON.stringify(done));
    assert.ok(Number.isInteger(done.result?.model), JSON.stringify(done));
    assert.equal(done.error, null);
    const progress = W.all.filter((m) => m.type === 'job.progress' && m.job === job.id);
    t.diagnostic(`${progress.length} job.progress messages before job.done`);
    let last = 0;
    for (const p of progress) {
      assert.ok(['queued', 'running'].includes(p.status), JSON.stringify(p));
      assert.ok(p.progress >= last && p.progress <= 1, `progress not monotone in 0..1: ${JSON.stringify(progress)}`);
      last = p.progress;
    }
    assert.ok(W.all.indexOf(done) > W.all.indexOf(progress.at(-1)), 'job.done comes last');
    await W.none((m) => m.type === 'job.done' && m.job === job.id, 300, 'second job.done');
    const m = (await http(d, 'GET', done.result.href ?? `/api/v1/models/${done.result.model}`)).json;
    assert.equal(m.stats.vertices, grid.vertices);
    assert.equal(m.stats.triangles, grid.triangles);
  });

  it('a job already finished gets its job.done at once', async () => {
    const job = await upload(d, fixture('two_boxes.obj'), { name: 'small' });
    const rest = await waitJob(d, job.id);
    const done = await W.request({ type: 'watch', job: job.id },
      (m) => m.type === 'job.done' && m.job === job.id, 3000, 'job.done of a finished job');
    assert.equal(done.status, 'succeeded');
    assert.equal(done.result.model, rest.result.model);
  });

  it('a failed job reports its problem in job.done', async () => {
    const job = await upload(d, fixture('bad_index_line5.obj'), { name: 'bad' });
    const done = await W.request({ type: 'watch', job: job.id },
      (m) => m.type === 'job.done' && m.job === job.id, 10000, 'job.done of a failed job');
    assert.equal(done.status, 'failed');
    assert.equal(done.result, null);
    assert.equal(done.error.type, `${PROBLEM}parse`);
    assert.equal(done.error.line, 5);
  });

  it('DELETE on a running job cancels it: job.done cancelled, no model', async () => {
    const file = path.join(d.dir, 'cancel.obj');
    writeGridObj(file, 30e6);
    const before = (await http(d, 'GET', '/api/v1/models?page_size=200')).json.items.length;
    const job = await upload(d, fs.readFileSync(file), { name: 'to cancel' });
    W.send({ type: 'watch', job: job.id });
    let status = job.status;
    const t0 = Date.now();
    while (status === 'queued') {
      assert.ok(Date.now() - t0 < 30000, 'job never started');
      await sleep(10);
      status = (await http(d, 'GET', `/api/v1/jobs/${job.id}`)).json.status;
    }
    assert.equal(status, 'running', 'the job finished before it could be cancelled');
    const del = await http(d, 'DELETE', `/api/v1/jobs/${job.id}`);
    assert.equal(del.status, 200, del.text);
    assert.equal(del.json.id, job.id);
    const done = await W.next((m) => m.type === 'job.done' && m.job === job.id, 30000, 'job.done after cancel');
    assert.equal(done.status, 'cancelled', JSON.stringify(done));
    assert.equal(done.result, null);
    const rest = await waitJob(d, job.id);
    assert.equal(rest.status, 'cancelled');
    assert.equal((await http(d, 'GET', '/api/v1/models?page_size=200')).json.items.length, before);
  });

  it('watching an unknown job is an error', async () => {
    const e = await W.request({ type: 'watch', job: 999999 }, (m) => m.type === 'error' || m.type === 'job.done');
    assert.equal(e.type, 'error', JSON.stringify(e));
    assert.equal(e.problem.status, 404);
  });
});
