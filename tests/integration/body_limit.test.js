// --max-body: 413 from Content-Length before reading, and while streaming a chunked body.
import assert from 'node:assert/strict';
import { after, before, describe, it } from 'node:test';
import { assertProblem, http, rawRequest, removeDir, startDaemon, waitJob } from './harness.js';

const LIMIT = 1000;

// A valid OBJ of about `bytes` bytes (comment padding after one triangle).
function objOfSize(bytes) {
  const head = 'v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n';
  let s = head;
  while (s.length < bytes) s += `# ${'p'.repeat(Math.min(60, Math.max(0, bytes - s.length - 3)))}\n`;
  return s;
}

function asProblem(r) {
  // rawRequest results look like fetch ones for assertProblem.
  return { status: r.status, text: r.text, json: r.json, headers: { get: (k) => r.headers[k.toLowerCase()] } };
}

describe('body limit', () => {
  let d;
  before(async () => { d = await startDaemon({ args: ['--max-body', String(LIMIT)] }); });
  after(async () => {
    if (d) { try { await d.stop(); } finally { await d.kill(); removeDir(d.dir); } }
  });

  it('a body under the limit is accepted', async () => {
    const body = objOfSize(LIMIT - 100);
    const r = await http(d, 'POST', '/api/v1/models?name=small&format=obj', { body });
    assert.equal(r.status, 202, r.text);
    assert.equal((await waitJob(d, r.json.id)).status, 'succeeded');
  });

  it('Content-Length over the limit → 413 problem+json', async () => {
    const body = objOfSize(5 * LIMIT);
    const r = await http(d, 'POST', '/api/v1/models?name=big&format=obj', { body });
    assertProblem(r, 413, 'too-large', 'Content-Length 5000');
  });

  it('Content-Length over the limit is refused without sending the body', async () => {
    const head = `POST /api/v1/models?name=big&format=obj HTTP/1.1\r\nHost: 127.0.0.1\r\n` +
      `Content-Type: application/octet-stream\r\nContent-Length: 100000000\r\n\r\n`;
    const r = await rawRequest(d.port, head, [], { timeout: 5000 });
    assertProblem(asProblem(r), 413, 'too-large', 'Content-Length 1e8, no body sent');
  });

  it('a chunked body (no Content-Length) over the limit → 413 problem+json', async () => {
    const body = Buffer.from(objOfSize(5 * LIMIT));
    const head = `POST /api/v1/models?name=chunked&format=obj HTTP/1.1\r\nHost: 127.0.0.1\r\n` +
      `Content-Type: application/octet-stream\r\nTransfer-Encoding: chunked\r\nConnection: close\r\n\r\n`;
    const chunks = [];
    for (let i = 0; i < body.length; i += 500) {
      const c = body.subarray(i, i + 500);
      chunks.push(`${c.length.toString(16)}\r\n`, c, '\r\n');
    }
    chunks.push('0\r\n\r\n');
    const r = await rawRequest(d.port, head, chunks, { timeout: 5000 });
    assertProblem(asProblem(r), 413, 'too-large', 'chunked 5000 bytes');
  });

  it('a chunked body under the limit is accepted', async () => {
    const body = Buffer.from(objOfSize(LIMIT - 100));
    const head = `POST /api/v1/models?name=chunked-small&format=obj HTTP/1.1\r\nHost: 127.0.0.1\r\n` +
      `Content-Type: application/octet-stream\r\nTransfer-Encoding: chunked\r\nConnection: close\r\n\r\n`;
    const r = await rawRequest(d.port, head, [`${body.length.toString(16)}\r\n`, body, '\r\n0\r\n\r\n'], { timeout: 5000 });
    assert.equal(r.status, 202, r.text);
    assert.equal((await waitJob(d, r.json.id)).status, 'succeeded');
  });

  it('the daemon still serves after refusing', async () => {
    const r = await http(d, 'GET', '/api/v1/models');
    assert.equal(r.status, 200);
    assert.deepEqual(r.json.items.map((m) => m.name), ['small', 'chunked-small']);
  });
});
