// Durability: archgramd killed (SIGKILL) in the middle of a stream of acked ops keeps every
// op it acked, and the database passes PRAGMA integrity_check; a database that fills up
// (--db-max-bytes) answers changes with a 507 problem, keeps everything it had and keeps
// answering reads.
import assert from 'node:assert/strict';
import { after, describe, it } from 'node:test';
import {
  assertProblem, http, importModel, removeDir, sleep, sql, startDaemon, tempDir, waitJob, WsClient,
} from './harness.js';

const OBJ = 'v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n';

describe('durability', () => {
  const dir = tempDir();
  let d;
  after(async () => {
    if (d) await d.kill();
    removeDir(dir);
  });

  it('kill -9 during a stream of acked ops: every acked op is there after a restart', async () => {
    d = await startDaemon({ dir, args: ['--no-web', '--rate-ws', '0', '--rate-rest', '0'] });
    const model = await importModel(d, Buffer.from(OBJ), { name: 'stream' });
    const writers = await Promise.all([0, 1, 2].map(async (i) => {
      const c = await WsClient.open(d.wsUrl);
      const w = await c.request({ type: 'hello', model: model.id, user: `writer${i}` }, 'welcome');
      return { c, i, version: w.version, acked: [] };
    }));
    // each writer sends notes one after the other (each made on the newest version it knows);
    // the daemon is killed while they are at it
    let stop = false;
    const loops = writers.map(async (w) => {
      w.c.ws.on('message', (data) => {
        const m = JSON.parse(data.toString('utf8'));
        if (m.type === 'op') w.version = Math.max(w.version, m.version);
      });
      for (let n = 0; !stop; n++) {
        const cid = `w${w.i}-${n}`;
        let r;
        try {
          r = await w.c.request({ type: 'op', cid, base: w.version, op: { kind: 'note', text: `note ${cid}` } },
            (m) => (m.type === 'ack' || m.type === 'nack') && m.cid === cid, 3000);
        } catch {
          break; // the daemon is gone
        }
        if (r.type === 'ack') {
          w.acked.push({ cid, version: r.version });
          w.version = Math.max(w.version, r.version);
        }
      }
    });
    await sleep(1500);
    d.proc.kill('SIGKILL');
    await d.exit;
    stop = true;
    await Promise.all(loops);
    const acked = writers.flatMap((w) => w.acked);
    assert.ok(acked.length >= 20, `only ${acked.length} acks before the kill`);
    // the file as the kill left it
    assert.deepEqual(sql(d.db, 'PRAGMA integrity_check'), [['ok']]);
    // a restart reads it, with every acked op at the version it was acked with
    d = await startDaemon({ dir, db: d.db, args: ['--no-web'] });
    const log = (await http(d, 'GET', `/api/v1/models/${model.id}/ops?since=0`)).json.items;
    const byCid = new Map(log.map((o) => [o.cid, o]));
    for (const a of acked) {
      const o = byCid.get(a.cid);
      assert.ok(o, `acked op ${a.cid} (version ${a.version}) is missing`);
      assert.equal(o.version, a.version, `op ${a.cid}`);
      assert.equal(o.op.text, `note ${a.cid}`);
    }
    // versions are dense: no gap, no duplicate
    const versions = log.map((o) => o.version).sort((x, y) => x - y);
    versions.forEach((v, i) => assert.equal(v, versions[0] + i));
    const m = (await http(d, 'GET', `/api/v1/models/${model.id}`)).json;
    assert.equal(m.version, versions.at(-1));
    await d.stop();
  });

  it('a full database answers changes with 507, keeps what it had and keeps answering reads', async () => {
    const full = tempDir();
    try {
      d = await startDaemon({ dir: full, args: ['--no-web', '--db-max-bytes', String(640 << 10), '--rate-jobs', '0', '--rate-rest', '0'] });
      const kept = [];
      let failed;
      for (let i = 0; i < 400 && !failed; i++) {
        // each upload keeps its source bytes: a few KiB
        const body = `${OBJ}# ${'x'.repeat(6000)} ${i}\n`;
        const up = await http(d, 'POST', `/api/v1/models?name=m${i}&format=obj`, {
          body, headers: { 'Content-Type': 'application/octet-stream' },
        });
        assert.ok(up.status === 202 || up.status === 507, `${up.status} ${up.text}`);
        if (up.status === 507) {
          failed = up;
          break;
        }
        const job = await waitJob(d, up.json.id);
        if (job.status === 'succeeded') kept.push(job.result.model);
        else failed = job;
      }
      assert.ok(failed, 'the database never filled');
      assert.ok(kept.length > 0);
      // the failure is the storage-full problem, whether the job or the request met it
      const problem = failed.error ?? failed.json;
      assert.equal(problem.type, 'urn:archgram:problem:storage-full', JSON.stringify(problem));
      assert.equal(problem.status, 507);
      // a change now is refused the same way, over REST
      const m = (await http(d, 'GET', `/api/v1/models/${kept[0]}`)).json;
      const note = await http(d, 'POST', `/api/v1/models/${kept[0]}/ops`, {
        body: { op: { kind: 'note', text: 'y'.repeat(3900) } }, headers: { 'If-Match': `"${m.version}"` },
      });
      if (note.status !== 200) assertProblem(note, 507, 'storage-full', 'a note in a full database');
      // reads go on, every kept model is whole
      for (const id of kept) {
        const r = await http(d, 'GET', `/api/v1/models/${id}`);
        assert.equal(r.status, 200, r.text);
        assert.equal(r.json.stats.triangles, 4);
      }
      assert.equal((await http(d, 'GET', '/api/v1/health')).status, 200);
      await d.stop();
      assert.deepEqual(sql(d.db, 'PRAGMA integrity_check'), [['ok']]);
      const rows = sql(d.db, 'SELECT count(*) FROM models');
      assert.equal(Number(rows[0][0]), kept.length);
      d = null;
    } finally {
      if (d) await d.kill();
      removeDir(full);
    }
  });
});
