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
import { readExtrusion } from './generate.js';

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

const ringArea = (r) => r.reduce((a, p, i) => { const q = r[(i + 1) % r.length]; return a + p[0] * q[1] - q[0] * p[1]; }, 0) / 2;

// Independent checks of an extrusion: every group a closed 2-manifold (each welded directed
// edge once, its reverse once, no degenerate triangle), the base (faces down at the lowest z)
// of the footprint's area, no vertex beyond `reach` of the footprint's box or above `top`.
// Returns '' when all hold, else what failed.
function checkExtrusion(file, m, { reach, top, origin }) {
  const { v, weld, groups } = readExtrusion(file);
  const fails = [];
  let zmin = Infinity, zmax = -Infinity, base = 0;
  for (const [g, T] of groups) {
    const use = new Map();
    let bad = 0;
    for (const t of T) {
      const w = t.map((i) => weld[i]);
      if (w[0] === w[1] || w[1] === w[2] || w[0] === w[2]) { bad++; continue; }
      for (let k = 0; k < 3; k++) { const key = `${w[k]},${w[(k + 1) % 3]}`; use.set(key, (use.get(key) || 0) + 1); }
    }
    let open = 0;
    for (const [key, n] of use) { const [a, b] = key.split(','); if (n !== 1 || use.get(`${b},${a}`) !== 1) open++; }
    if (bad || open) fails.push(`group ${g}: ${bad} degenerate triangles, ${open} directed edges not used once each way`);
    for (const t of T) for (const i of t) { zmin = Math.min(zmin, v[i][2]); zmax = Math.max(zmax, v[i][2]); }
  }
  for (const T of groups.values()) for (const t of T) {
    const [A, B, C] = t.map((i) => v[i]);
    if (![A, B, C].every((p) => p[2] < zmin + 1e-6)) continue;
    const a = ((B[0] - A[0]) * (C[1] - A[1]) - (B[1] - A[1]) * (C[0] - A[0])) / 2;
    base -= a; // faces down are clockwise seen from above
  }
  if (!m.polys) return { fails, zmax, zmin };
  const want = m.polys.reduce((a, p) => a + p.reduce((b, r, k) => b + (k ? -1 : 1) * Math.abs(ringArea(r)), 0), 0);
  if (!(Math.abs(base - want) <= 1e-4 * want + 0.01)) fails.push(`base area ${base.toFixed(4)} m², the footprint's ${want.toFixed(4)} m²`);
  if (!(zmax <= top + 1e-3) || Math.abs(zmin) > 1e-6) fails.push(`heights ${zmin.toFixed(4)}..${zmax.toFixed(4)} m, at most 0..${top.toFixed(3)} m expected`);
  const lo = [Infinity, Infinity], hi = [-Infinity, -Infinity];
  for (const p of m.polys) for (const r of p) for (const q of r) for (let k = 0; k < 2; k++) { lo[k] = Math.min(lo[k], q[k] + m.origin[k] - origin[k]); hi[k] = Math.max(hi[k], q[k] + m.origin[k] - origin[k]); }
  let out = 0;
  for (const p of v) for (let k = 0; k < 2; k++) out = Math.max(out, lo[k] - p[k], p[k] - hi[k]);
  if (!(out <= reach + 1e-3)) fails.push(`a vertex ${out.toFixed(3)} m outside the footprint's box (at most ${reach} m expected)`);
  return { fails, zmax, zmin };
}
// the smallest half side of the polygons' boxes: no roof rises above its inradius over it
function halfSide(polys) {
  return Math.max(...polys.map((p) => { const xs = p[0].map((q) => q[0]), ys = p[0].map((q) => q[1]); return Math.min(Math.max(...xs) - Math.min(...xs), Math.max(...ys) - Math.min(...ys)) / 2; }));
}

// the largest box diagonal of the polygons: a roof whose other edges are vertical (a gable,
// a chimney's sides) can rise over the whole width
function diagonal(polys) {
  return Math.max(...polys.map((p) => { const xs = p[0].map((q) => q[0]), ys = p[0].map((q) => q[1]); return Math.hypot(Math.max(...xs) - Math.min(...xs), Math.max(...ys) - Math.min(...ys)); }));
}

// CGAL's straight skeleton (../shared/tools/cgal_skeleton, built by make into build/oracle):
// the highest 45-degree rise over the polygons, or null when it is not built.
const ORACLE = path.join(here, '../../build/oracle/cgal_skeleton');
let oracleNoted = false;
function oracleRise(m, work) {
  if (!fs.existsSync(ORACLE)) {
    if (!oracleNoted) console.log(`(${ORACLE} not built: the hip roofs are not compared with CGAL's skeleton)`);
    oracleNoted = true;
    return null;
  }
  const L = [];
  m.polys.forEach((p, i) => {
    L.push(`P part${i}`);
    for (const r of p) { L.push(`L ${r.length}`); for (const q of r) L.push(`${q[0]} ${q[1]}`); }
    L.push('E');
  });
  const txt = path.join(work, 'oracle.txt');
  fs.writeFileSync(txt, L.join('\n') + '\n');
  const r = spawnSync(ORACLE, ['--exact', txt], { encoding: 'utf8', timeout: 60000 });
  const lines = (r.stdout || '').split('\n').filter((l) => l.startsWith('part'));
  const notOk = lines.find((l) => l.split(',')[6] !== 'ok');
  if (lines.length !== m.polys.length || notOk) return { error: `not compared (${notOk ? notOk.split(',')[6] : (r.stdout || r.stderr).trim()})` };
  return { rise: Math.max(...lines.map((l) => Number(l.split(',')[7]))) };
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
  const summary = `${d.triangles} triangles, extents ${d.extent.map((x) => x.toFixed(1)).join('x')}; ${r.out.split('\n').slice(-1)[0]}`;
  if (!ok) return record(m, 'extrude', 'BUG:empty-result', summary);
  const report = JSON.parse(fs.readFileSync(rep, 'utf8'));
  const fell = report.fallbacks.length || report.failed.length;
  // hip: walls to the height, then 45 degrees; no part of it leaves the footprint's box
  const c = checkExtrusion(outObj, m, { reach: 0, top: (m.height || 0) + (m.polys ? halfSide(m.polys) : 0), origin: report.origin || [0, 0] });
  let verdict = c.fails.length ? 'BUG:wrong-result' : fell ? 'WARN:fallback' : 'ok';
  let note = c.fails.length ? c.fails.join('; ') : summary;
  if (!c.fails.length && m.polys && !fell) {
    const o = oracleRise(m, work);
    if (o && o.error) note += `; CGAL: ${o.error.split('\n')[0]}`;
    else if (o && Math.abs(c.zmax - m.height - o.rise) > 1e-3) { verdict = 'BUG:wrong-result'; note = `roof rise ${(c.zmax - m.height).toFixed(4)} m, CGAL's skeleton ${o.rise.toFixed(4)} m`; }
    else if (o) note += `; rise ${o.rise.toFixed(3)} m as CGAL's`;
  }
  record(m, 'extrude', verdict, note);
  if (m.polys) sweepMixedStyle(m, work);
}

// per-edge profiles from a style's rules: vertical walls north, a 0.5 m soffit and 45°
// south, steep (63°) or the soffit elsewhere; reach: the soffit mitred (2.5x), top: the
// steep slope over the whole footprint
const MIXED = { name: 'mixed', height: 9, seed: 7, profiles: { steep: [[0.5, 1]], wall: [[0, 1]], over: [[-0.5, 0], [2.5, 3]] },
  rules: [{ orientation: 'north', profiles: 'wall' }, { orientation: 'south', profiles: 'over' }, { profiles: { steep: 0.6, over: 0.4 } }] };
function sweepMixedStyle(m, work) {
  const style = path.join(work, 'mixed.json'), outObj = path.join(work, 'mixed.obj'), rep = path.join(work, 'mixed-report.json');
  fs.writeFileSync(style, JSON.stringify(MIXED));
  const r = run(['extrude', m.file, '--style', style, '--out', outObj, '--report', rep]);
  if (r.verdict !== 'ok') return record(m, 'extrude-mixed', r.verdict === 'error' ? 'BUG:rejected-valid' : `BUG:${r.verdict}`, r.out);
  const report = JSON.parse(fs.readFileSync(rep, 'utf8'));
  const c = checkExtrusion(outObj, m, { reach: 2.5 * 0.5, top: m.height + 2 * (diagonal(m.polys) + 0.5), origin: report.origin || [0, 0] });
  const fell = report.fallbacks.length || report.failed.length;
  record(m, 'extrude-mixed', c.fails.length ? 'BUG:wrong-result' : fell ? 'WARN:fallback' : 'ok', c.fails.length ? c.fails.join('; ') : r.out.split('\n').slice(-1)[0]);
}

// a plan with per-edge profiles, steps and offset events: the shell is checked like a
// footprint's, with the reach its overhangs (mitred up to 2.5x) and steps allow
function sweepPlan(m, work) {
  const outObj = path.join(work, 'plan.obj');
  const r = run(['extrude', '--plan', m.file, '--out', outObj]);
  // every plan here is valid: an error (a refusal, or a building that is not good) is a bug
  if (r.verdict !== 'ok') return record(m, 'extrude-plan', r.verdict === 'error' ? 'BUG:rejected-valid' : `BUG:${r.verdict}`, r.out.split('\n').filter((l) => /not good|: /.test(l)).slice(-2).join(' | '));
  const c = checkExtrusion(outObj, m, { reach: 2.5 * 0.6 + 1, top: 7 + 2 * (diagonal(m.polys) + 0.6) + 3, origin: [0, 0] });
  record(m, 'extrude-plan', c.fails.length ? 'BUG:wrong-result' : 'ok', c.fails.length ? c.fails.join('; ') : r.out.split('\n').slice(-1)[0]);
}

// A segmented PLY as archgram writes it (binary little endian, `comment offset`): the
// absolute points of each segment.
function readSegments(file) {
  const b = fs.readFileSync(file);
  const end = b.indexOf('end_header\n') + 11;
  const head = b.subarray(0, end).toString().split('\n');
  const off = (head.find((l) => l.startsWith('comment offset')) || 'comment offset 0 0 0').split(' ').slice(2).map(Number);
  const size = { char: 1, uchar: 1, short: 2, ushort: 2, int: 4, uint: 4, float: 4, double: 8 };
  const at = {};
  let rec = 0;
  for (const l of head.filter((x) => x.startsWith('property '))) { const [, type, name] = l.split(' '); at[name] = [rec, type]; rec += size[type]; }
  const n = Number(head.find((l) => l.startsWith('element vertex')).split(' ')[2]);
  const get = (o, [k, type]) => (type === 'float' ? b.readFloatLE(o + k) : type === 'double' ? b.readDoubleLE(o + k) : b.readInt32LE(o + k));
  const seg = new Map();
  for (let i = 0; i < n; i++) {
    const o = end + i * rec, s = get(o, at.segment);
    if (!seg.has(s)) seg.set(s, []);
    seg.get(s).push(['x', 'y', 'z'].map((c, k) => get(o, at[c]) + off[k]));
  }
  return seg;
}
// the planes of cloudPoints' box building (turned by `deg` about z, moved by `o`) as
// [normal, d]: the ground and the roof, four walls
function boxPlanes(deg, o) {
  const a = deg * Math.PI / 180, c = Math.cos(a), s = Math.sin(a);
  const wall = (nx, ny, x, y) => { const n = [c * nx - s * ny, s * nx + c * ny, 0]; const p = [c * x - s * y + o[0], s * x + c * y + o[1]]; return [n, n[0] * p[0] + n[1] * p[1]]; };
  return [[[0, 0, 1], o[2]], [[0, 0, 1], o[2] + 9], wall(0, 1, 0, 0), wall(0, 1, 0, 10), wall(1, 0, 0, 0), wall(1, 0, 20, 0)];
}
// each known plane has one segment holding most of its points, all of which lie on it
function checkPlanes(file, planes) {
  const seg = readSegments(file);
  const dist = (p, [n, d]) => Math.abs(n[0] * p[0] + n[1] * p[1] + n[2] * p[2] - d);
  const fails = [], found = [];
  planes.forEach((pl, k) => {
    let best = null;
    for (const [id, P] of seg) {
      if (id < 0) continue;
      const on = P.filter((p) => dist(p, pl) < 0.05).length;
      if (!best || on > best.on) best = { id, on, all: P.length };
    }
    const onPlane = [...seg.values()].flat().filter((p) => dist(p, pl) < 0.02).length;
    if (!best || best.on < 0.8 * best.all || best.on < 0.6 * onPlane) fails.push(`plane ${k}: no segment holds it (best: segment ${best && best.id}, ${best && best.on} of its ${best && best.all} points on it, the plane has ${onPlane})`);
    else found.push(best.id);
  });
  if (new Set(found).size !== found.length) fails.push(`two planes in one segment (${found})`);
  const small = [...seg].filter(([id]) => id >= 0 && !found.includes(id));
  return { fails, note: `${planes.length} planes found as segments ${found.join(',')}; ${small.length} more segments of ${small.reduce((a, [, P]) => a + P.length, 0)} points` };
}

function sweepCloud(m, work) {
  const f = m.file;
  let r = run(['info', f, '--json']);
  if (m.expectError) {
    if (m.refuse && r.verdict === 'error' && !new RegExp(m.refuse, 'i').test(r.out)) return record(m, 'info', 'UNHELPFUL', `refused, but not naming /${m.refuse}/: ${r.out}`);
    return errorStep(m, 'info', r, f);
  }
  if (r.verdict !== 'ok') return record(m, 'info', r.verdict === 'error' ? 'BUG:rejected-valid' : `BUG:${r.verdict}`, r.out);
  let info = null; try { info = JSON.parse(r.out.slice(r.out.indexOf('{'))); } catch { /* text */ }
  const n = info && (info.points ?? info.count);
  let verdict = m.points && n !== undefined && n !== m.points ? 'BUG:wrong-count' : 'ok', note = `points ${n}`;
  if (m.bbox && info) {
    const off = [0, 1, 2].flatMap((k) => [info.min[k] - m.bbox[0][k], info.max[k] - m.bbox[1][k]]).map(Math.abs);
    const tol = 1e-6 * (1 + Math.max(...m.bbox[1].map(Math.abs)));
    if (!(Math.max(...off) <= tol)) { verdict = 'BUG:wrong-bbox'; note += `; box ${JSON.stringify([info.min, info.max])}, stored ${JSON.stringify(m.bbox)}`; }
    else note += '; box as stored';
  }
  record(m, 'info', verdict, note);
  const seg = path.join(work, 'seg.ply');
  r = run(['segment', f, '--out', seg]);
  if (r.verdict === 'ok' && m.planes) {
    const c = checkPlanes(seg, boxPlanes(/rot23/.test(m.variant) ? 23 : 0, /rot23/.test(m.variant) ? [0, 0, 0] : [85000, 445000, 0]));
    record(m, 'segment', c.fails.length ? 'BUG:wrong-result' : 'ok', c.fails.length ? c.fails.join('; ') : c.note);
  } else record(m, 'segment', r.verdict === 'ok' ? 'ok' : r.verdict === 'error' ? (precise(r.out, f) ? 'precise-error' : 'UNHELPFUL') : `BUG:${r.verdict}`, r.out);
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
  else if (m.family === 'plan') sweepPlan(m, work);
  else sweepCloud(m, work);
}
fs.writeFileSync(path.join(dir, 'sweep.json'), JSON.stringify(rows, null, 1));
const problems = rows.filter((r) => /^(BUG|UNHELPFUL)/.test(r.verdict));
const table = {};
for (const r of rows) { const k = r.verdict.replace(/:.*/, ''); (table[r.family] ??= {})[k] = (table[r.family][k] || 0) + 1; }
for (const [fam, t] of Object.entries(table)) console.log(`${fam}\t${Object.entries(t).map(([k, n]) => `${k} ${n}`).join(', ')}`);
console.log(`\n${rows.length} steps, ${problems.length} problems`);
process.exit(problems.length ? 1 : 0);
