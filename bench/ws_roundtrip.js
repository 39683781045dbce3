// archgram websocket latency: two clients in one room; A sends 500 ops one after the
// other; prints op→ack (to A) and op→broadcast (to B) times. Prints figures; not a test.
import fs from 'node:fs';
import { performance } from 'node:perf_hooks';
import {
  DAEMON, DATA, importModel, removeDir, startDaemon, WsClient,
} from '../tests/integration/harness.js';

const N = 500;

function summary(ms) {
  const s = [...ms].sort((a, b) => a - b);
  const q = (p) => s[Math.min(s.length - 1, Math.floor(p * s.length))];
  return `median ${q(0.5).toFixed(3)} ms, p95 ${q(0.95).toFixed(3)} ms, max ${s.at(-1).toFixed(3)} ms`;
}

if (!fs.existsSync(DAEMON)) {
  console.log(`bench/ws_roundtrip.js: ${DAEMON} is missing (make build/archgramd); skipped`);
  process.exit(0);
}

const d = await startDaemon();
let A;
let B;
try {
  const model = await importModel(d, fs.readFileSync(`${DATA}/two_boxes.obj`), { name: 'bench' });
  A = await WsClient.open(d.wsUrl);
  B = await WsClient.open(d.wsUrl);
  let version = (await A.request({ type: 'hello', model: model.id, user: 'a' }, 'welcome')).version;
  await B.request({ type: 'hello', model: model.id, user: 'b' }, 'welcome');
  await A.next('join');

  const toAck = [];
  const toPeer = [];
  const t0 = performance.now();
  for (let i = 0; i < N; i++) {
    const cid = `bench-${i}`;
    const ack = A.next((m) => (m.type === 'ack' || m.type === 'nack') && m.cid === cid, 10000);
    const seen = B.next((m) => m.type === 'op' && m.cid === cid, 10000);
    const ts = performance.now();
    A.send({ type: 'op', base: version, cid, op: { kind: i % 2 ? 'note' : 'rename', [i % 2 ? 'text' : 'name']: `step ${i}` } });
    const [a] = await Promise.all([
      ack.then((m) => { toAck.push(performance.now() - ts); return m; }),
      seen.then(() => { toPeer.push(performance.now() - ts); }),
    ]);
    if (a.type !== 'ack') throw new Error(`op ${i} refused: ${JSON.stringify(a)}`);
    version = a.version;
    A.all.length = 0;
    B.all.length = 0;
  }
  const total = (performance.now() - t0) / 1000;
  console.log(`ws roundtrip: ${N} sequential ops in ${total.toFixed(2)} s (${(N / total).toFixed(0)} ops/s)`);
  console.log(`ws op→ack:       ${summary(toAck)}`);
  console.log(`ws op→broadcast: ${summary(toPeer)}`);
} finally {
  if (A) await A.close();
  if (B) await B.close();
  await d.stop();
  removeDir(d.dir);
}
