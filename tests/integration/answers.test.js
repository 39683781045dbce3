// Every message gets an answer: problems whose detail quotes long non-ASCII input (cut between
// UTF-8 characters, never inside one), a URL that is not UTF-8, oversized URLs and headers,
// absurd Content-Length, bad chunking, If-Match tags of every well-formed shape; over REST and
// over the websocket (ack or nack, never silence).
import assert from 'node:assert/strict';
import { after, before, describe, it } from 'node:test';
import {
  assertProblem, http, rawRequest, removeDir, startDaemon, waitJob, WsClient,
} from './harness.js';

// Strict UTF-8 check of a Buffer (what JSON text on the wire must be).
function validUtf8(buf) {
  try {
    new TextDecoder('utf-8', { fatal: true }).decode(buf);
    return true;
  } catch {
    return false;
  }
}

describe('every message answered', () => {
  let d;
  let model;
  before(async () => {
    d = await startDaemon({ args: ['--no-web', '--demo'] });
    // the demo's models are proceduralized by jobs: wait for them
    for (let i = 1; i <= 3; i++) {
      const j = await http(d, 'GET', `/api/v1/jobs/${i}`);
      if (j.status === 200) await waitJob(d, i, { timeout: 60000 });
    }
    model = (await http(d, 'GET', '/api/v1/models/2')).json;
  });
  after(async () => {
    if (d) { try { await d.stop(); } finally { await d.kill(); removeDir(d.dir); } }
  });

  // Op members made of multi-byte characters whose refusal quotes them past the 256-byte
  // error buffer: every cut position of a 2-, 3- and 4-byte character.
  const names = [];
  for (const ch of ['é', '€', '𝄞']) for (let pad = 0; pad < 4; pad++) names.push('x'.repeat(pad) + ch.repeat(100));

  it('REST: an op refusal that quotes long multi-byte input is a valid problem', async () => {
    for (const name of names) {
      const r = await http(d, 'POST', `/api/v1/models/${model.id}/ops`, {
        body: { op: { kind: 'note', text: 'hello', [name]: 1 } },
        headers: { 'If-Match': `"${model.version}"` },
      });
      assertProblem(r, 400, 'invalid', `member ${name.slice(0, 8)}…`);
      assert.ok(validUtf8(r.body), 'the problem is UTF-8');
      assert.match(r.json.detail, /op member/);
      // the detail ends on a whole character of the name
      assert.ok(name.startsWith(r.json.detail.split('"')[1]), r.json.detail);
    }
  });

  it('websocket: an op refusal and an unknown type quoting long multi-byte input are answered', async () => {
    const c = await WsClient.open(d.wsUrl);
    try {
      await c.request({ type: 'hello', model: model.id, user: 'utf' }, 'welcome');
      for (const [i, name] of names.entries()) {
        const nack = await c.request({ type: 'op', cid: `u-${i}`, base: model.version, op: { kind: 'note', text: 'x', [name]: 1 } },
          (m) => m.cid === `u-${i}`, 5000, `the answer to op u-${i}`);
        assert.equal(nack.type, 'nack', JSON.stringify(nack));
        assert.equal(nack.problem.status, 400);
        assert.match(nack.problem.detail, /op member/);
      }
      for (const ch of ['€', 'é', '𝄞']) {
        const err = await c.request({ type: ch.repeat(80) }, 'error', 5000, 'the error for an unknown type');
        assert.match(err.problem.detail, /unknown message type/);
      }
      // and the connection still works
      const ack = await c.request({ type: 'op', cid: 'u-ok', base: model.version, op: { kind: 'note', text: 'still here' } },
        (m) => m.cid === 'u-ok');
      assert.equal(ack.type, 'ack', JSON.stringify(ack));
      model.version = ack.version;
    } finally {
      await c.close();
    }
  });

  it('a URL that is not UTF-8 after decoding is a 400 problem', async () => {
    for (const p of ['/api/v1/models/%ff', '/api/v1/%c3%28', '/%ed%a0%80', '/api/v1/models/1/%f0%9f']) {
      const r = await rawRequest(d.port, `GET ${p} HTTP/1.1\r\nHost: x\r\nConnection: close\r\n\r\n`);
      assert.equal(r.status, 400, `${p}: ${r.text}`);
      assert.match(r.headers['content-type'], /^application\/problem\+json/, p);
      assert.equal(r.json.type, 'urn:archgram:problem:invalid', p);
      assert.match(r.json.detail, /UTF-8/, p);
    }
  });

  it('a long URL is a 414 problem, large headers a 431 problem, an absurd length a 413 problem', async () => {
    const long = await rawRequest(d.port, `GET /api/v1/models?x=${'a'.repeat(20000)} HTTP/1.1\r\nHost: x\r\nConnection: close\r\n\r\n`);
    assert.equal(long.status, 414, long.text);
    assert.equal(long.json.type, 'urn:archgram:problem:uri-too-long');
    const big = await rawRequest(d.port, `GET /api/v1/health HTTP/1.1\r\nHost: x\r\nX-Big: ${'b'.repeat(30000)}\r\nConnection: close\r\n\r\n`);
    assert.equal(big.status, 431, big.text);
    assert.equal(big.json.type, 'urn:archgram:problem:headers-too-large');
    const absurd = await rawRequest(d.port, 'POST /api/v1/extrusions/preview HTTP/1.1\r\nHost: x\r\nContent-Type: application/json\r\nContent-Length: 999999999999999\r\nConnection: close\r\n\r\n');
    assert.equal(absurd.status, 413, absurd.text);
    assert.equal(absurd.json.type, 'urn:archgram:problem:too-large');
  });

  it('what libmicrohttpd refuses itself (bad chunking, an unparsable length, a URL past its memory) is still answered', async () => {
    const chunked = await rawRequest(d.port, 'POST /api/v1/extrusions/preview HTTP/1.1\r\nHost: x\r\nTransfer-Encoding: chunked\r\nConnection: close\r\n\r\nzz\r\nabc\r\n0\r\n\r\n');
    assert.equal(chunked.status, 400);
    const overflow = await rawRequest(d.port, 'POST /api/v1/extrusions/preview HTTP/1.1\r\nHost: x\r\nContent-Length: 99999999999999999999999\r\nConnection: close\r\n\r\n');
    assert.ok(overflow.status === 413 || overflow.status === 400, String(overflow.status));
    const huge = await rawRequest(d.port, `GET /api/v1/models?x=${'a'.repeat(200000)} HTTP/1.1\r\nHost: x\r\nConnection: close\r\n\r\n`);
    assert.ok(huge.status === 414 || huge.status === 431, String(huge.status));
    // the server is fine afterwards
    assert.equal((await http(d, 'GET', '/api/v1/health')).status, 200);
  });

  it('If-Match: any well-formed tag that does not name the version is 412; a list naming it matches', async () => {
    const up = await http(d, 'POST', `/api/v1/models?name=target&format=obj`, {
      body: 'v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n', headers: { 'Content-Type': 'application/octet-stream' },
    });
    const done = await waitJob(d, up.json.id);
    const href = done.result.href;
    let v = (await http(d, 'GET', href)).json.version;
    for (const tag of ['"stale-0"', '"0"', 'W/"1"', `W/"${v}"`, '""', '"abc", "def"', `"${v + 1}", "${v + 2}"`]) {
      const r = await http(d, 'DELETE', href, { headers: { 'If-Match': tag } });
      assertProblem(r, 412, 'stale', `DELETE If-Match: ${tag}`);
      assert.equal(r.json.element, v, 'the problem names the current version');
      const p = await http(d, 'PATCH', href, { body: { name: 'n' }, headers: { 'If-Match': tag } });
      assertProblem(p, 412, 'stale', `PATCH If-Match: ${tag}`);
    }
    for (const bad of ['stale-0', '"unterminated', 'W/', '"a" "b"', '"a",,x']) {
      assertProblem(await http(d, 'DELETE', href, { headers: { 'If-Match': bad } }), 400, 'invalid', `If-Match: ${bad}`);
    }
    assert.equal((await http(d, 'GET', href)).status, 200, 'nothing was deleted');
    const renamed = await http(d, 'PATCH', href, { body: { name: 'listed' }, headers: { 'If-Match': `"stale-0", "${v}"` } });
    assert.equal(renamed.status, 200, renamed.text);
    v = renamed.json.version;
    const del = await http(d, 'DELETE', href, { headers: { 'If-Match': `W/"x", "${v}"` } });
    assert.equal(del.status, 204, del.text);
  });
});
