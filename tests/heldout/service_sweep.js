// The held-out sweep through the service's upload path: every mesh and cloud of generate.js
// uploaded to a fresh archgramd (the format named by the extension, and sniffed), then
// proceduralized. A job ends succeeded or failed with a problem (type, status < 500, detail
// naming a line or element where it can); never a 5xx, a dropped reply or a dead daemon.
//   node tests/heldout/service_sweep.js DIR [--only SUBSTRING]   (after generate.js DIR)
import fs from 'node:fs';
import path from 'node:path';
import { http, removeDir, startDaemon, waitJob } from '../integration/harness.js';

const args = process.argv.slice(2);
const dir = args[0];
const only = args.includes('--only') ? args[args.indexOf('--only') + 1] : '';
if (!dir || !fs.existsSync(path.join(dir, 'manifest.json'))) {
  console.error('usage: node tests/heldout/service_sweep.js DIR (after node tests/heldout/generate.js DIR)');
  process.exit(2);
}
const manifest = JSON.parse(fs.readFileSync(path.join(dir, 'manifest.json'), 'utf8'))
  .filter((m) => m.family !== 'footprints' && `${m.family}-${m.variant}`.includes(only));

const formatOf = (file) => {
  const ext = path.extname(file).slice(1).toLowerCase();
  return ext;
};

const d = await startDaemon();
const rows = [];
const log = (m, step, verdict, note = '') => {
  rows.push({ variant: `${m.family}-${m.variant}`, step, verdict, note });
  console.log(`${m.family}\t${m.variant}\t${step}\t${verdict}\t${String(note).split('\n')[0].slice(0, 240)}`);
};
const problemOk = (e) => e && typeof e.type === 'string' && e.status >= 400 && e.status < 500 && typeof e.detail === 'string';

try {
  for (const m of manifest) {
    for (const named of [true, false]) {
      const q = new URLSearchParams({ name: m.variant });
      if (named) q.set('format', formatOf(m.file));
      const step = named ? 'upload(format)' : 'upload(sniffed)';
      let res;
      try {
        // the service limits job submissions per client: wait as its Retry-After says
        for (;;) {
          res = await http(d, 'POST', `/api/v1/models?${q}`, { body: fs.readFileSync(m.file), headers: { 'Content-Type': 'application/octet-stream' }, timeout: 120000 });
          if (res.status !== 429) break;
          await new Promise((r) => setTimeout(r, 1000 * Number(res.headers.get('retry-after') || 1)));
        }
      } catch (e) {
        log(m, step, 'BUG:no-reply', e.message);
        if (d.exited) throw new Error('the daemon died');
        continue;
      }
      if (res.status >= 500) { log(m, step, `BUG:${res.status}`, res.text); continue; }
      if (res.status !== 202) {
        log(m, step, problemOk(res.json) ? (m.expectError ? 'precise-error' : 'BUG:refused-valid') : 'UNHELPFUL', `${res.status} ${res.json?.detail ?? res.text}`);
        continue;
      }
      const job = await waitJob(d, res.json.id, { timeout: 120000 });
      if (job.status !== 'succeeded') {
        const v = !problemOk(job.error) ? 'UNHELPFUL' : job.error.status >= 500 ? `BUG:${job.error.status}` : m.expectError ? 'precise-error' : 'BUG:refused-valid';
        log(m, step, v, job.error?.detail ?? JSON.stringify(job));
        continue;
      }
      if (m.expectError) { log(m, step, 'BUG:accepted-bad-input'); continue; }
      const model = (await http(d, 'GET', job.result.href)).json;
      log(m, step, 'ok', `${model.kind ?? ''} ${model.up?.axis ?? ''} ${JSON.stringify(model.stats ?? model.counts ?? {}).slice(0, 120)}`);
      if (!named) continue;
      let p;
      for (;;) {
        p = await http(d, 'POST', `/api/v1/models/${model.id}/proceduralize`);
        if (p.status !== 429) break;
        await new Promise((r) => setTimeout(r, 1000 * Number(p.headers.get('retry-after') || 1)));
      }
      if (p.status !== 202) { log(m, 'proceduralize', p.status >= 500 ? `BUG:${p.status}` : 'refused', p.text); continue; }
      const pj = await waitJob(d, p.json.id, { timeout: 120000 });
      if (pj.status === 'succeeded') log(m, 'proceduralize', 'ok');
      else log(m, 'proceduralize', !problemOk(pj.error) ? 'UNHELPFUL' : pj.error.status >= 500 ? `BUG:${pj.error.status}` : 'precise-error', pj.error?.detail ?? JSON.stringify(pj));
      const h = await http(d, 'GET', '/api/v1/health');
      if (h.status !== 200) log(m, 'health', `BUG:${h.status}`, h.text);
    }
  }
} finally {
  await d.stop().catch(() => {});
  await d.kill();
  removeDir(d.dir);
}
const problems = rows.filter((r) => /^(BUG|UNHELPFUL)/.test(r.verdict));
console.log(`\n${rows.length} steps, ${problems.length} problems`);
process.exit(problems.length ? 1 : 0);
