// Rate limits and slow clients: 300 proceduralize POSTs in a row meet the job-submission limit
// (429 with Retry-After), REST requests and websocket messages have limits of their own per
// client address, and a flood of partial requests (slowloris) neither locks other clients out
// nor keeps its connections: they are cut at the header timeout.
import assert from 'node:assert/strict';
import { after, before, describe, it } from 'node:test';
import {
  assertProblem, http, removeDir, sleep, startDaemon, waitJob, WsClient,
} from './harness.js';
import { healthFrom, partialRequest } from './clients.js';

const OBJ = 'v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n';

async function stopAll(d) {
  if (d) { try { if (!d.exited) await d.stop(); } finally { await d.kill(); removeDir(d.dir); } }
}

describe('rate limits', () => {
  let d;
  after(() => stopAll(d));

  it('300 proceduralize POSTs in a row: the job-submission limit answers 429 with Retry-After', async () => {
    d = await startDaemon({ args: ['--no-web'] });
    const up = await http(d, 'POST', '/api/v1/models?name=t&format=obj', {
      body: OBJ, headers: { 'Content-Type': 'application/octet-stream' },
    });
    assert.equal(up.status, 202);
    const model = (await waitJob(d, up.json.id)).result.href;
    const codes = {};
    let limited;
    for (let i = 0; i < 300; i++) {
      const r = await http(d, 'POST', `${model}/proceduralize`, { body: '' });
      codes[r.status] = (codes[r.status] ?? 0) + 1;
      if (r.status === 429 && !limited) limited = r;
    }
    assert.ok(limited, `every POST was accepted: ${JSON.stringify(codes)}`);
    assertProblem(limited, 429, 'rate-limited', 'the 429');
    assert.match(limited.headers.get('retry-after') ?? '', /^[1-9]\d*$/);
    assert.ok(codes[202] >= 55 && codes[202] <= 70, `the burst of 60 then 1/s: ${JSON.stringify(codes)}`);
    // reads are not job submissions
    assert.equal((await http(d, 'GET', model)).status, 200);
  });

  it('REST requests: a client past its rate gets 429, another address is not affected', async () => {
    await stopAll(d);
    d = await startDaemon({ args: ['--no-web', '--rate-rest', '5/20'] });
    const codes = [];
    const t0 = Date.now();
    for (let i = 0; i < 40; i++) codes.push((await http(d, 'GET', '/api/v1/health')).status);
    // a burst of 20, then 5 a second for as long as the loop took
    const allowed = 20 + Math.ceil((5 * (Date.now() - t0)) / 1000);
    const first = codes.indexOf(429);
    const ok = codes.filter((c) => c === 200).length;
    assert.ok(first >= 19 && ok <= allowed, `first 429 at ${first}, ${ok} of 40 allowed (at most ${allowed}): ${codes.join(' ')}`);
    const r = await http(d, 'GET', '/api/v1/models');
    assertProblem(r, 429, 'rate-limited');
    // a client at another loopback address has a bucket of its own
    const other = (await healthFrom(d.port, '127.0.0.9')).head;
    assert.match(other, /^HTTP\/1\.1 200/);
    await sleep(1200);
    assert.equal((await http(d, 'GET', '/api/v1/health')).status, 200, 'tokens come back');
  });

  it('websocket messages: past the rate an op is nacked and other messages answered with an error', async () => {
    await stopAll(d);
    d = await startDaemon({ args: ['--no-web', '--rate-ws', '2/10'] });
    const up = await http(d, 'POST', '/api/v1/models?name=w&format=obj', {
      body: OBJ, headers: { 'Content-Type': 'application/octet-stream' },
    });
    const model = (await waitJob(d, up.json.id)).result.model;
    const c = await WsClient.open(d.wsUrl);
    try {
      const w = await c.request({ type: 'hello', model, user: 'rl' }, 'welcome');
      let version = w.version;
      const answers = [];
      for (let i = 0; i < 14; i++) {
        const a = await c.request({ type: 'op', cid: `n${i}`, base: version, op: { kind: 'note', text: `n${i}` } },
          (m) => m.cid === `n${i}`);
        if (a.type === 'ack') version = a.version;
        answers.push(a);
      }
      const nacks = answers.filter((a) => a.type === 'nack');
      assert.ok(nacks.length >= 3, answers.map((a) => a.type).join(' '));
      assert.equal(nacks[0].problem.type, 'urn:archgram:problem:rate-limited');
      assert.ok(nacks[0].retry_after >= 1);
      const err = await c.request({ type: 'presence', state: { x: 1 } }, 'error');
      assert.equal(err.problem.status, 429);
    } finally {
      await c.close();
    }
  });
});

describe('slow clients', () => {
  let d;
  after(() => stopAll(d));

  it('partial requests from many addresses: a new client is answered at once, the slow ones are cut', async () => {
    d = await startDaemon({
      args: ['--no-web', '--header-timeout', '2', '--max-connections-per-address', '40', '--rate-rest', '0'],
    });
    const sockets = [];
    // 10 addresses × 60 attempts: 40 each are kept open (the per-address limit), the rest
    // refused at once
    for (let a = 10; a < 20; a++) {
      const batch = await Promise.all([...Array(60).keys()].map(() => partialRequest(d.port, `127.0.0.${a}`)));
      sockets.push(...batch);
    }
    // keep trickling a header byte every 300 ms: the idle timeout alone would never fire
    const trickle = setInterval(() => {
      for (const s of sockets) if (!s.destroyed) s.write('X');
    }, 300);
    try {
      await sleep(300);
      const open = sockets.filter((s) => !s.destroyed && !s.closedAt).length;
      const h = (await http(d, 'GET', '/api/v1/health')).json;
      assert.ok(h.http.connections >= 300 && h.http.connections <= 420, `server holds ${h.http.connections}, client ${open}`);
      // a new client from yet another address
      const times = [];
      for (let i = 0; i < 5; i++) {
        const r = await healthFrom(d.port, '127.0.0.2');
        times.push(r.ms);
        assert.match(r.head, /^HTTP\/1\.1 200/);
      }
      console.log(`# a new client beside ${h.http.connections} partial connections: ${times.map((t) => t.toFixed(1)).join(', ')} ms`);
      assert.ok(Math.min(...times) < 250, times.join(' '));
      // the slow ones are cut at the header timeout, though they keep sending
      const t0 = Date.now();
      while (Date.now() - t0 < 6000 && sockets.some((s) => !s.closedAt)) await sleep(100);
      assert.ok(sockets.every((s) => s.closedAt), `${sockets.filter((s) => !s.closedAt).length} still open`);
      // the client's pooled keep-alive socket sat idle past the header timeout too, so the
      // server may have cut it just as fetch reuses it: a GET is then sent again, as HTTP
      // clients do on a persistent connection the server closed
      const h2 = (await http(d, 'GET', '/api/v1/health').catch(() => http(d, 'GET', '/api/v1/health'))).json;
      assert.ok(h2.http.slow_cut >= 300, `cut ${h2.http.slow_cut}`);
    } finally {
      clearInterval(trickle);
      for (const s of sockets) s.destroy();
    }
  });
});
