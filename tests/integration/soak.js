// A collaboration soak: many websocket clients on one proceduralized facade, each sending a
// mix of notes, renames and structural edits of the window it looks after (a local resize
// that grows the window a little, then shrinks it back), each op made on the version the
// client last saw. Nothing one client's resize changes is named by another's, so every
// structural op is one that does not conflict; notes and renames race each other (a rename
// after a rename made on the same version is a true conflict, as is a note after a note).
// Used by soak.test.js (bounded) and bench/soak.js (full size).
import assert from 'node:assert/strict';
import { facadeObj, http, importModel, sleep, waitJob, WsClient } from './harness.js';

const near = (a, b, eps) => a.every((v, i) => Math.abs(v - b[i]) <= eps);
const gap = (a, b) => Math.max(...a.map((v, i) => Math.abs(v - b[i])));

// The client's window in a tree: where it left it, or — when another client's edit moved it
// (a true conflict, nacked as such) — the window nearest to that, which it looks after from
// then on.
function findWindow(t, box) {
  const comps = t.nodes.filter((n) => n.kind === 'component' && n.box[3] - n.box[0] < 2);
  const exact = comps.find((n) => near(n.box, box, 1e-6));
  if (exact) return exact;
  return comps.sort((a, b) => gap(a.box, box) - gap(b.box, box))[0] ?? null;
}

// The proceduralized facade with one window per client.
export async function soakModel(d, clients) {
  const cols = Math.ceil(Math.sqrt(clients * 2));
  const rows = Math.ceil(clients / cols);
  let model = await importModel(d, Buffer.from(facadeObj(cols, rows, [2.5 * cols + 1, 3.2 * rows + 1])), { name: 'soak' });
  const r = await http(d, 'POST', `/api/v1/models/${model.id}/proceduralize`, {});
  assert.equal(r.status, 202, r.text);
  const job = await waitJob(d, r.json.id, { timeout: 120000 });
  assert.equal(job.status, 'succeeded', JSON.stringify(job));
  model = (await http(d, 'GET', `/api/v1/models/${model.id}`)).json;
  return model;
}

// Runs `clients` clients for `seconds`; returns the figures and checks that every client and
// the database end with the same op log.
export async function runSoak(d, model, { clients = 50, seconds = 40, seed = 1 } = {}) {
  const tree = async () => {
    const t = await http(d, 'GET', `/api/v1/models/${model.id}/tree`, { timeout: 60000 });
    assert.equal(t.status, 200, t.text);
    return t.json;
  };
  const t0 = await tree();
  const windows = t0.nodes.filter((n) => n.visible && n.box[3] - n.box[0] < 2)
    .sort((a, b) => a.box[2] - b.box[2] || a.box[0] - b.box[0]);
  assert.ok(windows.length >= clients, `${windows.length} windows for ${clients} clients`);
  let rnd = seed;
  const random = () => { rnd = (rnd * 1103515245 + 12345) % 2147483648; return rnd / 2147483648; };
  // conflicts: nacked structural ops whose window had in fact changed (the client checks the
  // tree itself); a nack of one whose window had not is a refusal the rebase should have spared
  const stats = { structural: 0, firstAcked: 0, structuralNacked: 0, conflicts: 0, notes: 0, renames: 0, fastNacked: 0, ops: 0 };
  const nackDetails = [];
  const deadline = Date.now() + seconds * 1000;
  const peers = [];
  for (let i = 0; i < clients; i++) {
    const c = await WsClient.open(d.wsUrl, { timeout: 20000 });
    const w = await c.request({ type: 'hello', model: model.id, user: `soak${i}` }, 'welcome', 20000);
    peers.push({ c, seen: new Map(), version: w.version, box: [...windows[i].box], grown: false, n: 0 });
  }
  // every client notes what it learns: broadcast ops and its own acks, version → cid
  for (const p of peers) {
    p.c.ws.on('message', (data) => {
      const m = JSON.parse(data.toString('utf8'));
      if (m.type === 'op') {
        p.seen.set(m.version, m.cid);
        p.version = Math.max(p.version, m.version);
      }
    });
  }
  const answer = (p, cid) => p.c.next((m) => (m.type === 'ack' || m.type === 'nack') && m.cid === cid, 120000, `the answer to ${cid}`);
  const send = async (p, op) => {
    const cid = `s${peers.indexOf(p)}-${p.n++}`;
    p.c.inbox = p.c.inbox.filter((m) => m.type === 'ack' || m.type === 'nack');
    const reply = answer(p, cid);
    p.c.send({ type: 'op', cid, base: p.version, op });
    const r = await reply;
    if (r.type === 'ack') {
      p.seen.set(r.version, cid);
      p.version = Math.max(p.version, r.version);
    }
    stats.ops++;
    return r;
  };
  const loop = async (p, i) => {
    while (Date.now() < deadline) {
      const x = random();
      if (x < 0.3) {
        stats.notes++;
        const r = await send(p, { kind: 'note', text: `note from ${i}` });
        if (r.type === 'nack') stats.fastNacked++;
      } else if (x < 0.4) {
        stats.renames++;
        const r = await send(p, { kind: 'rename', name: `soak by ${i}` });
        if (r.type === 'nack') stats.fastNacked++;
      } else {
        // the client's window as it sees it now, grown or shrunk back by 5 cm
        const t = await tree();
        const node = findWindow(t, p.box);
        assert.ok(node, `client ${i} cannot find its window ${p.box}`);
        p.box = [...node.box];
        p.version = Math.max(p.version, t.version);
        const box = [...p.box];
        const dz = p.grown ? -0.05 : 0.05;
        box[3] += dz;
        box[5] += dz;
        const region = [p.box[0] - 0.02, p.box[1] - 0.02, p.box[2] - 0.02,
          Math.max(p.box[3], box[3]) + 0.02, p.box[4] + 0.02, Math.max(p.box[5], box[5]) + 0.02];
        stats.structural++;
        let r = await send(p, { kind: 'resize', node: node.id, box, mode: 'local', region });
        if (r.type === 'ack') stats.firstAcked++;
        else {
          stats.structuralNacked++;
          nackDetails.push(r.problem?.detail);
        }
        for (let retry = 0; r.type === 'nack' && retry < 5; retry++) {
          // made again on what the client sees now (its window may have moved)
          const t2 = await tree();
          if (retry === 0 && !t2.nodes.some((n) => n.kind === 'component' && near(n.box, p.box, 1e-6))) {
            stats.conflicts++;
          }
          const n2 = findWindow(t2, p.box);
          assert.ok(n2, `client ${i} lost its window ${p.box} after: ${r.problem?.detail}`);
          p.box = [...n2.box];
          p.version = Math.max(p.version, t2.version);
          box.splice(0, 6, ...p.box);
          box[3] += dz;
          box[5] += dz;
          r = await send(p, { kind: 'resize', node: n2.id, box, mode: 'local', region });
        }
        if (r.type === 'ack') {
          p.box = box;
          p.grown = !p.grown;
        }
      }
      await sleep(random() * 50);
    }
  };
  const started = Date.now();
  await Promise.all(peers.map(loop));
  const elapsed = (Date.now() - started) / 1000;
  // let the last broadcasts arrive, then compare every client with the database
  const final = (await http(d, 'GET', `/api/v1/models/${model.id}`)).json.version;
  for (let i = 0; i < 200 && peers.some((p) => p.version < final); i++) await sleep(50);
  const log = (await http(d, 'GET', `/api/v1/models/${model.id}/ops?since=${t0.version}`)).json.items;
  const expected = new Map(log.map((o) => [o.version, o.cid]));
  for (const [i, p] of peers.entries()) {
    assert.equal(p.version, final, `client ${i} ends at version ${p.version}, the database at ${final}`);
    for (const [v, cid] of expected) {
      assert.equal(p.seen.get(v), cid, `client ${i}: version ${v} is ${p.seen.get(v)}, the database has ${cid}`);
    }
  }
  for (const p of peers) await p.c.close();
  return { ...stats, clients, seconds: elapsed, versions: final - t0.version, nackDetails };
}
