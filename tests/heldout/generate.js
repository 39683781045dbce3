// Held-out inputs: meshes, footprints and point clouds shaped like third-party data (other
// exporters' conventions, units, offsets, axes) rather than like the project's fixtures.
// `node tests/heldout/generate.js DIR` writes every variant into DIR and DIR/manifest.json
// (one entry per file: family, variant, command kind, and the facts an independent check
// needs: the input's triangle area in metres and its extents). tests/heldout/sweep.js runs
// the CLI on them.
import fs from 'node:fs';
import path from 'node:path';
import { fileURLToPath } from 'node:url';

const here = path.dirname(fileURLToPath(import.meta.url));
export const SHARED = path.resolve(here, '../../../shared/data');

// --- a synthetic building: z up, metres, polygons (quads) --------------------------------
// A 20 x 10 x 9 m block with a gable roof and 4 x 3 protruding windows on the front facade.
export function building() {
  const v = [], f = [];
  const box = (x0, y0, z0, x1, y1, z1) => {
    const b = v.length;
    for (const [x, y, z] of [[x0, y0, z0], [x1, y0, z0], [x1, y1, z0], [x0, y1, z0],
      [x0, y0, z1], [x1, y0, z1], [x1, y1, z1], [x0, y1, z1]]) v.push([x, y, z]);
    for (const q of [[0, 3, 2, 1], [4, 5, 6, 7], [0, 1, 5, 4], [1, 2, 6, 5], [2, 3, 7, 6], [3, 0, 4, 7]])
      f.push(q.map((i) => b + i));
  };
  box(0, 0, 0, 20, 10, 9);
  // gable: a prism on top, ridge along x
  const b = v.length;
  v.push([0, 0, 9], [20, 0, 9], [20, 10, 9], [0, 10, 9], [0, 5, 13], [20, 5, 13]);
  f.push([b + 0, b + 1, b + 5, b + 4], [b + 2, b + 3, b + 4, b + 5], [b + 0, b + 4, b + 3], [b + 1, b + 2, b + 5]);
  for (let c = 0; c < 4; c++)
    for (let r = 0; r < 3; r++) {
      const x = 2 + c * 4.5, z = 1 + r * 2.8;
      box(x, -0.2, z, x + 1.5, 0, z + 1.6);
    }
  return { v, f };
}

export const tri = (f) => f.flatMap((p) => p.slice(2).map((_, k) => [p[0], p[k + 1], p[k + 2]]));

function area3(a, b, c) {
  const u = [b[0] - a[0], b[1] - a[1], b[2] - a[2]], w = [c[0] - a[0], c[1] - a[1], c[2] - a[2]];
  const x = u[1] * w[2] - u[2] * w[1], y = u[2] * w[0] - u[0] * w[2], z = u[0] * w[1] - u[1] * w[0];
  return Math.hypot(x, y, z) / 2;
}
export function measure(v, f) {
  let area = 0;
  const lo = [Infinity, Infinity, Infinity], hi = [-Infinity, -Infinity, -Infinity];
  for (const t of tri(f)) {
    area += area3(v[t[0]], v[t[1]], v[t[2]]);
    for (const i of t) for (let k = 0; k < 3; k++) { lo[k] = Math.min(lo[k], v[i][k]); hi[k] = Math.max(hi[k], v[i][k]); }
  }
  return { area, extent: hi.map((h, k) => h - lo[k]), lo, hi };
}

// transforms of a z-up mesh
const mapv = (m, fn) => ({ v: m.v.map(fn), f: m.f });
export const rotZ = (m, deg) => {
  const a = deg * Math.PI / 180, c = Math.cos(a), s = Math.sin(a);
  return mapv(m, ([x, y, z]) => [c * x - s * y, s * x + c * y, z]);
};
export const scale = (m, k) => mapv(m, (p) => p.map((x) => x * k));
export const offset = (m, o) => mapv(m, (p) => p.map((x, i) => x + o[i]));
export const yUp = (m) => mapv(m, ([x, y, z]) => [x, z, -y]);

function rng(seed) {
  let s = seed >>> 0;
  return () => { s = (s * 1664525 + 1013904223) >>> 0; return s / 4294967296; };
}
const shuffle = (a, r) => { a = a.slice(); for (let i = a.length - 1; i > 0; i--) { const j = Math.floor(r() * (i + 1)); [a[i], a[j]] = [a[j], a[i]]; } return a; };

// --- writers ------------------------------------------------------------------------------
const num = (x, fmt) => fmt === 'sci' ? x.toExponential(9) : fmt === 'fixed' ? x.toFixed(6) : String(+x.toFixed(6));
export function objText(m, o = {}) {
  const nl = o.crlf ? '\r\n' : '\n', sp = o.tabs ? '\t' : ' ';
  const L = [];
  if (o.mtllib) L.push(`mtllib ${o.mtllib}`);
  L.push('# exported by a third-party tool');
  m.v.forEach((p, i) => {
    let s = ['v', ...p.map((x) => num(x, o.num))].join(sp);
    if (o.colours) s += `${sp}0.5${sp}0.25${sp}1`;
    if (o.midComments && i % 3 === 0) s += ' # corner';
    L.push(s);
  });
  if (o.unreferenced) for (let i = 0; i < 50; i++) L.push(`v ${1000 + i} ${-1000} ${i}`);
  if (o.vt) { L.push('vt 0 0', 'vt 1 0', 'vt 1 1', 'vt 0 1'); }
  if (o.vn) { L.push('vn 0 0 1', 'vn 0 1 0'); }
  const n = m.v.length;
  m.f.forEach((p, k) => {
    if (o.groupsEach) L.push(`g part_${k}`);
    else if (o.objects && k % 7 === 0) L.push(`o object_${k / 7}`, `usemtl mat_${k % 3}`);
    if (o.smooth && k === 0) L.push('s off');
    const refs = p.map((i, j) => {
      const idx = o.negative ? i - n : i + 1;
      if (o.vt && o.vn) return k % 3 === 0 ? `${idx}/${(j % 4) + 1}/1` : k % 3 === 1 ? `${idx}//2` : `${idx}/${(j % 4) + 1}`;
      return String(idx);
    });
    L.push(['f', ...refs].join(sp) + (o.midComments && k % 5 === 0 ? ' # face' : ''));
  });
  if (o.lines) L.push('l 1 2', 'p 3');
  return L.join(nl) + nl;
}

export function plyText(m, o = {}) {
  const fmt = o.format || 'ascii';
  const T = tri(m.f);
  const faces = o.quads ? m.f : T;
  const extra = !!o.extra;
  const h = [`ply`, `format ${fmt} 1.0`, 'comment made by another tool'];
  const cT = o.double ? 'double' : 'float';
  h.push(`element vertex ${m.v.length}`, `property ${cT} x`, `property ${cT} y`, `property ${cT} z`);
  if (extra) h.push('property float nx', 'property float ny', 'property float nz', 'property uchar red', 'property uchar green', 'property uchar blue', 'property float quality');
  h.push(`element face ${faces.length}`, `property list uchar ${o.intIdx ? 'uint' : 'int'} ${o.vertexIndex ? 'vertex_index' : 'vertex_indices'}`);
  if (extra) h.push('property int flags');
  h.push('end_header');
  if (fmt === 'ascii') {
    const L = [...h];
    for (const p of m.v) L.push([...p.map((x) => num(x)), ...(extra ? ['0', '0', '1', '200', '10', '10', '0.5'] : [])].join(' '));
    for (const t of faces) L.push([t.length, ...t, ...(extra ? [3] : [])].join(' '));
    return Buffer.from(L.join('\n') + '\n');
  }
  const le = fmt === 'binary_little_endian';
  const bufs = [Buffer.from(h.join('\n') + '\n')];
  for (const p of m.v) {
    const b = Buffer.alloc((o.double ? 24 : 12) + (extra ? 12 + 3 + 4 : 0));
    let off = 0;
    for (const x of p) { if (o.double) { le ? b.writeDoubleLE(x, off) : b.writeDoubleBE(x, off); off += 8; } else { le ? b.writeFloatLE(x, off) : b.writeFloatBE(x, off); off += 4; } }
    if (extra) {
      for (const x of [0, 0, 1]) { le ? b.writeFloatLE(x, off) : b.writeFloatBE(x, off); off += 4; }
      b[off++] = 200; b[off++] = 10; b[off++] = 10;
      le ? b.writeFloatLE(0.5, off) : b.writeFloatBE(0.5, off);
    }
    bufs.push(b);
  }
  for (const t of faces) {
    const b = Buffer.alloc(1 + 4 * t.length + (extra ? 4 : 0));
    b[0] = t.length;
    t.forEach((i, k) => (le ? b.writeUInt32LE(i, 1 + 4 * k) : b.writeUInt32BE(i, 1 + 4 * k)));
    if (extra) le ? b.writeInt32LE(3, 1 + 4 * t.length) : b.writeInt32BE(3, 1 + 4 * t.length);
    bufs.push(b);
  }
  return Buffer.concat(bufs);
}

function normal(a, b, c) {
  const u = [b[0] - a[0], b[1] - a[1], b[2] - a[2]], w = [c[0] - a[0], c[1] - a[1], c[2] - a[2]];
  const n = [u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2], u[0] * w[1] - u[1] * w[0]];
  const l = Math.hypot(...n) || 1;
  return n.map((x) => x / l);
}
export function stlAscii(m) {
  const L = ['solid building'];
  for (const t of tri(m.f)) {
    const [a, b, c] = t.map((i) => m.v[i]);
    L.push(`  facet normal ${normal(a, b, c).map((x) => x.toExponential(6)).join(' ')}`, '    outer loop');
    for (const p of [a, b, c]) L.push(`      vertex ${p.map((x) => x.toExponential(6)).join(' ')}`);
    L.push('    endloop', '  endfacet');
  }
  L.push('endsolid building');
  return Buffer.from(L.join('\n') + '\n');
}
// binary STL; solidHeader: the 80-byte header starts with "solid" (many exporters do this)
export function stlBinary(m, solidHeader) {
  const T = tri(m.f);
  const b = Buffer.alloc(84 + 50 * T.length);
  b.write(solidHeader ? 'solid exported binary' : 'binary STL', 0);
  b.writeUInt32LE(T.length, 80);
  T.forEach((t, k) => {
    const o = 84 + 50 * k, P = t.map((i) => m.v[i]);
    normal(...P).forEach((x, j) => b.writeFloatLE(x, o + 4 * j));
    P.forEach((p, j) => p.forEach((x, i) => b.writeFloatLE(x, o + 12 + 12 * j + 4 * i)));
  });
  return b;
}

// glTF 2.0 (y up by the format), one mesh; node: a translation and a rotation about y
export function gltf(m, { binary, node } = {}) {
  const y = yUp(m), T = tri(y.f);
  const pos = Buffer.alloc(12 * y.v.length), idx = Buffer.alloc(4 * T.length * 3);
  const lo = [Infinity, Infinity, Infinity], hi = [-Infinity, -Infinity, -Infinity];
  y.v.forEach((p, i) => p.forEach((x, k) => { pos.writeFloatLE(x, 12 * i + 4 * k); lo[k] = Math.min(lo[k], Math.fround(x)); hi[k] = Math.max(hi[k], Math.fround(x)); }));
  T.flat().forEach((i, k) => idx.writeUInt32LE(i, 4 * k));
  const bin = Buffer.concat([pos, idx]);
  const doc = {
    asset: { version: '2.0', generator: 'another tool' }, scene: 0, scenes: [{ nodes: [0] }],
    nodes: [{ mesh: 0, ...(node || {}) }],
    meshes: [{ primitives: [{ attributes: { POSITION: 0 }, indices: 1 }] }],
    buffers: [binary ? { byteLength: bin.length } : { byteLength: bin.length, uri: `data:application/octet-stream;base64,${bin.toString('base64')}` }],
    bufferViews: [{ buffer: 0, byteOffset: 0, byteLength: pos.length }, { buffer: 0, byteOffset: pos.length, byteLength: idx.length }],
    accessors: [{ bufferView: 0, componentType: 5126, count: y.v.length, type: 'VEC3', min: lo, max: hi },
      { bufferView: 1, componentType: 5125, count: T.length * 3, type: 'SCALAR' }],
  };
  if (!binary) return Buffer.from(JSON.stringify(doc));
  let js = Buffer.from(JSON.stringify(doc));
  js = Buffer.concat([js, Buffer.alloc((4 - (js.length % 4)) % 4, 0x20)]);
  const head = Buffer.alloc(12);
  head.write('glTF', 0); head.writeUInt32LE(2, 4); head.writeUInt32LE(12 + 8 + js.length + 8 + bin.length, 8);
  const c0 = Buffer.alloc(8); c0.writeUInt32LE(js.length, 0); c0.write('JSON', 4);
  const c1 = Buffer.alloc(8); c1.writeUInt32LE(bin.length, 0); c1.write('BIN\0', 4);
  return Buffer.concat([head, c0, js, c1, bin]);
}

// --- an OBJ reader for the shared meshes (v and f only) -----------------------------------
export function readObj(file) {
  const v = [], f = [];
  for (const line of fs.readFileSync(file, 'utf8').split(/\r?\n/)) {
    const t = line.trim().split(/\s+/);
    if (t[0] === 'v') v.push(t.slice(1, 4).map(Number));
    else if (t[0] === 'f') f.push(t.slice(1).map((s) => { const i = parseInt(s, 10); return i < 0 ? v.length + i : i - 1; }));
  }
  return { v, f };
}

// An extrusion's OBJ as z-up points, triangles per group (component) and each vertex's id
// welded at 1e-6 m: what sweep.js and the held-out tests check extrusions on.
export function readExtrusion(file) {
  const text = fs.readFileSync(file, 'utf8');
  const yup = /^# archgram:.*y up/m.test(text);
  const v = [], groups = new Map();
  let g = '';
  for (const line of text.split('\n')) {
    const t = line.trim().split(/\s+/);
    if (t[0] === 'v') { const [x, y, z] = t.slice(1, 4).map(Number); v.push(yup ? [x, -z, y] : [x, y, z]); }
    else if (t[0] === 'g' || t[0] === 'o') g = t.slice(1).join(' ');
    else if (t[0] === 'f') {
      const p = t.slice(1).map((s) => parseInt(s, 10) - 1);
      if (!groups.has(g)) groups.set(g, []);
      for (let k = 1; k + 1 < p.length; k++) groups.get(g).push([p[0], p[k], p[k + 1]]);
    }
  }
  const ids = new Map();
  const weld = v.map((p) => { const k = p.map((x) => Math.round(x * 1e6)).join(','); if (!ids.has(k)) ids.set(k, ids.size); return ids.get(k); });
  return { v, weld, groups };
}

// --- mesh variants ------------------------------------------------------------------------
export function meshVariants() {
  const out = [];
  const add = (variant, ext, data, base, extra = {}) => out.push({ family: 'mesh', variant, ext, data, base, ...extra });
  const B = building();
  const T = { v: B.v, f: tri(B.f) };
  add('obj-quads', 'obj', objText(B), B);
  add('obj-triangles', 'obj', objText(T), B);
  add('obj-negative-indices', 'obj', objText(B, { negative: true }), B);
  add('obj-vt-vn-mix', 'obj', objText(B, { vt: true, vn: true }), B);
  add('obj-groups-each-face', 'obj', objText(B, { groupsEach: true }), B);
  add('obj-objects-usemtl-missing-mtllib', 'obj', objText(B, { objects: true, mtllib: 'absent.mtl', smooth: true }), B);
  add('obj-crlf-tabs', 'obj', objText(B, { crlf: true, tabs: true }), B);
  add('obj-scientific', 'obj', objText(B, { num: 'sci' }), B);
  add('obj-mid-line-comments', 'obj', objText(B, { midComments: true }), B);
  add('obj-vertex-colours', 'obj', objText(B, { colours: true }), B);
  add('obj-unreferenced-vertices', 'obj', objText(B, { unreferenced: true }), B);
  add('obj-lines-points', 'obj', objText(B, { lines: true }), B);
  add('obj-utm32', 'obj', objText(offset(B, [678088, 5403784, 413]), { num: 'fixed' }), B);
  add('obj-rd-new', 'obj', objText(offset(B, [85000, 445000, -2]), { num: 'fixed' }), B);
  add('obj-1e7', 'obj', objText(offset(B, [1e7, 1e7, 0]), { num: 'fixed' }), B);
  add('obj-yup', 'obj', objText(yUp(B)), B);
  add('obj-yup-utm', 'obj', objText(yUp(offset(B, [678088, 5403784, 413])), { num: 'fixed' }), B);
  for (const deg of [17, 30, 45, 133]) add(`obj-rot${deg}`, 'obj', objText(rotZ(B, deg)), rotZ(B, deg));
  add('obj-mm', 'obj', objText(scale(B, 1000)), B, { scale: 1000 });
  add('obj-feet', 'obj', objText(scale(B, 1 / 0.3048)), B, { scale: 1 / 0.3048 });
  add('obj-yup-mm-rot30', 'obj', objText(yUp(scale(rotZ(B, 30), 1000))), rotZ(B, 30), { scale: 1000 });
  const r = rng(5);
  add('obj-faces-shuffled', 'obj', objText({ v: B.v, f: shuffle(T.f, r) }), B);
  add('obj-winding-reversed', 'obj', objText({ v: B.v, f: B.f.map((p) => p.slice().reverse()) }), B);
  // degenerate and duplicate faces: area unchanged by zero-area ones; duplicates double it
  const deg = { v: B.v, f: [...B.f, [0, 0, 1], [0, 1, 1, 0], [2, 2, 2]] };
  add('obj-degenerate-faces', 'obj', objText(deg), B);
  add('obj-duplicate-faces', 'obj', objText({ v: B.v, f: [...B.f, ...B.f.slice(0, 6)] }), B, { dupArea: true });
  // a fin: a non-manifold flap on the ridge
  const nm = { v: [...B.v, [10, 5, 16]], f: [...B.f, [52, 53, B.v.length]] };
  add('obj-non-manifold-fin', 'obj', objText(nm), null);
  // an n-gon floor: the box bottom as an octagon with collinear midpoints
  const ng = { v: [...B.v, [10, 0, 0], [20, 5, 0], [10, 10, 0], [0, 5, 0]], f: B.f.slice(1) };
  const n0 = B.v.length;
  ng.f.unshift([0, n0 + 3, 3, n0 + 2, 2, n0 + 1, 1, n0]);
  add('obj-ngon-collinear', 'obj', objText(ng), B);
  // ground plane and a terrain skirt
  const gp = { v: [...B.v, [-90, -95, -0.01], [110, -95, -0.01], [110, 105, -0.01], [-90, 105, -0.01]], f: [...B.f, [n0, n0 + 1, n0 + 2, n0 + 3]] };
  add('obj-ground-plane', 'obj', objText(gp), null);
  const sk = { v: [...B.v], f: [...B.f] };
  const ring = [[-1, -1], [21, -1], [21, 11], [-1, 11]];
  for (const [x, y] of ring) sk.v.push([x, y, 0.3]);
  for (const [x, y] of ring) sk.v.push([x * 1.5 - 5, y * 1.5 - 2.5, -3]);
  for (let k = 0; k < 4; k++) sk.f.push([n0 + k, n0 + 4 + k, n0 + 4 + ((k + 1) % 4), n0 + ((k + 1) % 4)]);
  add('obj-terrain-skirt', 'obj', objText(sk), null);
  add('obj-empty', 'obj', '# nothing here\n', null, { expectError: true });
  add('obj-only-vertices', 'obj', 'v 0 0 0\nv 1 0 0\nv 0 1 0\n', null, { expectError: true });
  add('obj-index-zero', 'obj', 'v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n', null, { expectError: true });
  add('obj-nan', 'obj', 'v 0 0 0\nv nan 0 0\nv 0 1 0\nf 1 2 3\n', null, { expectError: true });
  add('obj-inf', 'obj', 'v 0 0 0\nv 1e400 0 0\nv 0 1 0\nf 1 2 3\n', null, { expectError: true });
  add('obj-utf8-bom', 'obj', '\ufeff' + objText(B), B);
  add('obj-line-continuation', 'obj', objText(B).replace('f 1 4 3 2', 'f 1 4 \\\n3 2'), B);

  // PLY and STL, glTF
  for (const format of ['ascii', 'binary_little_endian', 'binary_big_endian']) {
    add(`ply-${format}`, 'ply', plyText(B, { format }), B);
    add(`ply-${format}-extra-props`, 'ply', plyText(B, { format, extra: true, quads: true }), B);
    add(`ply-${format}-double-utm`, 'ply', plyText(offset(B, [678088, 5403784, 413]), { format, double: true }), B);
  }
  add('ply-vertex_index-uint', 'ply', plyText(B, { vertexIndex: true, intIdx: true, format: 'binary_little_endian' }), B);
  add('stl-ascii', 'stl', stlAscii(B), B);
  add('stl-binary', 'stl', stlBinary(B, false), B);
  add('stl-binary-solid-header', 'stl', stlBinary(B, true), B);
  add('stl-ascii-mm', 'stl', stlAscii(scale(B, 1000)), B, { scale: 1000 });
  add('stl-binary-rot30-rd', 'stl', stlBinary(offset(rotZ(B, 30), [85000, 445000, 0]), false), rotZ(B, 30));
  add('gltf-embedded', 'gltf', gltf(B), B);
  add('glb', 'glb', gltf(B, { binary: true }), B);
  add('glb-node-transform', 'glb', gltf(B, { binary: true, node: { translation: [5, 0, 3], rotation: [0, Math.sin(Math.PI / 12), 0, Math.cos(Math.PI / 12)] } }), rotZ(B, 30));

  // shared meshes, transformed
  const pick = [['lod3_ingolstadt/obj/4018148.obj', 'ingolstadt148'], ['lod3_ingolstadt/obj/4018194.obj', 'ingolstadt194'], ['meshes_0ad/rome_workshop.obj', '0ad-workshop']];
  for (const [rel, name] of pick) {
    const file = path.join(SHARED, rel);
    if (!fs.existsSync(file)) continue;
    let M = readObj(file);
    const zup = rel.includes('ingolstadt');
    if (!zup) M = mapv(M, ([x, y, z]) => [x, -z, y]); // 0 A.D. is y up
    const MT = { v: M.v, f: tri(M.f) };
    const rr = rng(11);
    add(`${name}-as-is`, 'obj', objText(M), M);
    add(`${name}-rot37-utm-shuffled`, 'obj', objText({ v: rotZ(offset(M, [0, 0, 0]), 37).v.map(([x, y, z]) => [x + 678088, y + 5403784, z + 413]), f: shuffle(MT.f, rr) }, { num: 'fixed' }), rotZ(M, 37));
    add(`${name}-reversed-mm`, 'obj', objText({ v: scale(M, 1000).v, f: M.f.map((p) => p.slice().reverse()) }), M, { scale: 1000 });
    add(`${name}-yup-rot200`, 'obj', objText(yUp(rotZ(M, 200))), rotZ(M, 200));
    add(`${name}-ply-be`, 'ply', plyText(rotZ(M, 73), { format: 'binary_big_endian' }), rotZ(M, 73));
    add(`${name}-stl`, 'stl', stlBinary(offset(M, [85000, 445000, 0]), true), M);
  }
  return out;
}

// --- footprints -----------------------------------------------------------------------------
export function footprintVariants() {
  const out = [];
  const add = (variant, doc, extra = {}) => out.push({ family: 'footprints', variant, ext: 'geojson', data: typeof doc === 'string' ? doc : JSON.stringify(doc), ...extra });
  const fc = (features) => ({ type: 'FeatureCollection', features });
  const poly = (rings, props = { height: 9 }) => ({ type: 'Feature', properties: props, geometry: { type: 'Polygon', coordinates: rings } });
  const sq = (x, y, w, h) => [[x, y], [x + w, y], [x + w, y + h], [x, y + h], [x, y]];
  const o = [85000, 445000];
  const at = (ring) => ring.map(([x, y, ...z]) => [x + o[0], y + o[1], ...z]);
  add('ccw-closed', fc([poly([at(sq(0, 0, 20, 10))])]));
  add('cw-closed', fc([poly([at(sq(0, 0, 20, 10)).reverse()])]));
  add('open-ring', fc([poly([at(sq(0, 0, 20, 10)).slice(0, 4)])]));
  add('hole', fc([poly([at(sq(0, 0, 30, 30)), at(sq(10, 10, 10, 10)).reverse()])]));
  add('hole-same-winding', fc([poly([at(sq(0, 0, 30, 30)), at(sq(10, 10, 10, 10))])]));
  add('multipolygon', fc([{ type: 'Feature', properties: { height: 12 }, geometry: { type: 'MultiPolygon', coordinates: [[at(sq(0, 0, 10, 10))], [at(sq(20, 0, 10, 15))]] } }]));
  add('3d-coordinates', fc([poly([at(sq(0, 0, 20, 10).map(([x, y]) => [x, y, 1.5]))])]));
  add('collinear-duplicate', fc([poly([at([[0, 0], [5, 0], [5, 0], [10, 0], [20, 0], [20, 10], [20, 10], [0, 10], [0, 0]])])]));
  add('sliver', fc([poly([at([[0, 0], [20, 0], [20, 0.001], [0, 0.001], [0, 0]])]), poly([at(sq(30, 0, 10, 10))])]));
  add('huge-offset-1e7', fc([poly([sq(0, 0, 20, 10).map(([x, y]) => [x + 1e7, y + 1e7])])]));
  add('height-missing', fc([poly([at(sq(0, 0, 20, 10))], {})]));
  add('height-string', fc([poly([at(sq(0, 0, 20, 10))], { height: '9.5' })]));
  add('height-garbage', fc([poly([at(sq(0, 0, 20, 10))], { height: 'tall' })]));
  add('height-negative', fc([poly([at(sq(0, 0, 20, 10))], { height: -4 })]));
  add('properties-null', fc([{ type: 'Feature', properties: null, geometry: { type: 'Polygon', coordinates: [at(sq(0, 0, 20, 10))] } }]));
  add('geometry-null', fc([{ type: 'Feature', properties: {}, geometry: null }, poly([at(sq(30, 0, 10, 10))])]));
  add('two-point-ring', fc([poly([at([[0, 0], [1, 1], [0, 0]])]), poly([at(sq(30, 0, 10, 10))])]));
  add('self-intersecting-bowtie', fc([poly([at([[0, 0], [10, 10], [10, 0], [0, 10], [0, 0]])]), poly([at(sq(30, 0, 10, 10))])]));
  add('lonlat', fc([poly([[[4.3, 52.07], [4.3003, 52.07], [4.3003, 52.0702], [4.3, 52.0702], [4.3, 52.07]]])]));
  add('single-feature', poly([at(sq(0, 0, 20, 10))]));
  add('bare-geometry', { type: 'Polygon', coordinates: [at(sq(0, 0, 20, 10))] });
  add('empty-collection', fc([]), { expectError: true });
  add('point-features-only', fc([{ type: 'Feature', properties: {}, geometry: { type: 'Point', coordinates: o } }]), { expectError: true });
  add('many-vertices-circle', fc([poly([at(Array.from({ length: 2001 }, (_, i) => { const a = (2 * Math.PI * (i % 2000)) / 2000; return [15 * Math.cos(a), 15 * Math.sin(a)]; }))])]));
  // Den Haag, transformed: reversed rings, no closing vertex, 3-D, shifted
  const dh = path.join(SHARED, 'footprints_denhaag_lod2/denhaag_tile01_footprints.geojson');
  if (fs.existsSync(dh)) {
    const doc = JSON.parse(fs.readFileSync(dh, 'utf8'));
    const feats = doc.features.slice(0, 60);
    const mapRings = (fn) => feats.map((ft) => ({ ...ft, geometry: ft.geometry && { ...ft.geometry, coordinates: ft.geometry.type === 'Polygon' ? ft.geometry.coordinates.map(fn) : ft.geometry.coordinates.map((p) => p.map(fn)) } }));
    add('denhaag-60', { ...doc, features: feats });
    add('denhaag-reversed-open', { ...doc, features: mapRings((r) => r.slice(0, -1).reverse()) });
    add('denhaag-3d', { ...doc, features: mapRings((r) => r.map(([x, y]) => [x, y, 0.7])) });
    add('denhaag-properties-stripped', { ...doc, features: feats.map((ft) => ({ ...ft, properties: {} })) });
  }
  heldoutShapes(add, fc, poly, sq);
  const cj = path.join(SHARED, 'footprints_denhaag_lod2/DenHaag_01.city.json');
  if (fs.existsSync(cj)) out.push({ family: 'footprints', variant: 'cityjson-denhaag', ext: 'city.json', copy: cj });
  return out;
}

// Shapes of round 2: holes touching the outer ring, courtyards, spikes and 1e-7 m runs,
// repeated vertices, 1 mm edges, L/U/T/H turned by odd angles at UTM and web-mercator
// offsets, MultiPolygons with touching parts. Each carries `polys` (its polygons as meant:
// rings without the closing corner, outer first, relative to `origin`) and `height`, which
// sweep.js checks the output against (base area, roof bounds, CGAL's skeleton for hip).
const ringArea = (r) => r.reduce((a, p, i) => { const q = r[(i + 1) % r.length]; return a + p[0] * q[1] - q[0] * p[1]; }, 0) / 2;
const ccw = (r) => (ringArea(r) > 0 ? r : r.slice().reverse());
const turn = (r, deg) => { const a = deg * Math.PI / 180, c = Math.cos(a), s = Math.sin(a); return r.map(([x, y]) => [c * x - s * y, s * x + c * y]); };
const close = (r) => [...r, r[0]];
export const SHAPES = {
  L: [[0, 0], [20, 0], [20, 8], [8, 8], [8, 18], [0, 18]],
  U: [[0, 0], [24, 0], [24, 16], [17, 16], [17, 6], [7, 6], [7, 16], [0, 16]],
  T: [[0, 0], [8, 0], [8, 10], [16, 10], [16, 16], [-8, 16], [-8, 10], [0, 10]],
  H: [[0, 0], [6, 0], [6, 7], [14, 7], [14, 0], [20, 0], [20, 20], [14, 20], [14, 13], [6, 13], [6, 20], [0, 20]],
};
function heldoutShapes(add, fc, poly, sq) {
  const open = (r) => r.slice(0, -1);
  // polys: [[outer, ...holes]] in local metres; coordinates written at `origin` + local
  const shape = (variant, polys, origin, { write, multi, height = 9 } = {}) => {
    const at = (r) => close(r.map(([x, y]) => [x + origin[0], y + origin[1]]));
    const rings = (p) => p.map((r, k) => at(k ? ccw(r).reverse() : ccw(r)));
    const doc = write ? write(at) : multi ? fc([{ type: 'Feature', properties: { height }, geometry: { type: 'MultiPolygon', coordinates: polys.map(rings) } }])
      : fc(polys.map((p) => poly(rings(p), { height })));
    add(variant, doc, { polys: polys.map((p) => p.map(ccw).map((r, k) => (k ? r.slice().reverse() : r))), origin, height });
  };
  const rd = [85000, 445000], utm = [500000, 5.8e6], merc = [2e7, 2e7 * 0.33];
  const O = open(sq(0, 0, 30, 30));
  // a hole whose corner is an outer corner, and one whose corner lies on an outer edge
  shape('hole-touches-outer-corner', [[O, [[0, 0], [10, 4], [4, 10]]]], rd);
  shape('hole-touches-outer-edge', [[O, [[15, 0], [20, 6], [10, 6]]]], rd);
  shape('two-holes-touching-each-other', [[O, [[5, 5], [15, 5], [15, 15], [5, 15]], [[15, 15], [25, 15], [25, 25], [15, 25]]]], rd);
  const yard = [];
  for (let i = 0; i < 4; i++) for (let j = 0; j < 4; j++) yard.push(open(sq(4 + 14 * i, 4 + 14 * j, 8, 8)));
  shape('courtyards-16', [[open(sq(0, 0, 60, 60)), ...yard]], rd);
  shape('courtyards-16-utm', [[open(sq(0, 0, 60, 60)), ...yard]], utm);
  // a spike out and back (no area: cleaned), and one 1e-7 m wide
  const spike = (w) => [[0, 0], [20, 0], [20, 10], [10 + w, 10], [10, 25], [10 - w, 10], [0, 10]];
  shape('spike-out-zero-width', [[spike(0)]], rd, { write: (at) => fc([poly([at(spike(0))])]) });
  shape('spike-1e-7-wide', [[spike(1e-7)]], rd);
  // a front edge of 200 corners, each 1e-7 m off the line
  const run = [[0, 0], ...Array.from({ length: 199 }, (_, i) => [0.1 * (i + 1), (i % 2 ? 1 : -1) * 1e-7]), [20, 0], [20, 10], [0, 10]];
  shape('nearly-collinear-1e-7', [[run]], rd);
  shape('nearly-collinear-1e-7-utm', [[run]], utm);
  const dup = [[0, 0], [0, 0], [20, 0], [20, 0], [20, 0], [20, 10], [0, 10], [0, 10]];
  shape('duplicate-vertices', [[open(sq(0, 0, 20, 10))]], rd, { write: (at) => fc([poly([at(dup)])]) });
  shape('closing-vertex-repeated', [[open(sq(0, 0, 20, 10))]], rd, { write: (at) => { const r = at(open(sq(0, 0, 20, 10))); return fc([poly([[...r, r[0], r[0]]])]); } });
  // outer clockwise with a counter-clockwise hole: both reversed
  shape('cw-outer-ccw-hole', [[O, open(sq(10, 10, 10, 10))]], rd, { write: (at) => fc([poly([at(O).reverse(), at(open(sq(10, 10, 10, 10)))])]) });
  // 1 mm edges next to 40 m ones: a chamfered corner and a 1 mm jog
  shape('chamfer-1mm', [[[[0, 0], [39.999, 0], [40, 0.001], [40, 12], [0, 12]]]], rd);
  shape('jog-1mm', [[[[0, 0], [40, 0], [40, 12], [20, 12], [20, 12.001], [0, 12.001]]]], rd);
  for (const [name, deg, o] of [['L', 17, rd], ['U', 33.3, rd], ['T', 71, utm], ['H', 123.4, utm], ['L', 201, merc], ['H', 299.9, merc]])
    shape(`${name}-rot${deg}-${o === rd ? 'rd' : o === utm ? 'utm' : 'mercator'}`, [[turn(SHAPES[name], deg)]], o);
  shape('U-rot33-cw', [[turn(SHAPES.U, 33)]], rd, { write: (at) => fc([poly([at(turn(SHAPES.U, 33)).reverse()])]) });
  // MultiPolygons: parts meeting at a corner, sharing a whole edge, sharing part of an edge
  shape('multipolygon-corner-touch', [[open(sq(0, 0, 10, 10))], [open(sq(10, 10, 10, 10))]], rd, { multi: true });
  shape('multipolygon-shared-edge', [[open(sq(0, 0, 20, 10))]], rd, { write: (at) => fc([{ type: 'Feature', properties: { height: 9 }, geometry: { type: 'MultiPolygon', coordinates: [[at(open(sq(0, 0, 10, 10)))], [at(open(sq(10, 0, 10, 10)))]] } }]) });
  shape('multipolygon-partial-edge', [[[[0, 0], [10, 0], [10, 2], [18, 2], [18, 8], [10, 8], [10, 10], [0, 10]]]], rd, { write: (at) => fc([{ type: 'Feature', properties: { height: 9 }, geometry: { type: 'MultiPolygon', coordinates: [[at(open(sq(0, 0, 10, 10)))], [at(open(sq(10, 2, 8, 6)))]] } }]) });
  shape('features-corner-touch-utm', [[turn(SHAPES.L, 17)], [turn(SHAPES.L, 17).map(([x, y]) => [-x, -y])]], utm);
}

// --- plans: per-edge profiles, dormers, chimneys (archgram extrude --plan) ------------------
// Each carries `polys` as footprints do (corners of loop 0 and holes at z = 0) and `rise`:
// how far above the footprint its profiles can take the roof.
export function planVariants() {
  const out = [];
  const add = (variant, plan, extra) => out.push({ family: 'plan', variant, ext: 'json', data: JSON.stringify(plan), ...extra });
  const profiles = {
    steep: { points: [[0, 0], [0, 6], [1, 8]] },
    wall: [[0, 0], [0, 6]],
    overhang: [[0, 0], [0, 6], [-0.5, 6.2], [3, 9.7]],
    lean: [[0, 0], [0, 6], [-0.6, 7], [2, 9]],
    dormer: [[0, 0], [0, 1.5], [1, 2.5]],
    chimney: [[0, 0], [0, 3]],
  };
  const withOrigin = (pts, o) => pts.map(([x, y]) => [x + o[0], y + o[1]]);
  const P = (variant, loops, edgeProfiles, o, extra = {}) => {
    const plan = { profiles, default_profile: 'steep', loops: loops.map((r, k) => (k === 0 ? { points: withOrigin(r, o), profiles: edgeProfiles } : withOrigin(r, o))), ...extra };
    add(variant, plan, { polys: [loops], origin: o, rise: 10 + (extra.steps ? 3 : 0) });
  };
  const box = [[0, 0], [12, 0], [12, 8], [0, 8]];
  P('box-steep-wall-overhang', [box], ['steep', 'wall', 'overhang', 'wall'], [0, 0]);
  P('box-lean-all', [box], ['lean', 'lean', 'lean', 'lean'], [0, 0]);
  P('L-rot17-mixed-utm', [ccw(turn(SHAPES.L, 17))], ['steep', 'overhang', 'wall', 'lean', 'steep', 'overhang'], [500000, 5.8e6]);
  P('U-mixed', [ccw(SHAPES.U)], ['overhang', 'steep', 'wall', 'steep', 'lean', 'steep', 'wall', 'steep'], [0, 0]);
  P('H-overhang-all-mercator', [ccw(turn(SHAPES.H, 123.4))], Array(12).fill('overhang'), [2e7, 6.6e6]);
  P('courtyard-overhang', [[[0, 0], [30, 0], [30, 30], [0, 30]], [[10, 10], [10, 20], [20, 20], [20, 10]]], ['overhang', 'steep', 'overhang', 'steep'], [85000, 445000]);
  P('box-dormers', [box], ['steep', 'wall', 'steep', 'wall'], [0, 0], {
    steps: [{ name: 'd1', edge: 0, relative: 0.3, height: 6.8, width: 2, depth: 1, profile: 'dormer' },
      { name: 'd2', edge: 0, relative: 0.7, height: 6.8, width: 2, depth: 1, profile: 'dormer' }] });
  P('box-chimney-forced', [box], ['steep', 'wall', 'steep', 'wall'], [85000, 445000], {
    steps: [{ name: 'c', edge: 2, relative: 0.6, height: 7, profile: 'chimney', points: [[-0.4, -0.6], [0.4, -0.6], [0.4, 0.3], [-0.4, 0.3]] }] });
  P('box-offset-event-gables', [box], ['steep', 'wall', 'steep', 'wall'], [0, 0], {
    offsets: [{ height: 6, outside: 0.4, edges: [{ edge: 1, disabled: true }, { edge: 3, disabled: true }] }] });
  // two parts meeting corner to corner across a 0.5 m gap, both with a 0.5 m soffit: the
  // soffits run into each other head-on (the MultiPolygon with corner-touching parts under
  // a style with soffits falls back for the same reason)
  out.push({ family: 'plan', variant: 'diagonal-parts-soffits-collide', ext: 'json', polys: [[box.map(([x, y]) => [x * 10 / 12, y * 10 / 8])], [[[10.5, 10.5], [20, 10.5], [20, 20], [10.5, 20]]]], origin: [0, 0], rise: 10,
    data: JSON.stringify({ profiles: { o: [[0, 0], [0, 9], [-0.5, 9], [2.5, 12]] }, default_profile: 'o', loops: [[[0, 0], [10, 0], [10, 10], [0, 10]], [[10.5, 10.5], [20, 10.5], [20, 20], [10.5, 20]]] }) });
  return out;
}

// --- point clouds -----------------------------------------------------------------------------
// A building's surface sampled: four walls, a flat roof, windows recessed 0.2 m (holes in the
// front wall with a back plane), and ground points around it.
export function cloudPoints({ ground = true, building = true, seed = 3, step = 0.25, windows = true } = {}) {
  const r = rng(seed), P = [];
  const j = () => (r() - 0.5) * 0.01;
  const inWindow = (x, z) => { if (!windows) return false; for (let c = 0; c < 4; c++) for (let k = 0; k < 3; k++) { const x0 = 2 + c * 4.5, z0 = 1 + k * 2.8; if (x > x0 && x < x0 + 1.5 && z > z0 && z < z0 + 1.6) return true; } return false; };
  if (building) {
    for (let x = 0; x <= 20; x += step) for (let z = 0; z <= 9; z += step) {
      if (inWindow(x, z)) P.push([x + j(), 0.2 + j(), z + j(), 6]); else P.push([x + j(), j(), z + j(), 6]);
      P.push([x + j(), 10 + j(), z + j(), 6]);
    }
    for (let y = step; y < 10; y += step) for (let z = 0; z <= 9; z += step) { P.push([j(), y + j(), z + j(), 6]); P.push([20 + j(), y + j(), z + j(), 6]); }
    for (let x = 0; x <= 20; x += step) for (let y = 0; y <= 10; y += step) P.push([x + j(), y + j(), 9 + j(), 6]);
  }
  if (ground) for (let x = -10; x <= 30; x += step * 2) for (let y = -10; y <= 20; y += step * 2) if (!(x >= 0 && x <= 20 && y >= 0 && y <= 10)) P.push([x + j(), y + j(), j(), 2]);
  return P;
}

// LAS 1.2/1.3/1.4 writer, point formats 0-3 and 6-8
export function las(points, { minor = 2, format = 0, scale = 0.001, offset = [0, 0, 0] } = {}) {
  const sizes = { 0: 20, 1: 28, 2: 26, 3: 34, 6: 30, 7: 36, 8: 38 };
  const rec = sizes[format];
  const hsize = minor >= 4 ? 375 : minor === 3 ? 235 : 227;
  const h = Buffer.alloc(hsize);
  h.write('LASF', 0); h[24] = 1; h[25] = minor;
  h.write('other tool', 26);
  h.writeUInt16LE(hsize, 94); h.writeUInt32LE(hsize, 96); h.writeUInt32LE(0, 100);
  h[104] = format; h.writeUInt16LE(rec, 105);
  const n = points.length;
  if (format < 6) h.writeUInt32LE(n, 107);
  for (let k = 0; k < 3; k++) { h.writeDoubleLE(scale, 131 + 8 * k); h.writeDoubleLE(offset[k], 155 + 8 * k); }
  const lo = [0, 1, 2].map((k) => Math.min(...points.map((p) => p[k]))), hi = [0, 1, 2].map((k) => Math.max(...points.map((p) => p[k])));
  h.writeDoubleLE(hi[0], 179); h.writeDoubleLE(lo[0], 187); h.writeDoubleLE(hi[1], 195); h.writeDoubleLE(lo[1], 203); h.writeDoubleLE(hi[2], 211); h.writeDoubleLE(lo[2], 219);
  if (minor >= 4) h.writeBigUInt64LE(BigInt(n), 247);
  const body = Buffer.alloc(rec * n);
  points.forEach((p, i) => {
    const o = i * rec;
    for (let k = 0; k < 3; k++) body.writeInt32LE(Math.round((p[k] - offset[k]) / scale), o + 4 * k);
    body.writeUInt16LE(100, o + 12);
    if (format < 6) { body[o + 14] = 0x09; body[o + 15] = p[3] ?? 1; }
    else { body[o + 14] = 0x11; body[o + 15] = 0; body[o + 16] = p[3] ?? 1; }
    if (format === 1 || format === 3) body.writeDoubleLE(i * 1e-3, o + 20);
    if (format >= 6) body.writeDoubleLE(i * 1e-3, o + 22);
    if (format === 2) body.writeUInt16LE(40000, o + 20);
    if (format === 3) body.writeUInt16LE(40000, o + 28);
    if (format === 7 || format === 8) body.writeUInt16LE(40000, o + 30);
  });
  return Buffer.concat([h, body]);
}

export function cloudVariants() {
  const out = [];
  const add = (variant, ext, data, extra = {}) => out.push({ family: 'cloud', variant, ext, data, ...extra });
  const P = cloudPoints();
  const utm = [85000, 445000, 0];
  const shifted = P.map(([x, y, z, c]) => [x + utm[0], y + utm[1], z, c]);
  for (const [minor, format] of [[2, 0], [2, 1], [2, 2], [2, 3], [3, 1], [4, 6], [4, 7], [4, 8]])
    add(`las1.${minor}-pf${format}-rd`, 'las', las(shifted, { minor, format, offset: [85000, 445000, 0] }), { points: P.length });
  add('las-scale-1e-7-offset-0', 'las', las(P, { scale: 1e-7 }), { points: P.length });
  add('las-scale-0.01-no-offset-rd', 'las', las(shifted, { scale: 0.01 }), { points: P.length });
  add('las-only-ground', 'las', las(cloudPoints({ building: false }), {}), {});
  add('las-rotated-40', 'las', las(P.map(([x, y, z, c]) => { const a = 0.7; return [Math.cos(a) * x - Math.sin(a) * y, Math.sin(a) * x + Math.cos(a) * y, z, c]; }), {}), {});
  const B = P.filter((p) => p[3] === 6);
  const ply = (pts, normals) => {
    const L = ['ply', 'format ascii 1.0', `element vertex ${pts.length}`, 'property double x', 'property double y', 'property double z'];
    if (normals) L.push('property float nx', 'property float ny', 'property float nz');
    L.push('property uchar classification', 'end_header');
    for (const p of pts) L.push([p[0].toFixed(4), p[1].toFixed(4), p[2].toFixed(4), ...(normals ? ['0', '0', '1'] : []), p[3]].join(' '));
    return L.join('\n') + '\n';
  };
  add('ply-cloud-no-normals', 'ply', ply(B, false), {});
  add('ply-cloud-normals-rd', 'ply', ply(B.map(([x, y, z, c]) => [x + utm[0], y + utm[1], z, c]), true), {});
  add('xyz-text', 'xyz', B.map((p) => p.slice(0, 3).map((x) => x.toFixed(3)).join(' ')).join('\n') + '\n', {});
  add('xyz-comma-header', 'xyz', '//X,Y,Z\n' + B.map((p) => p.slice(0, 3).map((x) => x.toFixed(3)).join(',')).join('\r\n') + '\r\n', {});
  add('ply-cloud-single-point', 'ply', ply([[1, 2, 3, 6]], false), {});
  add('ply-cloud-all-same-point', 'ply', ply(Array.from({ length: 500 }, () => [1, 2, 3, 6]), false), {});
  add('ply-cloud-collinear', 'ply', ply(Array.from({ length: 500 }, (_, i) => [i * 0.05, 0, 0, 6]), false), {});
  add('las-empty', 'las', las([[0, 0, 0, 2]], {}).subarray(0, 227), { expectError: true });
  cloudRound2(add, P, ply);
  return out;
}

// the box around points as a LAS file stores them (each coordinate on its scale's grid)
const lasBox = (pts, scale = 0.001, off = [0, 0, 0]) => {
  const q = pts.map((p) => [0, 1, 2].map((k) => Math.round((p[k] - off[k]) / scale) * scale + off[k]));
  return [[0, 1, 2].map((k) => Math.min(...q.map((p) => p[k]))), [0, 1, 2].map((k) => Math.max(...q.map((p) => p[k])))];
};
// Clouds of round 2: every LAS version with every point format it defines (0-3 in all,
// 6-8 in 1.4), formats it must refuse, extreme scales and offsets, shuffled, duplicated,
// turned and noisy clouds, binary PLY with doubles and extra properties, and a plain box
// building whose planes are known (four walls, the roof, the ground: 6). Each carries the
// facts sweep.js checks: `points`, `bbox` ([min, max] as stored), `planes`, or `refuse`
// (a pattern the refusal must match).
function cloudRound2(add, P, ply) {
  const rd = [85000, 445000, 0];
  const at = (pts, o) => pts.map(([x, y, z, c]) => [x + o[0], y + o[1], z + o[2], c]);
  const S = at(P, rd);
  for (const [minor, format] of [[2, 0], [3, 0], [3, 2], [3, 3], [4, 0], [4, 1], [4, 2], [4, 3]])
    add(`las1.${minor}-pf${format}-box-check`, 'las', las(S, { minor, format, offset: rd }), { points: P.length, bbox: lasBox(S, 0.001, rd) });
  const small = at(P.slice(0, 200), rd);
  const patch = (buf, f) => { const b = Buffer.from(buf); f(b); return b; };
  add('las-pf11-undefined', 'las', patch(las(small, { minor: 4, format: 6, offset: rd }), (b) => { b[104] = 11; }), { expectError: true, refuse: 'point format 11' });
  add('las-laz-bit-no-vlr', 'las', patch(las(small, { format: 1, offset: rd }), (b) => { b[104] = 0x81; }), { expectError: true, refuse: 'LAZ|LASzip' });
  add('las-record-too-short', 'las', patch(las(small, { format: 3, offset: rd }), (b) => { b.writeUInt16LE(20, 105); }), { expectError: true, refuse: 'record' });
  add('las-version-2.0', 'las', patch(las(small, { format: 0, offset: rd }), (b) => { b[24] = 2; b[25] = 0; }), { expectError: true, refuse: 'version|2\\.0' });
  add('las-count-beyond-file', 'las', patch(las(small, { format: 0, offset: rd }), (b) => { b.writeUInt32LE(1e9, 107); }), { expectError: true, refuse: 'point|record|bytes' });
  const far = at(P, [1e9, -1e9, 1000]);
  add('las-offset-1e9', 'las', las(far, { offset: [1e9, -1e9, 1000] }), { points: P.length, bbox: lasBox(far, 0.001, [1e9, -1e9, 1000]) });
  add('las-scale-1-utm', 'las', las(at(P, [500000, 5.8e6, 0]), { scale: 1, offset: [500000, 5.8e6, 0] }), { points: P.length, bbox: lasBox(at(P, [500000, 5.8e6, 0]), 1, [500000, 5.8e6, 0]) });
  add('las-scale-1e-4-utm', 'las', las(at(P, [500000, 5.8e6, 0]), { scale: 1e-4, offset: [500000, 5.8e6, 0] }), { points: P.length, bbox: lasBox(at(P, [500000, 5.8e6, 0]), 1e-4, [500000, 5.8e6, 0]) });
  const r = rng(17);
  const shuffled = shuffle(S, r);
  add('las-shuffled-rd', 'las', las(shuffled, { offset: rd }), { points: P.length, bbox: lasBox(S, 0.001, rd) });
  const dup = [...S, ...S];
  add('las-duplicated-rd', 'las', las(dup, { offset: rd, format: 1 }), { points: dup.length, bbox: lasBox(S, 0.001, rd) });
  const a = 23 * Math.PI / 180;
  const turned = at(P.map(([x, y, z, c]) => [Math.cos(a) * x - Math.sin(a) * y, Math.sin(a) * x + Math.cos(a) * y, z, c]), rd);
  add('las-rotated-23-rd', 'las', las(turned, { offset: rd, minor: 4, format: 6 }), { points: P.length, bbox: lasBox(turned, 0.001, rd) });
  // 2 % noise in a 60 m box, and five outliers a kilometre off (a bird, a multipath return)
  const noisy = [...S, ...Array.from({ length: Math.round(P.length * 0.02) }, () => [rd[0] - 20 + 60 * r(), rd[1] - 20 + 50 * r(), 30 * r(), 1]),
    ...Array.from({ length: 5 }, (_, i) => [rd[0] + 1000 + i, rd[1] - 1000, 300 + i, 7])];
  add('las-noise-outliers-rd', 'las', las(noisy, { offset: rd }), { points: noisy.length, bbox: lasBox(noisy, 0.001, rd) });
  const G = cloudPoints({ building: false });
  add('las1.4-pf7-only-ground-rd', 'las', las(at(G, rd), { minor: 4, format: 7, offset: rd }), { points: G.length, bbox: lasBox(at(G, rd), 0.001, rd) });
  // a box building (no windows) on its ground: exactly six planes
  const box = cloudPoints({ windows: false });
  add('las-box-6-planes', 'las', las(at(box, rd), { offset: rd }), { points: box.length, bbox: lasBox(at(box, rd), 0.001, rd), planes: 6 });
  add('las-box-6-planes-duplicated', 'las', las(at([...box, ...box], rd), { offset: rd }), { points: 2 * box.length, bbox: lasBox(at(box, rd), 0.001, rd), planes: 6 });
  add('las-box-6-planes-rot23', 'las', las(box.map(([x, y, z, c]) => [Math.cos(a) * x - Math.sin(a) * y, Math.sin(a) * x + Math.cos(a) * y, z, c]), {}), { points: box.length, planes: 6 });
  // binary PLY: doubles at UTM with extra per-point properties, and big-endian floats
  const plyBinary = (pts, { le = true, dbl = true } = {}) => {
    const h = ['ply', `format binary_${le ? 'little' : 'big'}_endian 1.0`, 'comment from a scanner', `element vertex ${pts.length}`,
      ...['x', 'y', 'z'].map((c) => `property ${dbl ? 'double' : 'float'} ${c}`), 'property ushort intensity', 'property uchar return_number', 'property double gps_time', 'property uchar classification', 'end_header'];
    const cs = dbl ? 8 : 4, rec = 3 * cs + 2 + 1 + 8 + 1;
    const b = Buffer.alloc(rec * pts.length);
    pts.forEach((p, i) => {
      let o = i * rec;
      for (let k = 0; k < 3; k++, o += cs) dbl ? (le ? b.writeDoubleLE(p[k], o) : b.writeDoubleBE(p[k], o)) : (le ? b.writeFloatLE(p[k], o) : b.writeFloatBE(p[k], o));
      le ? b.writeUInt16LE(1234, o) : b.writeUInt16BE(1234, o); b[o + 2] = 1;
      le ? b.writeDoubleLE(i * 1e-3, o + 3) : b.writeDoubleBE(i * 1e-3, o + 3); b[o + 11] = p[3];
    });
    return Buffer.concat([Buffer.from(h.join('\n') + '\n'), b]);
  };
  const box3 = (pts) => [[0, 1, 2].map((k) => Math.min(...pts.map((p) => p[k]))), [0, 1, 2].map((k) => Math.max(...pts.map((p) => p[k])))];
  const U = at(P, [500000, 5.8e6, 0]);
  add('ply-binary-double-utm-extra', 'ply', plyBinary(U), { points: U.length, bbox: box3(U) });
  const F = P.map((p) => p.map(Math.fround));
  add('ply-binary-be-float-extra', 'ply', plyBinary(F, { le: false, dbl: false }), { points: F.length, bbox: box3(F) });
}

export function allVariants() {
  return [...meshVariants(), ...footprintVariants(), ...planVariants(), ...cloudVariants()];
}

if (process.argv[1] && path.resolve(process.argv[1]) === fileURLToPath(import.meta.url)) {
  const dir = process.argv[2];
  if (!dir) { console.error('usage: node tests/heldout/generate.js DIR'); process.exit(2); }
  fs.mkdirSync(dir, { recursive: true });
  const manifest = [];
  for (const v of allVariants()) {
    const file = path.join(dir, `${v.family}-${v.variant}.${v.ext}`);
    if (v.copy) fs.copyFileSync(v.copy, file); else fs.writeFileSync(file, v.data);
    const m = v.base ? measure(v.base.v, v.base.f) : null;
    manifest.push({ family: v.family, variant: v.variant, file, expectError: !!v.expectError, scale: v.scale || 1, dupArea: !!v.dupArea, points: v.points,
      area: m && m.area, extent: m && m.extent, polys: v.polys, origin: v.origin, height: v.height, rise: v.rise,
      bbox: v.bbox, planes: v.planes, refuse: v.refuse });
  }
  fs.writeFileSync(path.join(dir, 'manifest.json'), JSON.stringify(manifest, null, 1));
  console.log(`${manifest.length} inputs in ${dir}`);
}
