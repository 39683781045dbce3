// archgram collaboration soak at full size: SOAK_CLIENTS (50) websocket clients on one
// facade for SOAK_SECONDS (180) s, a mix of notes, renames and local resizes of each client's
// own window (tests/integration/soak.js); prints the ops, the share of structural ops acked
// on their first send, and checks that every client ends with the database's op log. Figures,
// not a test (the bounded soak is tests/integration/rebase.test.js).
import fs from 'node:fs';
import { DAEMON, removeDir, startDaemon } from '../tests/integration/harness.js';
import { runSoak, soakModel } from '../tests/integration/soak.js';

if (!fs.existsSync(DAEMON)) {
  console.log(`bench/soak.js: ${DAEMON} is missing (make build/archgramd); skipped`);
  process.exit(0);
}

const clients = Number(process.env.SOAK_CLIENTS ?? 50);
const seconds = Number(process.env.SOAK_SECONDS ?? 180);
const d = await startDaemon({
  args: ['--no-web', '--rate-ws', '0', '--rate-rest', '0', '--max-connections-per-address', '4096'],
});
try {
  const model = await soakModel(d, clients);
  const r = await runSoak(d, model, { clients, seconds, seed: 7 });
  console.log(`soak: ${r.clients} clients, ${r.seconds.toFixed(0)} s, ${r.ops} ops (${r.versions} versions, ` +
    `${(r.versions / r.seconds).toFixed(1)}/s); structural ${r.structural} (${r.conflicts} true conflicts), ` +
    `acked on the first send ${r.firstAcked} (${((100 * r.firstAcked) / (r.structural - r.conflicts)).toFixed(1)} % ` +
    `of those that did not conflict); notes and renames ` +
    `${r.notes + r.renames}, nacked (same-kind conflicts) ${r.fastNacked}; every client ends with the database`);
  for (const detail of r.nackDetails.slice(0, 5)) console.log(`  nack: ${detail}`);
} finally {
  await d.stop(10000);
  removeDir(d.dir);
}
