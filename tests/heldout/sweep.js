// The held-out sweep: every input of generate.js through the CLI, under a time and a memory
// limit, with independent checks of what it reports as success. Prints one line per step
// and a table per family; exits 1 when a step crashed, hung, ran out of memory, gave an
// unhelpful message, or succeeded with a wrong result.
//   node tests/heldout/sweep.js DIR [--cli build/archgram] [--only SUBSTRING] [--timeout S]
//                               [--mem-kb KB]
import fs from 'node:fs';
import path from 'node:path';
import { spawnSync } from 'node:child_process';
import { fileURLToPath } from 'node:url';

const here = path.dirname(fileURLToPath(import.meta.url));
const args = process.argv.slice(2);
const opt = (name, dflt) => { const i = args.indexOf(name); return i >= 0 ? args[i + 1] : dflt; };
const dir = args[0];
const cli = path.resolve(opt('--cli', path.join(here, '../../build/archgram')));
const only = opt('--only', '');
// --mem-kb 0 for a sanitizer build (its shadow memory needs a large address space)
const TIME = Number(opt('--timeout', 120)), MEM_KB = Number(opt('--mem-kb', 2 * 1024 * 1024));
if (!dir || !fs.existsSync(path.join(dir, 'manifest.json'))) {
  console.error('usage: node tests/heldout/sweep.js DIR (after node tests/heldout/generate.js DIR)');
  process.exit(2);
}
const manifest = JSON.parse(fs.readFileSync(path.join(dir, 'manifest.json'), 'utf8'));

function run(argv) {
  const cmd = MEM_KB > 0 ? `ulimit -v ${MEM_KB}; exec "$@"` : 'exec "$@"';
  const r = spawnSync('sh', ['-c', cmd, 'sh', cli, ...argv], { encoding: 'utf8', timeout: TIME * 1000, killSignal: 'SIGKILL' });
  const out = (r.stdout || '') + (r.stderr || '');
  let verdict;
  if (r.error && r.error.code === 'ETIMEDOUT') verdict = 'hang';
  else if (r.signal) verdict = `crash(${r.signal})`;
  else if (/AddressSanitizer|runtime error:|LeakSanitizer/.test(out)) verdict = 'sanitizer';
  else if (r.status === 0) verdict = 'ok';
  else if (r.status === 1 || r.status === 2) verdict = /out of memory|cannot allocate/i.test(out) ? 'oom' : 'error';
  else verdict = `exit${r.status}`;
  return { verdict, status: r.status, out: out.trim() };
}

// a message is precise when it names the file (and a line, element or field) and is one line
const precise = (out, file) => out.split('\n').some((l) => l.includes(path.basename(file)) && l.length < 400);

function readObjMesh(file) {
  const v = [], T = [];
  for (const line of fs.readFileSync(file, 'utf8').split('\n')) {
    const t = line.trim().split(/\s+/);
    if (t[0] === 'v') v.push(t.slice(1, 4).map(Number));
    else if (t[0] === 'f') { const p = t.slice(1).map((s) => parseInt(s, 10) - 1); for (let k = 1; k + 1 < p.length; k++) T.push([p[0], p[k], p[k + 1]]); }
  }
  let area = 0; const lo = [Infinity, Infinity, Infinity], hi = [-Infinity, -Infinity, -Infinity];
  for (const [a, b, c] of T) {
    const A = v[a], Bv = v[b], C = v[c];
    const u = [Bv[0] - A[0], Bv[1] - A[1], Bv[2] - A[2]], w = [C[0] - A[0], C[1] - A[1], C[2] - A[2]];
    area += Math.hypot(u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2], u[0] * w[1] - u[1] * w[0]) / 2;
    for (const p of [A, Bv, C]) for (let k = 0; k < 3; k++) { lo[k] = Math.min(lo[k], p[k]); hi[k] = Math.max(hi[k], p[k]); }
  }
  return { triangles: T.length, area, extent: hi.map((h, k) => h - lo[k]), lo, hi };
}

const rows = [];
const record = (m, step, verdict, note = '') => {
  rows.push({ family: m.family, variant: m.variant, step, verdict, note });
  console.log(`${m.family}\t${m.variant}\t${step}\t${verdict}${note ? '\t' + note.split('\n')[0].slice(0, 300) : ''}`);
};
const bad = (v) => !['ok', 'error'].includes(v);

function errorStep(m, step, r, file) {
  if (r.verdict === 'error') record(m, step, precise(r.out, file) ? 'precise-error' : 'UNHELPFUL', r.out);
  else record(m, step, r.verdict === 'ok' ? 'ok' : `BUG:${r.verdict}`, r.out);
}

function sweepMesh(m, work) {
  const f = m.file, out = path.join(work, 'p');
  let r = run(['info', f, '--json']);
  if (m.expectError) {
    errorStep(m, 'info', r, f);
    r = run(['proceduralize', f, '--out', out]);
    if (r.verdict === 'ok') record(m, 'proceduralize', 'BUG:accepted-bad-input', r.out); else errorStep(m, 'proceduralize', r, f);
    return;
  }
  if (r.verdict !== 'ok') return errorStep(m, 'info', r, f) || record(m, 'info', r.verdict === 'error' ? 'BUG:rejected-valid' : `BUG:${r.verdict}`, r.out);
  record(m, 'info', 'ok');
  r = run(['proceduralize', f, '--out', out]);
  if (r.verdict !== 'ok') return record(m, 'proceduralize', r.verdict === 'error' ? 'BUG:rejected-valid' : `BUG:${r.verdict}`, r.out);
  const up = (r.out.match(/up axis (\w)/) || [])[1];
  record(m, 'proceduralize', 'ok', r.out.split('\n')[0].replace(/^.*?: /, '') + ` [up ${up}]`);
  const back = path.join(work, 'back.obj');
  r = run(['derive', path.join(out, 'grammar.txt'), '--out', back, '--compare', f]);
  if (r.verdict !== 'ok') return record(m, 'derive', `BUG:${r.verdict}`, r.out);
  const cmp = r.out.match(/max error (\S+) \((\S+) of the diagonal\), (\d+) of (\d+) input triangles unmatched/);
  const unmatched = cmp ? Number(cmp[3]) : NaN;
  const d = readObjMesh(back);
  // independent: the derived mesh's area and extents against the input's (in metres, any
  // permutation of the axes, units scale m.scale or 1: the output may keep the file's units)
  let note = `area ${d.area.toFixed(2)} extents ${d.extent.map((x) => x.toFixed(2)).join('x')}; compare: ${cmp ? cmp.slice(1).join(' ') : r.out}`;
  let verdict = 'ok';
  if (m.area != null) {
    const sE = (e) => e.slice().sort((a, b) => a - b);
    const fits = [1, m.scale].some((k) => {
      const areaOk = Math.abs(d.area - m.area * k * k) <= 1e-3 * m.area * k * k || (m.dupArea && d.area >= m.area * k * k * 0.999);
      const ext = sE(d.extent), want = sE(m.extent.map((x) => x * k));
      return areaOk && ext.every((x, i) => Math.abs(x - want[i]) <= 1e-3 * Math.max(1, want[2]) + 0.01 * k);
    });
    if (!fits) verdict = 'BUG:wrong-result';
  }
  if (!(unmatched === 0)) verdict = verdict === 'ok' ? 'WARN:unmatched' : verdict;
  record(m, 'derive', verdict, note);
  // resize the root 1.5x along x
  const op = path.join(work, 'op.json');
  fs.writeFileSync(op, JSON.stringify({ kind: 'resize', node: 'root', scale: [1.5, 1, 1] }));
  r = run(['edit', out, '--op', op, '--out', path.join(work, 'e')]);
  record(m, 'edit-resize', r.verdict === 'ok' ? 'ok' : r.verdict === 'error' ? (precise(r.out, op) || /resize|node|root/.test(r.out) ? 'precise-error' : 'UNHELPFUL') : `BUG:${r.verdict}`, r.out);
  // part save of the first component below the root, compose it back into its own model
  const tree = JSON.parse(fs.readFileSync(path.join(out, 'tree.json'), 'utf8'));
  const nodes = tree.nodes.filter((n) => n.kind !== 'root');
  if (!nodes.length) return;
  const part = path.join(work, 'x.agpart');
  r = run(['part', 'save', out, '--node', String(nodes[0].id), '--name', 'held-out part', '--out', part]);
  record(m, 'part-save', r.verdict === 'ok' ? 'ok' : r.verdict === 'error' ? 'precise-error' : `BUG:${r.verdict}`, r.out);
  if (r.verdict !== 'ok') return;
  const target = nodes[nodes.length - 1].id;
  r = run(['part', 'compose', out, '--part', part, '--target', String(target), '--mode', 'replace', '--out', path.join(work, 'c')]);
  record(m, 'part-compose', r.verdict === 'ok' ? 'ok' : r.verdict === 'error' ? 'precise-error' : `BUG:${r.verdict}`, r.out);
}

function sweepFootprints(m, work) {
  const f = m.file;
  const outObj = path.join(work, 'city.obj'), rep = path.join(work, 'report.json');
  const r = run(['extrude', f, '--style', 'hip', '--out', outObj, '--report', rep]);
  if (m.expectError) return r.verdict === 'ok' ? record(m, 'extrude', 'BUG:accepted-bad-input', r.out) : errorStep(m, 'extrude', r, f);
  if (r.verdict !== 'ok') {
    if (r.verdict === 'error') return record(m, 'extrude', precise(r.out, f) ? 'precise-error' : 'UNHELPFUL', r.out);
    return record(m, 'extrude', `BUG:${r.verdict}`, r.out);
  }
  const d = readObjMesh(outObj);
  const ok = d.triangles > 0 && d.extent.every(Number.isFinite);
  record(m, 'extrude', ok ? 'ok' : 'BUG:empty-result', `${d.triangles} triangles, extents ${d.extent.map((x) => x.toFixed(1)).join('x')}; ${r.out.split('\n').slice(-1)[0]}`);
}

function sweepCloud(m, work) {
  const f = m.file;
  let r = run(['info', f, '--json']);
  if (m.expectError) return errorStep(m, 'info', r, f);
  if (r.verdict !== 'ok') return record(m, 'info', r.verdict === 'error' ? 'BUG:rejected-valid' : `BUG:${r.verdict}`, r.out);
  let info = null; try { info = JSON.parse(r.out.slice(r.out.indexOf('{'))); } catch { /* text */ }
  const n = info && (info.points ?? info.count);
  record(m, 'info', m.points && n !== undefined && n !== m.points ? 'BUG:wrong-count' : 'ok', `points ${n}`);
  r = run(['segment', f, '--out', path.join(work, 'seg.ply')]);
  record(m, 'segment', r.verdict === 'ok' ? 'ok' : r.verdict === 'error' ? (precise(r.out, f) ? 'precise-error' : 'UNHELPFUL') : `BUG:${r.verdict}`, r.out);
  r = run(['proceduralize', f, '--out', path.join(work, 'p')]);
  record(m, 'proceduralize', r.verdict === 'ok' ? 'ok' : r.verdict === 'error' ? (precise(r.out, f) ? 'precise-error' : 'UNHELPFUL') : `BUG:${r.verdict}`, r.out);
  if (r.verdict === 'ok') {
    r = run(['derive', path.join(work, 'p', 'grammar.txt'), '--out', path.join(work, 'back.ply'), '--compare', f]);
    record(m, 'derive', r.verdict === 'ok' ? 'ok' : `BUG:${r.verdict}`, r.out);
  }
  if (/rd|rotated|only-ground/.test(m.variant) && m.file.endsWith('.las')) {
    const fp = path.join(work, 'fp.geojson');
    const o = /rd/.test(m.variant) ? [85000, 445000] : [0, 0];
    const ring = [[-0.5, -0.5], [20.5, -0.5], [20.5, 10.5], [-0.5, 10.5], [-0.5, -0.5]].map(([x, y]) => [x + o[0], y + o[1]]);
    fs.writeFileSync(fp, JSON.stringify({ type: 'FeatureCollection', features: [{ type: 'Feature', properties: { id: 'b1' }, geometry: { type: 'Polygon', coordinates: [ring] } }] }));
    r = run(['cut', f, '--footprints', fp, '--out', path.join(work, 'cut')]);
    record(m, 'cut', r.verdict === 'ok' ? 'ok' : r.verdict === 'error' ? 'precise-error' : `BUG:${r.verdict}`, r.out);
  }
}

for (const m of manifest) {
  if (only && !`${m.family}-${m.variant}`.includes(only)) continue;
  const work = path.join(dir, 'out', `${m.family}-${m.variant}`);
  fs.rmSync(work, { recursive: true, force: true });
  fs.mkdirSync(work, { recursive: true });
  if (m.family === 'mesh') sweepMesh(m, work);
  else if (m.family === 'footprints') sweepFootprints(m, work);
  else sweepCloud(m, work);
}
fs.writeFileSync(path.join(dir, 'sweep.json'), JSON.stringify(rows, null, 1));
const problems = rows.filter((r) => /^(BUG|UNHELPFUL)/.test(r.verdict));
console.log(`\n${rows.length} steps, ${problems.length} problems`);
process.exit(problems.length ? 1 : 0);
