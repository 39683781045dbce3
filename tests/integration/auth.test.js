// Accounts, tokens and roles (schema/openapi.json, schema/websocket.md): identity from the
// token only, roles on models and sharing, CSRF and CORS, the websocket handshake's token and
// Origin, safe start-up defaults, tokens kept hashed and the admin token shown once.
// Every account here is made by the test with the role it needs; the harness's own admin
// accounts ("api", …) are not used to reach a model unless a test says so.
import assert from 'node:assert/strict';
import { spawn } from 'node:child_process';
import fs from 'node:fs';
import path from 'node:path';
import { after, before, describe, it } from 'node:test';
import {
  assertProblem, DAEMON, facadeObj, fixture, freePorts, http, printedToken, removeDir, sleep,
  sql, startDaemon, tempDir, waitJob, WsClient,
} from './harness.js';

const OBJ = fixture('two_boxes.obj');

// archgramd with args, run to its exit (or killed after ms): { code, out, err }.
function runDaemon(args, ms = 10000) {
  return new Promise((resolve) => {
    const p = spawn(DAEMON, args, { stdio: ['ignore', 'pipe', 'pipe'] });
    let out = '';
    let err = '';
    p.stdout.on('data', (s) => { out += s; });
    p.stderr.on('data', (s) => { err += s; });
    const timer = setTimeout(() => p.kill('SIGKILL'), ms);
    p.on('exit', (code, signal) => { clearTimeout(timer); resolve({ code, signal, out, err }); });
  });
}

// Uploads OBJ as the token's account and waits for the model; returns it.
async function importAs(d, token, name) {
  const up = await http(d, 'POST', `/api/v1/models?name=${name}&format=obj`, {
    body: OBJ, token, headers: { 'Content-Type': 'application/octet-stream' },
  });
  assert.equal(up.status, 202, up.text);
  const job = await waitJob(d, up.json.id);
  assert.equal(job.status, 'succeeded', JSON.stringify(job));
  const m = await http(d, 'GET', job.result.href, { token });
  assert.equal(m.status, 200, m.text);
  return m.json;
}

const share = (d, owner, id, user, role) =>
  http(d, 'PUT', `/api/v1/models/${id}/members/${user}`, { token: owner, body: { role } });

describe('accounts, tokens and roles', () => {
  let d;
  const t = {}; // tokens by account name
  const clients = [];
  const open = async (opts) => { const c = await WsClient.open(d.wsUrl, opts); clients.push(c); return c; };

  before(async () => {
    d = await startDaemon({ args: ['--workers', '1', '--no-web'] });
    for (const [name, role] of [['alice', 'editor'], ['bob', 'editor'], ['vera', 'viewer'], ['sam', 'editor']]) {
      t[name] = await d.makeAccount(name, role);
    }
  });
  after(async () => {
    for (const c of clients) await c.close().catch(() => {});
    if (d) { try { await d.stop(); } finally { await d.kill(); removeDir(d.dir); } }
  });

  it('every route but the health check and the API document needs a token', async () => {
    assert.equal((await http(d, 'GET', '/api/v1/health', { token: null })).status, 200);
    assert.equal((await http(d, 'GET', '/api/v1/openapi.json', { token: null })).status, 200);
    for (const [method, p] of [['GET', '/api/v1/models'], ['GET', '/api/v1/models/1'], ['GET', '/api/v1/jobs/1'],
      ['GET', '/api/v1/me'], ['GET', '/api/v1/users'], ['DELETE', '/api/v1/models/1']]) {
      const r = await http(d, method, p, { token: null });
      assertProblem(r, 401, 'unauthorized', `${method} ${p} without a token`);
      assert.match(r.headers.get('www-authenticate') ?? '', /^Bearer /);
    }
    const bad = await http(d, 'GET', '/api/v1/models', { token: 'agt_not-a-token-this-server-made' });
    assertProblem(bad, 401, 'unauthorized', 'an unknown token');
    const basic = await http(d, 'GET', '/api/v1/models', { token: null, headers: { Authorization: 'Basic YTpi' } });
    assertProblem(basic, 401, 'unauthorized', 'another scheme');
    const me = await http(d, 'GET', '/api/v1/me', { token: t.alice });
    assert.equal(me.status, 200, me.text);
    assert.deepEqual([me.json.name, me.json.role, me.json.auth], ['alice', 'editor', true]);
  });

  it('X-Archgram-User sets no identity: the author is the token\'s account', async () => {
    const m = await importAs(d, t.bob, 'bobs');
    const r = await http(d, 'PATCH', m.href, {
      token: t.bob, body: { name: 'renamed' }, headers: { 'If-Match': `"${m.version}"`, 'X-Archgram-User': 'alice' },
    });
    assert.equal(r.status, 200, r.text);
    const n = await http(d, 'POST', `${m.href}/ops`, {
      token: t.bob, body: { op: { kind: 'note', text: 'who?' } }, headers: { 'If-Match': `"${r.json.version}"`, 'X-Archgram-User': 'alice' },
    });
    assert.equal(n.status, 200, n.text);
    const log = await http(d, 'GET', `${m.href}/ops?since=${m.version}`, { token: t.bob });
    assert.deepEqual(log.json.items.map((o) => o.author), ['bob', 'bob']);
    // and alice, whom bob named, cannot even see bob's model
    assertProblem(await http(d, 'GET', m.href, { token: t.alice }), 404, 'not-found', "alice reading bob's model");
  });

  it('the websocket "user" sets no identity: join, presence and ops carry the account', async () => {
    const m = await importAs(d, t.alice, 'room');
    assert.equal((await share(d, t.alice, m.id, 'bob', 'editor')).status, 200);
    const A = await open({ token: t.alice });
    const B = await open({ token: t.bob });
    const wa = await A.request({ type: 'hello', model: m.id, user: 'bob' }, 'welcome');
    assert.equal(wa.user, 'alice');
    assert.equal(wa.role, 'owner');
    const wb = await B.request({ type: 'hello', model: m.id, user: 'alice' }, 'welcome');
    assert.equal(wb.user, 'bob');
    assert.equal(wb.role, 'editor');
    assert.deepEqual(wb.peers.map((p) => p.user), ['alice']);
    assert.equal((await A.next('join')).user, 'bob');
    B.send({ type: 'presence', state: { name: 'alice', selection: [1] } });
    const p = await A.next('presence');
    assert.equal(p.user, 'bob');
    assert.equal(p.state.name, 'bob', 'the presence name is the account\'s');
    B.send({ type: 'op', base: m.version, cid: 'b-1', op: { kind: 'note', text: 'hi' } });
    assert.equal((await B.next((x) => x.type === 'ack' && x.cid === 'b-1')).version, m.version + 1);
    assert.equal((await A.next((x) => x.type === 'op' && x.cid === 'b-1')).author, 'bob');
  });

  it("an undo cannot reach someone else's edit, whoever the request claims to be", async () => {
    const up = await http(d, 'POST', '/api/v1/models?name=facade&format=obj', {
      body: Buffer.from(facadeObj(3, 2)), token: t.alice, headers: { 'Content-Type': 'application/octet-stream' },
    });
    const made = await waitJob(d, up.json.id);
    assert.equal(made.status, 'succeeded', JSON.stringify(made));
    const id = made.result.model;
    const pj = await http(d, 'POST', `/api/v1/models/${id}/proceduralize`, { token: t.alice, body: {} });
    assert.equal(pj.status, 202, pj.text);
    assert.equal((await waitJob(d, pj.json.id, { timeout: 60000 })).status, 'succeeded');
    assert.equal((await share(d, t.alice, id, 'bob', 'editor')).status, 200);
    const model = (await http(d, 'GET', `/api/v1/models/${id}`, { token: t.alice })).json;
    const tree = (await http(d, 'GET', `/api/v1/models/${id}/tree`, { token: t.alice })).json;
    const box = [...tree.nodes[0].box];
    box[3] = box[0] + 0.9 * (box[3] - box[0]);
    // (alice names herself too, as a client of a server without accounts would)
    const e = await http(d, 'POST', `/api/v1/models/${id}/ops`, {
      token: t.alice, body: { cid: 'a-1', op: { kind: 'resize', node: 'root', box } }, headers: { 'If-Match': `"${model.version}"`, 'X-Archgram-User': 'alice' }, timeout: 60000,
    });
    assert.equal(e.status, 200, e.text);
    // bob claims to be alice over REST and over the websocket: both undo bob's own history
    const u = await http(d, 'POST', `/api/v1/models/${id}/ops`, {
      token: t.bob, body: { cid: 'b-undo', op: { kind: 'undo' } }, headers: { 'If-Match': `"${e.json.version}"`, 'X-Archgram-User': 'alice' }, timeout: 60000,
    });
    assertProblem(u, 409, 'undo-conflict', "bob's undo of alice's edit");
    assert.match(u.json.detail, /^bob has no edit/);
    const B = await open({ token: t.bob });
    await B.request({ type: 'hello', model: id, user: 'alice' }, 'welcome');
    const nack = await B.request({ type: 'op', base: e.json.version, cid: 'b-undo-ws', op: { kind: 'undo' } },
      (x) => (x.type === 'ack' || x.type === 'nack') && x.cid === 'b-undo-ws', 60000);
    assert.equal(nack.type, 'nack', JSON.stringify(nack));
    assert.equal(nack.problem.type, 'urn:archgram:problem:undo-conflict');
    const now = await http(d, 'GET', `/api/v1/models/${id}`, { token: t.alice });
    assert.equal(now.json.version, e.json.version, 'nothing was undone');
    const log = await http(d, 'GET', `/api/v1/models/${id}/ops?since=${model.version}`, { token: t.alice });
    assert.deepEqual(log.json.items.map((o) => [o.author, o.op.kind]), [['alice', 'resize']]);
    // alice herself may undo it
    const ua = await http(d, 'POST', `/api/v1/models/${id}/ops`, {
      token: t.alice, body: { cid: 'a-undo', op: { kind: 'undo' } }, headers: { 'If-Match': `"${e.json.version}"` }, timeout: 60000,
    });
    assert.equal(ua.status, 200, ua.text);
  });

  it('DELETE with If-Match: * is for owners only', async () => {
    const m = await importAs(d, t.alice, 'keep me');
    assert.equal((await share(d, t.alice, m.id, 'bob', 'editor')).status, 200);
    assert.equal((await share(d, t.alice, m.id, 'vera', 'viewer')).status, 200);
    const del = (token) => http(d, 'DELETE', m.href, { token, headers: { 'If-Match': '*' } });
    assertProblem(await del(t.bob), 403, 'forbidden', 'an editor deleting');
    assertProblem(await del(t.vera), 403, 'forbidden', 'a viewer deleting');
    assertProblem(await del(t.sam), 404, 'not-found', 'a stranger deleting');
    assert.equal((await http(d, 'GET', m.href, { token: t.alice })).status, 200, 'still there');
    assert.equal((await del(t.alice)).status, 204);
    assertProblem(await http(d, 'GET', m.href, { token: t.alice }), 404, 'not-found', 'after the owner deleted it');
  });

  it('a cross-origin text/plain POST without a bearer token changes nothing', async () => {
    const before = (await http(d, 'GET', '/api/v1/models?page_size=200')).json.items.length;
    const m = await importAs(d, t.alice, 'target');
    const forms = [
      ['/api/v1/models?name=evil&format=obj', OBJ],
      ['/api/v1/extrusions?name=evil', '{"footprint":[[0,0],[4,0],[4,4],[0,4]],"height":3}'],
      [`/api/v1/models/${m.id}/proceduralize`, ''],
      [`/api/v1/models/${m.id}/ops`, '{"op":{"kind":"rename","name":"pwned"}}'],
    ];
    for (const [p, body] of forms) {
      const r = await http(d, 'POST', p, {
        token: null, body, headers: { 'Content-Type': 'text/plain', Origin: 'http://evil.example', 'If-Match': '*' },
      });
      assertProblem(r, 401, 'unauthorized', `cross-site POST ${p}`);
      assert.equal(r.headers.get('access-control-allow-origin'), null);
    }
    const after = (await http(d, 'GET', '/api/v1/models?page_size=200')).json.items;
    assert.equal(after.length, before + 1, 'no model was added');
    const now = after.find((x) => x.id === m.id);
    assert.deepEqual([now.name, now.version], [m.name, m.version], 'the model did not change');
  });

  it('CORS is off by default: no allow-origin header, preflights refused', async () => {
    const r = await http(d, 'GET', '/api/v1/models', { token: t.alice, headers: { Origin: 'http://app.example' } });
    assert.equal(r.status, 200);
    assert.equal(r.headers.get('access-control-allow-origin'), null);
    const pre = await http(d, 'OPTIONS', '/api/v1/models', {
      token: null, headers: { Origin: 'http://app.example', 'Access-Control-Request-Method': 'POST', 'Access-Control-Request-Headers': 'authorization' },
    });
    assertProblem(pre, 403, 'forbidden', 'a preflight with CORS off');
    assert.equal(pre.headers.get('access-control-allow-origin'), null);
  });

  it('a websocket handshake needs a token and the web client\'s Origin', async () => {
    await assert.rejects(open({ token: null }), (e) => e.status === 401, 'no token');
    await assert.rejects(open({ token: 'agt_nope' }), (e) => e.status === 401, 'an unknown token');
    await assert.rejects(open({ token: t.alice, origin: 'http://evil.example' }), (e) => e.status === 403, 'a foreign Origin');
    await assert.rejects(open({ token: t.alice, origin: `http://127.0.0.1:${d.port + 7}` }), (e) => e.status === 403, 'another port');
    await assert.rejects(open({ token: t.alice, origin: 'null' }), (e) => e.status === 403, 'an opaque Origin');
    // the web client's own origin, and a browser's way of sending the token (a subprotocol)
    const own = await open({ token: t.alice, origin: `http://127.0.0.1:${d.port}` });
    const w = await own.request({ type: 'watch', job: 999999 }, 'error');
    assert.equal(w.problem.status, 404);
    const viaProtocol = await open({ token: null, protocol: ['archgram', `archgram.bearer.${t.alice}`], origin: `http://127.0.0.1:${d.port}` });
    assert.equal(viaProtocol.ws.protocol, 'archgram');
    const m = await importAs(d, t.alice, 'proto');
    assert.equal((await viaProtocol.request({ type: 'hello', model: m.id }, 'welcome')).user, 'alice');
  });

  it("a viewer's ops are refused over REST and the websocket; its previews too", async () => {
    const m = await importAs(d, t.alice, 'look only');
    assert.equal((await share(d, t.alice, m.id, 'bob', 'viewer')).status, 200);
    const get = await http(d, 'GET', m.href, { token: t.bob });
    assert.equal(get.status, 200);
    assert.equal(get.json.role, 'viewer');
    for (const [method, p, body] of [['PATCH', m.href, { name: 'x' }], ['POST', `${m.href}/ops`, { op: { kind: 'note', text: 'x' } }],
      ['POST', `${m.href}/proceduralize`, {}], ['PUT', `${m.href}/members/bob`, { role: 'owner' }], ['PUT', `${m.href}/public`, { public_read: true }]]) {
      assertProblem(await http(d, method, p, { token: t.bob, body, headers: { 'If-Match': '*' } }), 403, 'forbidden', `a viewer's ${method} ${p}`);
    }
    const B = await open({ token: t.bob });
    const w = await B.request({ type: 'hello', model: m.id }, 'welcome');
    assert.equal(w.role, 'viewer');
    const nack = await B.request({ type: 'op', base: w.version, cid: 'v-1', op: { kind: 'rename', name: 'mine' } },
      (x) => (x.type === 'ack' || x.type === 'nack') && x.cid === 'v-1');
    assert.equal(nack.type, 'nack');
    assert.equal(nack.problem.type, 'urn:archgram:problem:forbidden');
    assert.equal(nack.version, w.version);
    const pe = await B.request({ type: 'preview', base: w.version, op: { kind: 'resize', node: 'root', scale: [2, 1, 1] } }, 'preview.error');
    assert.equal(pe.problem.type, 'urn:archgram:problem:forbidden');
    const now = await http(d, 'GET', m.href, { token: t.alice });
    assert.deepEqual([now.json.name, now.json.version], [m.name, m.version]);
    // a role given while connected counts at once; one taken away closes the room
    assert.equal((await share(d, t.alice, m.id, 'bob', 'editor')).status, 200);
    assert.equal((await B.next('access')).role, 'editor');
    const ack = await B.request({ type: 'op', base: w.version, cid: 'v-2', op: { kind: 'note', text: 'now I may' } },
      (x) => (x.type === 'ack' || x.type === 'nack') && x.cid === 'v-2');
    assert.equal(ack.type, 'ack', JSON.stringify(ack));
    const gone = await http(d, 'DELETE', `${m.href}/members/bob`, { token: t.alice });
    assert.equal(gone.status, 200, gone.text);
    assert.equal((await B.next('access')).role, 'none');
    const late = await B.request({ type: 'op', base: ack.version, cid: 'v-3', op: { kind: 'note', text: 'still?' } },
      (x) => x.type === 'nack' || x.type === 'ack' || x.type === 'error');
    assert.notEqual(late.type, 'ack', JSON.stringify(late));
  });

  it('sharing: members, public read, the last owner, and who sees which models', async () => {
    const m = await importAs(d, t.alice, 'shared');
    const ids = async (token) => (await http(d, 'GET', '/api/v1/models?page_size=200', { token })).json.items.map((x) => x.id);
    assert.ok(!(await ids(t.sam)).includes(m.id), 'a stranger does not list it');
    assertProblem(await http(d, 'GET', `${m.href}/mesh.glb`, { token: t.sam }), 404, 'not-found', "a stranger's mesh.glb");
    assertProblem(await http(d, 'GET', `${m.href}/ops`, { token: t.sam }), 404, 'not-found', "a stranger's op log");
    let s = await http(d, 'GET', `${m.href}/members`, { token: t.alice });
    assert.deepEqual(s.json, { model: m.id, public_read: false, items: [{ user: 'alice', role: 'owner' }] });
    s = await share(d, t.alice, m.id, 'sam', 'viewer');
    assert.deepEqual(s.json.items, [{ user: 'alice', role: 'owner' }, { user: 'sam', role: 'viewer' }]);
    const listed = (await http(d, 'GET', '/api/v1/models?page_size=200', { token: t.sam })).json.items.find((x) => x.id === m.id);
    assert.equal(listed.role, 'viewer');
    assertProblem(await share(d, t.alice, m.id, 'nobody', 'viewer'), 404, 'not-found', 'sharing with no account');
    assertProblem(await share(d, t.alice, m.id, 'sam', 'boss'), 400, 'invalid', 'an unknown role');
    assertProblem(await share(d, t.alice, m.id, 'alice', 'editor'), 409, 'conflict', 'the last owner stepping down');
    assertProblem(await http(d, 'DELETE', `${m.href}/members/alice`, { token: t.alice }), 409, 'conflict', 'the last owner leaving');
    s = await http(d, 'DELETE', `${m.href}/members/sam`, { token: t.alice });
    assert.deepEqual(s.json.items, [{ user: 'alice', role: 'owner' }]);
    assert.ok(!(await ids(t.sam)).includes(m.id));
    s = await http(d, 'PUT', `${m.href}/public`, { token: t.alice, body: { public_read: true } });
    assert.equal(s.json.public_read, true);
    assert.ok((await ids(t.sam)).includes(m.id), 'public-read models are listed for everyone');
    assert.equal((await http(d, 'GET', m.href, { token: t.vera })).json.role, 'viewer');
    assertProblem(await http(d, 'POST', `${m.href}/ops`, {
      token: t.sam, body: { op: { kind: 'note', text: 'x' } }, headers: { 'If-Match': '*' },
    }), 403, 'forbidden', 'public read is read only');
    // a second owner may take over
    await share(d, t.alice, m.id, 'bob', 'owner');
    s = await share(d, t.bob, m.id, 'alice', 'viewer');
    assert.deepEqual(s.json.items, [{ user: 'alice', role: 'viewer' }, { user: 'bob', role: 'owner' }]);
  });

  it('account roles: viewers make no models, only admins manage accounts, jobs are their asker\'s', async () => {
    const up = await http(d, 'POST', '/api/v1/models?name=v&format=obj', {
      body: OBJ, token: t.vera, headers: { 'Content-Type': 'application/octet-stream' },
    });
    assertProblem(up, 403, 'forbidden', 'a viewer account uploading');
    assertProblem(await http(d, 'GET', '/api/v1/users', { token: t.alice }), 403, 'forbidden', 'an editor listing accounts');
    assertProblem(await http(d, 'POST', '/api/v1/users', { token: t.alice, body: { name: 'eve' } }), 403, 'forbidden', 'an editor making an account');
    const mine = await http(d, 'POST', '/api/v1/models?name=j&format=obj', {
      body: OBJ, token: t.alice, headers: { 'Content-Type': 'application/octet-stream' },
    });
    assert.equal(mine.status, 202);
    assertProblem(await http(d, 'GET', `/api/v1/jobs/${mine.json.id}`, { token: t.bob }), 404, 'not-found', "another account's job");
    assertProblem(await http(d, 'DELETE', `/api/v1/jobs/${mine.json.id}`, { token: t.bob }), 404, 'not-found', "cancelling another account's job");
    const done = await waitJob(d, mine.json.id);
    assert.equal(done.status, 'succeeded');
    const w = await open({ token: t.bob });
    assert.equal((await w.request({ type: 'watch', job: mine.json.id }, 'error')).problem.status, 404);
    const model = await http(d, 'GET', done.result.href, { token: t.alice });
    assert.equal(model.json.role, 'owner', 'the asker owns what the job made');
    const admins = await http(d, 'GET', '/api/v1/users');
    assert.equal(admins.status, 200);
    const names = admins.json.items.map((u) => u.name);
    for (const n of ['admin', 'alice', 'bob', 'vera', 'sam']) assert.ok(names.includes(n), n);
    assertProblem(await http(d, 'POST', '/api/v1/users', { body: { name: 'alice' } }), 409, 'conflict', 'a taken name');
    assertProblem(await http(d, 'POST', '/api/v1/users', { body: { name: '../x' } }), 400, 'invalid', 'a bad name');
    assertProblem(await http(d, 'POST', '/api/v1/users', { body: { name: 'zed', role: 'god' } }), 400, 'invalid', 'a bad role');
  });

  it('tokens: several per account, listed without secrets, revoked at once', async () => {
    const r = await http(d, 'POST', '/api/v1/me/tokens', { token: t.sam, body: { label: 'laptop' } });
    assert.equal(r.status, 201, r.text);
    assert.match(r.json.token, /^agt_[A-Za-z0-9_-]{43}$/);
    const second = r.json.token;
    assert.equal((await http(d, 'GET', '/api/v1/me', { token: second })).json.name, 'sam');
    const list = await http(d, 'GET', '/api/v1/me/tokens', { token: second });
    assert.ok(!list.text.includes(second) && !list.text.includes(t.sam), 'no secret in the list');
    const entry = list.json.items.find((x) => x.label === 'laptop');
    assert.equal(entry.current, true);
    assertProblem(await http(d, 'DELETE', `/api/v1/me/tokens/${entry.id}`, { token: t.bob }), 404, 'not-found', "revoking someone else's token");
    assert.equal((await http(d, 'DELETE', `/api/v1/me/tokens/${entry.id}`, { token: t.sam })).status, 204);
    assertProblem(await http(d, 'GET', '/api/v1/me', { token: second }), 401, 'unauthorized', 'a revoked token');
    assert.equal((await http(d, 'GET', '/api/v1/me', { token: t.sam })).status, 200, 'the other token still works');
    const made = await http(d, 'POST', '/api/v1/users/sam/tokens', { body: { label: 'by admin' } });
    assert.equal(made.status, 201, made.text);
    assert.equal((await http(d, 'GET', '/api/v1/me', { token: made.json.token })).json.name, 'sam');
  });
});

describe('tokens at rest and the first start', () => {
  it('the admin token is printed once, on the first start, and works after restarts', async () => {
    const dir = tempDir();
    let d;
    try {
      d = await startDaemon({ dir });
      const token = printedToken(d.out);
      assert.match(token ?? '', /^agt_/, `first start output:\n${d.out}`);
      assert.match(d.out, new RegExp(`http://127\\.0\\.0\\.1:${d.port}/#token=${token}`));
      assert.equal((await http(d, 'GET', '/api/v1/me', { token })).json.role, 'admin');
      const made = await http(d, 'POST', '/api/v1/users', { token, body: { name: 'carl', role: 'viewer' } });
      assert.equal(made.status, 201, made.text);
      await d.stop();
      d = await startDaemon({ dir, db: d.db });
      assert.equal(printedToken(d.out), null, `a restart printed a token:\n${d.out}`);
      assert.doesNotMatch(d.out + d.err, new RegExp(token));
      assert.equal((await http(d, 'GET', '/api/v1/me', { token })).json.name, 'admin');
      await d.stop();
      // the tokens are kept as hashes: neither the token nor its bytes are in the files
      const stored = sql(d.db, 'SELECT hex(hash), length(hash), label FROM tokens ORDER BY id');
      assert.ok(stored.length >= 2, JSON.stringify(stored));
      for (const [hex, n] of stored) assert.equal(n, '32', `hash ${hex}`);
      for (const secret of [token, made.json.token]) {
        const raw = Buffer.from(secret.slice(4), 'base64url');
        for (const f of [d.db, `${d.db}-wal`].filter((x) => fs.existsSync(x))) {
          const bytes = fs.readFileSync(f);
          assert.equal(bytes.indexOf(secret), -1, `${path.basename(f)} holds a token`);
          assert.equal(bytes.indexOf(raw), -1, `${path.basename(f)} holds a token's bytes`);
          assert.equal(bytes.indexOf(raw.toString('hex').toUpperCase()), -1);
        }
        assert.ok(!stored.some(([hex]) => hex === Buffer.from(secret).toString('hex').toUpperCase()));
      }
    } finally {
      if (d) await d.kill();
      removeDir(dir);
    }
  });

  it('--admin-token-file signs the admin in with a secret, prints nothing, and rotates', async () => {
    const dir = tempDir();
    let d;
    try {
      const file = path.join(dir, 'admin_token');
      const first = 'secret-token-from-a-file-0123456789-abcdef';
      fs.writeFileSync(file, `${first}\n`);
      d = await startDaemon({ dir, args: ['--admin-token-file', file], signIn: false });
      assert.equal(printedToken(d.out), null);
      assert.equal((await http(d, 'GET', '/api/v1/me', { token: first })).json.name, 'admin');
      await d.stop();
      const second = 'another-secret-token-from-the-file-98765';
      fs.writeFileSync(file, second);
      d = await startDaemon({ dir, db: d.db, args: ['--admin-token-file', file], signIn: false });
      assert.equal((await http(d, 'GET', '/api/v1/me', { token: second })).json.name, 'admin');
      assertProblem(await http(d, 'GET', '/api/v1/me', { token: first }), 401, 'unauthorized', 'the old secret');
      await d.stop();
      fs.writeFileSync(file, 'short');
      const r = await runDaemon(['--port', '1', '--db', path.join(dir, 't.db'), '--admin-token-file', file]);
      assert.equal(r.code, 2, r.err);
      assert.match(r.err, /admin-token-file/);
    } finally {
      if (d) await d.kill();
      removeDir(dir);
    }
  });

  it('--create-user and --create-token print a token on the command line', async () => {
    const dir = tempDir();
    try {
      const db = path.join(dir, 'c.db');
      const u = await runDaemon(['--db', db, '--create-user', 'ops', '--role', 'viewer']);
      assert.equal(u.code, 0, u.err);
      const token = u.out.trim();
      assert.match(token, /^agt_[A-Za-z0-9_-]{43}$/);
      assert.match(u.err, /ops \(viewer\)/);
      const again = await runDaemon(['--db', db, '--create-user', 'ops']);
      assert.equal(again.code, 1);
      assert.match(again.err, /there is an account ops already/);
      const more = await runDaemon(['--db', db, '--create-token', 'ops']);
      assert.equal(more.code, 0, more.err);
      assert.notEqual(more.out.trim(), token);
      assert.equal((await runDaemon(['--db', db, '--create-token', 'nobody'])).code, 1);
      assert.equal((await runDaemon(['--db', db, '--create-user', 'x', '--role', 'root'])).code, 2);
      // the accounts exist when the service starts: no first-start admin then, and ops signs in
      const d = await startDaemon({ dir, db, signIn: false });
      try {
        assert.equal(printedToken(d.out), null);
        const me = await http(d, 'GET', '/api/v1/me', { token: more.out.trim() });
        assert.deepEqual([me.json.name, me.json.role], ['ops', 'viewer']);
        await d.stop();
      } finally {
        await d.kill();
      }
    } finally {
      removeDir(dir);
    }
  });
});

describe('safe defaults: loopback, --no-auth, CORS', () => {
  it('--no-auth refuses a non-loopback address and starts on loopback only', async () => {
    const [port] = await freePorts(1);
    const dir = tempDir();
    for (const bind of ['0.0.0.0', '192.168.1.10']) {
      const r = await runDaemon(['--bind', bind, '--port', String(port), '--no-auth', '--db', path.join(dir, 'n.db')]);
      assert.equal(r.code, 2, `--bind ${bind} --no-auth: ${r.out}${r.err}`);
      assert.match(r.err, /--no-auth serves only a loopback address/);
      assert.doesNotMatch(r.out, /listening on/);
      assert.ok(!fs.existsSync(path.join(dir, 'n.db')), 'it stopped before opening the database');
    }
    const d = await startDaemon({ dir, args: ['--no-auth', '--no-web'], signIn: false });
    try {
      assert.doesNotMatch(d.out, /#token=/);
      const list = await http(d, 'GET', '/api/v1/models', { token: null });
      assert.equal(list.status, 200, 'a read needs no token');
      const me = await http(d, 'GET', '/api/v1/me', { token: null });
      assert.deepEqual([me.json.name, me.json.auth], ['local', false]);
      // a change still needs the header a cross-site form cannot send
      const forged = await http(d, 'POST', '/api/v1/models?name=x&format=obj', {
        token: null, body: OBJ, headers: { 'Content-Type': 'text/plain', Origin: 'http://evil.example' },
      });
      assertProblem(forged, 401, 'unauthorized', 'a change without Authorization under --no-auth');
      const ok = await http(d, 'POST', '/api/v1/models?name=x&format=obj', {
        token: 'anything', body: OBJ, headers: { 'Content-Type': 'application/octet-stream' },
      });
      assert.equal(ok.status, 202, ok.text);
      await assert.rejects(WsClient.open(d.wsUrl, { token: null, origin: 'http://evil.example' }), (e) => e.status === 403);
      const ws = await WsClient.open(d.wsUrl, { token: null });
      await ws.close();
      await d.stop();
    } finally {
      await d.kill();
      removeDir(dir);
    }
  });

  it('the default bind is loopback; a non-loopback bind keeps auth on', async () => {
    const dir = tempDir();
    try {
      const [port, wsPort] = await freePorts(2);
      const p = spawn(DAEMON, ['--port', String(port), '--ws-port', String(wsPort), '--db', path.join(dir, 'l.db'), '--no-web'], { stdio: ['ignore', 'pipe', 'pipe'] });
      let out = '';
      p.stdout.on('data', (s) => { out += s; });
      for (let i = 0; i < 100 && !/listening on/.test(out); i++) await sleep(50);
      p.kill('SIGTERM');
      assert.match(out, new RegExp(`listening on http://127\\.0\\.0\\.1:${port}/`));
      const d = await startDaemon({ dir, db: path.join(dir, 'all.db'), args: ['--bind', '0.0.0.0', '--no-web'] });
      try {
        assert.match(d.out, /listening on http:\/\/0\.0\.0\.0:/);
        assertProblem(await http(d, 'GET', '/api/v1/models', { token: null }), 401, 'unauthorized', 'on 0.0.0.0');
        assert.equal((await http(d, 'GET', '/api/v1/models')).status, 200);
        await d.stop();
      } finally {
        await d.kill();
      }
    } finally {
      removeDir(dir);
    }
  });

  it('--cors allows the origins it names: answers, preflights and websockets', async () => {
    const dir = tempDir();
    const d = await startDaemon({ dir, args: ['--cors', 'http://app.example:5173', '--no-web'] });
    try {
      const app = 'http://app.example:5173';
      const r = await http(d, 'GET', '/api/v1/models', { headers: { Origin: app } });
      assert.equal(r.headers.get('access-control-allow-origin'), app);
      assert.match(r.headers.get('vary') ?? '', /Origin/);
      assert.match(r.headers.get('access-control-expose-headers') ?? '', /ETag/);
      const pre = await http(d, 'OPTIONS', '/api/v1/models/1', {
        token: null, headers: { Origin: app, 'Access-Control-Request-Method': 'DELETE', 'Access-Control-Request-Headers': 'authorization, if-match' },
      });
      assert.equal(pre.status, 204, pre.text);
      assert.equal(pre.headers.get('access-control-allow-origin'), app);
      assert.deepEqual(pre.headers.get('access-control-allow-methods').split(', ').sort(), ['DELETE', 'GET', 'PATCH']);
      assert.match(pre.headers.get('access-control-allow-headers'), /Authorization/);
      assert.match(pre.headers.get('access-control-allow-headers'), /If-Match/);
      const other = await http(d, 'OPTIONS', '/api/v1/models', {
        token: null, headers: { Origin: 'http://evil.example', 'Access-Control-Request-Method': 'POST' },
      });
      assertProblem(other, 403, 'forbidden', 'a preflight from another origin');
      const elsewhere = await http(d, 'GET', '/api/v1/models', { headers: { Origin: 'http://evil.example' } });
      assert.equal(elsewhere.headers.get('access-control-allow-origin'), null);
      assertProblem(await http(d, 'OPTIONS', '/api/v1/nothing', { token: null, headers: { Origin: app, 'Access-Control-Request-Method': 'GET' } }),
        404, 'not-found', 'a preflight for no resource');
      const ws = await WsClient.open(d.wsUrl, { origin: app });
      await ws.close();
      await assert.rejects(WsClient.open(d.wsUrl, { origin: 'http://evil.example' }), (e) => e.status === 403);
      await d.stop();
    } finally {
      await d.kill();
      removeDir(dir);
    }
    const bad = await runDaemon(['--cors', 'http://app.example/path', '--db', path.join(dir, 'x.db')]);
    assert.equal(bad.code, 2);
    assert.match(bad.err, /--cors takes an origin/);
  });
});
