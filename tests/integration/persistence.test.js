// Models, versions and the op log survive a restart on the same database.
import assert from 'node:assert/strict';
import { after, describe, it } from 'node:test';
import {
  fixture, http, importModel, removeDir, sql, startDaemon, tempDir, WsClient,
} from './harness.js';

describe('restart persistence', () => {
  const dir = tempDir();
  let d;
  let ws;
  after(async () => {
    if (ws) await ws.close().catch(() => {});
    if (d) await d.kill();
    removeDir(dir);
  });

  it('models, versions, ops and meshes survive a restart', async () => {
    d = await startDaemon({ dir });
    const a = await importModel(d, fixture('two_boxes.obj'), { name: 'kept' });
    const b = await importModel(d, fixture('two_boxes.obj'), { name: 'also kept', up: 'z' });
    const v0 = a.version;
    let r = await http(d, 'PATCH', a.href, { body: { name: 'kept, renamed' }, headers: { 'If-Match': `"${v0}"`, 'X-Archgram-User': 'ana' } });
    assert.equal(r.status, 200, r.text);
    r = await http(d, 'POST', `${a.href}/ops`, { body: { cid: 'n-1', op: { kind: 'note', text: 'persist me' } }, headers: { 'If-Match': `"${v0 + 1}"` } });
    assert.equal(r.status, 200, r.text);
    const glb = (await http(d, 'GET', a.mesh)).body;
    const opsBefore = (await http(d, 'GET', `${a.href}/ops?since=0`)).json.items;
    assert.ok(opsBefore.length >= 2, JSON.stringify(opsBefore));
    const listBefore = (await http(d, 'GET', '/api/v1/models')).json.items;
    await d.stop();

    assert.equal(sql(d.db, 'select count(*) from models')[0][0], '2');
    assert.deepEqual(sql(d.db, 'pragma integrity_check'), [['ok']]);

    d = await startDaemon({ dir, db: d.db });
    const listAfter = (await http(d, 'GET', '/api/v1/models')).json.items;
    assert.deepEqual(listAfter, listBefore);
    const m = await http(d, 'GET', a.href);
    assert.equal(m.json.name, 'kept, renamed');
    assert.equal(m.json.version, v0 + 2);
    assert.equal(m.headers.get('etag'), `"${v0 + 2}"`);
    assert.deepEqual((await http(d, 'GET', b.href)).json, b);
    const opsAfter = (await http(d, 'GET', `${a.href}/ops?since=0`)).json.items;
    assert.deepEqual(opsAfter, opsBefore);
    const tail = opsAfter.slice(-2);
    assert.deepEqual(tail.map((o) => [o.version, o.author, o.op.kind]), [[v0 + 1, 'ana', 'rename'], [v0 + 2, 'api', 'note']]);
    assert.equal(tail[1].cid, 'n-1');
    assert.ok((await http(d, 'GET', a.mesh)).body.equals(glb), 'same GLB after restart');

    // The websocket replays the persisted log, and versions continue from where they were.
    ws = await WsClient.open(d.wsUrl);
    const w = await ws.request({ type: 'hello', model: a.id, since: v0, user: 'bo' }, 'welcome');
    assert.equal(w.version, v0 + 2);
    assert.deepEqual(w.ops.map((o) => o.version), [v0 + 1, v0 + 2]);
    ws.send({ type: 'op', base: v0 + 2, cid: 'after-restart', op: { kind: 'note', text: 'x' } });
    assert.equal((await ws.next((x) => x.type === 'ack' && x.cid === 'after-restart')).version, v0 + 3);
    // A cid used before the restart is still recognised.
    ws.send({ type: 'op', base: v0 + 3, cid: 'n-1', op: { kind: 'note', text: 'persist me' } });
    const again = await ws.next((x) => x.type === 'ack' || x.type === 'nack');
    // n-1 was used by author "api", not "bo": for bo it is a new cid.
    assert.equal(again.type, 'ack', JSON.stringify(again));
    assert.equal(again.version, v0 + 4);
    await ws.close();
    ws = null;

    // New models continue the id sequence.
    const c = await importModel(d, fixture('two_boxes.obj'), { name: 'third' });
    assert.ok(c.id > b.id);
    await d.stop();
    d = null;
  });
});
