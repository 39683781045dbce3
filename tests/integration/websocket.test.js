// The live protocol (schema/websocket.md): rooms, sequenced ops, presence, catch-up,
// idempotent retries, errors that keep the connection, REST ops broadcast to the room.
import assert from 'node:assert/strict';
import { after, before, describe, it } from 'node:test';
import {
  fixture, http, importModel, PROBLEM, removeDir, startDaemon, WsClient,
} from './harness.js';

describe('websocket rooms and ops', () => {
  let d;
  let model;
  const clients = [];
  let A; let B; let aId; let bId;
  let version; // the model's current version as the test knows it

  const open = async () => { const c = await WsClient.open(d.wsUrl); clients.push(c); return c; };
  const isAck = (cid) => (m) => m.type === 'ack' && m.cid === cid;
  const isNack = (cid) => (m) => m.type === 'nack' && m.cid === cid;
  const isOp = (cid) => (m) => m.type === 'op' && m.cid === cid;
  const restModel = async () => (await http(d, 'GET', model.href)).json;

  before(async () => {
    d = await startDaemon();
    model = await importModel(d, fixture('two_boxes.obj'), { name: 'room' });
    version = model.version;
  });
  after(async () => {
    for (const c of clients) await c.close().catch(() => {});
    if (d) { try { await d.stop(); } finally { await d.kill(); removeDir(d.dir); } }
  });

  it('hello → welcome; the room sees joins', async () => {
    A = await open();
    const wa = await A.request({ type: 'hello', model: model.id, user: 'ana' }, 'welcome');
    assert.equal(wa.model, model.id);
    assert.equal(wa.version, version);
    assert.equal(typeof wa.you, 'string');
    assert.deepEqual(wa.ops, [], 'no since, no ops');
    assert.deepEqual(wa.peers, []);
    aId = wa.you;

    B = await open();
    const wb = await B.request({ type: 'hello', model: model.id, user: 'bo' }, 'welcome');
    bId = wb.you;
    assert.notEqual(aId, bId);
    assert.deepEqual(wb.peers, [{ peer: aId, user: 'ana', state: null }]);
    const join = await A.next('join');
    assert.deepEqual(join, { type: 'join', peer: bId, user: 'bo' });
  });

  it('an op is acked to its author and broadcast to the others', async () => {
    const op = { kind: 'rename', name: 'Hall' };
    A.send({ type: 'op', base: version, cid: 'c-1', op });
    const ack = await A.next(isAck('c-1'));
    assert.equal(ack.version, version + 1);
    const got = await B.next(isOp('c-1'));
    assert.equal(got.version, version + 1);
    assert.equal(got.author, 'ana');
    assert.deepEqual(got.op, op);
    await A.none(isOp('c-1'), 200, 'op echo to its author');
    version += 1;
    const m = await restModel();
    assert.equal(m.name, 'Hall');
    assert.equal(m.version, version);
  });

  it('presence reaches the others with the user; a late joiner gets peers with states', async () => {
    const state = { name: 'ana', selection: [3, 4], camera: { position: [1, 2, 3], target: [0, 0, 0] } };
    A.send({ type: 'presence', state });
    const p = await B.next('presence');
    assert.deepEqual(p, { type: 'presence', peer: aId, user: 'ana', state });
    await A.none('presence', 200, 'presence echo to its author');

    const C = await open();
    const wc = await C.request({ type: 'hello', model: model.id, user: 'cy' }, 'welcome');
    const peers = [...wc.peers].sort((x, y) => x.peer.localeCompare(y.peer));
    const expected = [{ peer: aId, user: 'ana', state }, { peer: bId, user: 'bo', state: null }]
      .sort((x, y) => x.peer.localeCompare(y.peer));
    assert.deepEqual(peers, expected);
    assert.equal(wc.version, version);
    await A.next((m) => m.type === 'join' && m.user === 'cy');
    await B.next((m) => m.type === 'join' && m.user === 'cy');
    await C.close();
    assert.deepEqual(await A.next('leave'), { type: 'leave', peer: wc.you });
    assert.deepEqual(await B.next('leave'), { type: 'leave', peer: wc.you });
  });

  it('an op on a stale base is nacked with the current version and nothing is broadcast', async () => {
    B.send({ type: 'op', base: version - 1, cid: 'b-1', op: { kind: 'rename', name: 'Stale' } });
    const nack = await B.next(isNack('b-1'));
    assert.equal(nack.version, version);
    assert.equal(nack.problem?.type, `${PROBLEM}stale`, JSON.stringify(nack));
    await A.none(isOp('b-1'), 200, 'broadcast of a refused op');
    const m = await restModel();
    assert.equal(m.name, 'Hall');
    assert.equal(m.version, version);
  });

  it('two ops on the same base at once: one ack, one stale nack', async () => {
    A.send({ type: 'op', base: version, cid: 'race-a', op: { kind: 'note', text: 'a' } });
    B.send({ type: 'op', base: version, cid: 'race-b', op: { kind: 'note', text: 'b' } });
    const ra = await A.next((m) => (m.type === 'ack' || m.type === 'nack') && m.cid === 'race-a');
    const rb = await B.next((m) => (m.type === 'ack' || m.type === 'nack') && m.cid === 'race-b');
    assert.deepEqual([ra.type, rb.type].sort(), ['ack', 'nack'], JSON.stringify([ra, rb]));
    const [win, lose, other] = ra.type === 'ack' ? [ra, rb, B] : [rb, ra, A];
    assert.equal(win.version, version + 1);
    assert.equal(lose.version, version + 1);
    assert.equal(lose.problem.type, `${PROBLEM}stale`);
    await other.next(isOp(win.cid));
    version += 1;
  });

  it('an invalid op is nacked', async () => {
    B.send({ type: 'op', base: version, cid: 'b-2', op: { kind: 'rename', name: '' } });
    const nack = await B.next(isNack('b-2'));
    assert.equal(nack.version, version);
    assert.ok(nack.problem && nack.problem.status >= 400, JSON.stringify(nack));
    B.send({ type: 'op', base: version, cid: 'b-3', op: { kind: 'no-such-kind' } });
    await B.next(isNack('b-3'));
    await A.none((m) => m.type === 'op', 200, 'broadcast of an invalid op');
    assert.equal((await restModel()).version, version);
  });

  it('a repeated cid is acked with its first version and applied once', async () => {
    const msg = { type: 'op', base: version, cid: 'c-2', op: { kind: 'note', text: 'look at the roof' } };
    A.send(msg);
    const ack1 = await A.next(isAck('c-2'));
    assert.equal(ack1.version, version + 1);
    await B.next(isOp('c-2'));
    version += 1;
    A.send(msg); // the same retry, its base now stale
    const ack2 = await A.next(isAck('c-2'));
    assert.equal(ack2.version, ack1.version);
    await B.none(isOp('c-2'), 300, 'second broadcast of a retried op');
    assert.equal((await restModel()).version, version);
    const ops = await http(d, 'GET', `${model.href}/ops?since=0`);
    assert.equal(ops.status, 200, ops.text);
    assert.equal(ops.json.items.filter((o) => o.cid === 'c-2').length, 1, JSON.stringify(ops.json));
  });

  it('a reconnect with since gets exactly the missed ops, in order', async () => {
    const since = version;
    await B.close();
    await A.next((m) => m.type === 'leave' && m.peer === bId);
    const sent = [
      { cid: 'c-3', op: { kind: 'note', text: 'first while away' } },
      { cid: 'c-4', op: { kind: 'rename', name: 'Hall 2' } },
    ];
    for (const s of sent) {
      A.send({ type: 'op', base: version, ...s });
      const ack = await A.next(isAck(s.cid));
      assert.equal(ack.version, version + 1);
      version += 1;
    }
    B = await open();
    const wb = await B.request({ type: 'hello', model: model.id, since, user: 'bo' }, 'welcome');
    bId = wb.you;
    assert.equal(wb.version, version);
    assert.equal(wb.ops.length, 2, JSON.stringify(wb.ops));
    wb.ops.forEach((o, i) => {
      assert.equal(o.version, since + 1 + i);
      assert.equal(o.author, 'ana');
      assert.equal(o.cid, sent[i].cid);
      assert.deepEqual(o.op, sent[i].op);
      assert.equal(typeof o.at, 'string');
    });
    await A.next((m) => m.type === 'join' && m.peer === bId);
  });

  it('malformed JSON, unknown types, binary and oversized frames get an error; the connection stays', async () => {
    const isError = (m) => m.type === 'error';
    const check = (e, what) => {
      assert.equal(typeof e.problem, 'object', `${what}: ${JSON.stringify(e)}`);
      assert.ok(e.problem.type.startsWith(PROBLEM), `${what}: ${JSON.stringify(e)}`);
      assert.ok(e.problem.status >= 400 && e.problem.status < 500, `${what}: ${JSON.stringify(e)}`);
      assert.equal(typeof e.problem.detail, 'string');
    };
    check(await A.request('{"type": "op", ', isError, 5000, 'error for malformed JSON'), 'malformed JSON');
    check(await A.request({ type: 'no-such-type' }, isError, 5000, 'error for an unknown type'), 'unknown type');
    check(await A.request('[1, 2, 3]', isError, 5000, 'error for a non-object'), 'non-object');
    check(await A.request(Buffer.from([1, 2, 3]), isError, 5000, 'error for a binary frame'), 'binary frame');
    const big = JSON.stringify({ type: 'presence', state: { pad: 'x'.repeat((1 << 20) + 1000) } });
    check(await A.request(big, isError, 10000, 'error for a frame over 1 MiB'), 'oversized frame');
    const fat = { type: 'presence', state: { pad: 'y'.repeat(20 * 1024) } };
    check(await A.request(fat, isError, 5000, 'error for presence over 16 KiB'), 'presence over 16 KiB');
    await B.none((m) => m.type === 'presence' && JSON.stringify(m).length > 16 * 1024, 200, 'oversized presence broadcast');

    // Still in the room and still sequencing.
    A.send({ type: 'op', base: version, cid: 'c-5', op: { kind: 'note', text: 'still here' } });
    assert.equal((await A.next(isAck('c-5'))).version, version + 1);
    await B.next(isOp('c-5'));
    version += 1;
  });

  it('REST PATCH and POST ops are broadcast to the room', async () => {
    const r = await http(d, 'PATCH', model.href, {
      body: { name: 'Renamed over REST' },
      headers: { 'If-Match': `"${version}"`, 'X-Archgram-User': 'rest-user' },
    });
    assert.equal(r.status, 200, r.text);
    version += 1;
    for (const c of [A, B]) {
      const op = await c.next((m) => m.type === 'op' && m.op?.kind === 'rename' && m.op.name === 'Renamed over REST');
      assert.equal(op.version, version);
      assert.equal(op.author, 'rest-user');
    }

    const n = await http(d, 'POST', `${model.href}/ops`, {
      body: { cid: 'rest-1', op: { kind: 'note', text: 'from REST' } },
      headers: { 'If-Match': `"${version}"` },
    });
    assert.equal(n.status, 200, n.text);
    assert.equal(n.json.version, version + 1, n.text);
    version += 1;
    for (const c of [A, B]) {
      const op = await c.next(isOp('rest-1'));
      assert.equal(op.version, version);
      assert.equal(op.author, 'api');
      assert.deepEqual(op.op, { kind: 'note', text: 'from REST' });
    }
    const log = await http(d, 'GET', `${model.href}/ops?since=${version - 2}`);
    assert.deepEqual(log.json.items.map((o) => [o.version, o.author]), [[version - 1, 'rest-user'], [version, 'api']]);
  });

  it('hello for an unknown model is an error', async () => {
    const C = await open();
    const e = await C.request({ type: 'hello', model: 999999, user: 'x' }, (m) => m.type === 'error' || m.type === 'welcome');
    assert.equal(e.type, 'error', JSON.stringify(e));
    assert.equal(e.problem.status, 404);
  });
});
