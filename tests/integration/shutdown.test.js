// SIGTERM while an import runs: the daemon exits 0 promptly, the job ends cancelled (or
// failed for the shutdown), no model row is left half-written, the file is intact.
import assert from 'node:assert/strict';
import fs from 'node:fs';
import path from 'node:path';
import { after, describe, it } from 'node:test';
import {
  http, PROBLEM, removeDir, sleep, sql, startDaemon, tempDir, writeGridObj,
} from './harness.js';

describe('shutdown during a job', () => {
  const dir = tempDir();
  let d;
  after(async () => {
    if (d) await d.kill();
    removeDir(dir);
  });

  it('SIGTERM while importing a large OBJ', { timeout: 180000 }, async (t) => {
    const file = path.join(dir, 'large.obj');
    const grid = writeGridObj(file, 60e6);
    const body = fs.readFileSync(file);
    assert.ok(body.length > 40e6, `generated ${body.length} bytes`);

    d = await startDaemon({ dir, args: ['--workers', '1'] });
    const r = await http(d, 'POST', '/api/v1/models?name=large&format=obj', {
      body, headers: { 'Content-Type': 'application/octet-stream' }, timeout: 120000,
    });
    assert.equal(r.status, 202, r.text);
    const id = r.json.id;

    // Wait until the worker has started on it.
    let status = r.json.status;
    const t0 = Date.now();
    while (status !== 'running') {
      assert.ok(['queued', 'running'].includes(status),
        `job ${id} is ${status} before SIGTERM could be sent (a ${grid.triangles}-triangle import finished too fast?)`);
      assert.ok(Date.now() - t0 < 30000, 'job never started running');
      await sleep(10);
      status = (await http(d, 'GET', `/api/v1/jobs/${id}`)).json.status;
    }
    const { ms } = await d.stop(10000);
    assert.ok(ms < 10000, `exit took ${ms} ms`);

    const rows = sql(d.db, `select status from jobs where id = ${id}`);
    assert.equal(rows.length, 1, 'the job row exists');
    const final = rows[0][0];
    t.diagnostic(`${(body.length / 1e6).toFixed(1)} MB OBJ; SIGTERM while running; exit 0 after ${ms} ms; job ${final}`);
    assert.ok(['cancelled', 'failed'].includes(final), `job row status ${final}`);
    assert.deepEqual(sql(d.db, 'select count(*) from models'), [['0']], 'no model row for the interrupted import');
    assert.deepEqual(sql(d.db, 'pragma integrity_check'), [['ok']]);

    d = await startDaemon({ dir, db: d.db });
    const j = await http(d, 'GET', `/api/v1/jobs/${id}`);
    assert.equal(j.status, 200, j.text);
    assert.equal(j.json.status, final);
    assert.equal(j.json.result, null);
    if (final === 'failed') {
      assert.ok(j.json.error?.type?.startsWith(PROBLEM), JSON.stringify(j.json.error));
      assert.match(j.json.error.detail, /shut|terminat|stop/i, 'a failed job names the shutdown');
    }
    assert.deepEqual((await http(d, 'GET', '/api/v1/models')).json.items, []);
    await d.stop();
    d = null;
  });
});
