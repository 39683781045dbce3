// Point clouds for the tests, written and read here independently of archgram's readers and
// writers: binary PLY (read and written), LAS 1.2 point format 2 and XYZ (written), a box
// building with its planes as ground truth, and the planes-found measure of the scoreboard.
import assert from 'node:assert/strict';
import fs from 'node:fs';

const TYPES = {
  char: ['getInt8', 1], uchar: ['getUint8', 1], short: ['getInt16', 2], ushort: ['getUint16', 2],
  int: ['getInt32', 4], uint: ['getUint32', 4], float: ['getFloat32', 4], double: ['getFloat64', 8],
  int8: ['getInt8', 1], uint8: ['getUint8', 1], int16: ['getInt16', 2], uint16: ['getUint16', 2],
  int32: ['getInt32', 4], uint32: ['getUint32', 4], float32: ['getFloat32', 4], float64: ['getFloat64', 8],
};

// The vertex element of a binary little-endian PLY without lists: { comments, props: {name: [values]} }.
export function readPly(file) {
  return parsePly(fs.readFileSync(file));
}

// The same from the bytes of a PLY (a points.ply answer).
export function parsePly(buf) {
  const end = buf.indexOf('end_header\n');
  const header = buf.toString('latin1', 0, end).split('\n');
  assert.equal(header[0], 'ply');
  assert.match(header[1], /binary_little_endian/);
  let n = 0;
  const props = [];
  const comments = [];
  for (const line of header) {
    const t = line.trim().split(/\s+/);
    if (t[0] === 'element' && t[1] === 'vertex') n = Number(t[2]);
    if (t[0] === 'property') props.push([t[2], t[1]]);
    if (t[0] === 'comment') comments.push(t.slice(1).join(' '));
  }
  const view = new DataView(buf.buffer, buf.byteOffset + end + 11);
  const out = Object.fromEntries(props.map(([name]) => [name, new Array(n)]));
  let at = 0;
  for (let i = 0; i < n; i++) {
    for (const [name, type] of props) {
      const [get, size] = TYPES[type];
      out[name][i] = view[get](at, true);
      at += size;
    }
  }
  return { n, comments, props: out, types: Object.fromEntries(props) };
}

// A binary PLY from columns: [[name, type, values], ...].
export function writePly(file, columns, comments = []) {
  fs.writeFileSync(file, plyBytes(columns, comments));
}

export function plyBytes(columns, comments = []) {
  const n = columns[0][2].length;
  let header = 'ply\nformat binary_little_endian 1.0\n';
  for (const c of comments) header += `comment ${c}\n`;
  header += `element vertex ${n}\n`;
  for (const [name, type] of columns) header += `property ${type} ${name}\n`;
  header += 'end_header\n';
  const row = columns.reduce((s, [, type]) => s + TYPES[type][1], 0);
  const body = new DataView(new ArrayBuffer(row * n));
  let at = 0;
  for (let i = 0; i < n; i++) {
    for (const [, type, values] of columns) {
      const [get, size] = TYPES[type];
      body['set' + get.slice(3)](at, values[i], true);
      at += size;
    }
  }
  return Buffer.concat([Buffer.from(header, 'latin1'), Buffer.from(body.buffer)]);
}

// A deterministic pseudo-random generator (tests must not depend on Math.random).
export function rng(seed) {
  let s = seed >>> 0;
  return () => ((s = (Math.imul(s, 1664525) + 1013904223) >>> 0) / 4294967296);
}

// A 12 x 8 x 6 m box without floor sampled on its 5 faces; `plane` is the face.
export function boxCloud(n, origin = [0, 0, 0]) {
  const r = rng(7);
  const x = [], y = [], z = [], plane = [], cls = [];
  const faces = [
    (u, v) => [u * 12, 0, v * 6], (u, v) => [12, u * 8, v * 6], (u, v) => [u * 12, 8, v * 6],
    (u, v) => [0, u * 8, v * 6], (u, v) => [u * 12, v * 8, 6],
  ];
  for (let i = 0; i < n; i++) {
    const f = i % 5;
    const p = faces[f](r(), r());
    x.push(p[0] + origin[0]); y.push(p[1] + origin[1]); z.push(p[2] + origin[2] + (r() - 0.5) * 0.01);
    plane.push(f); cls.push(6);
  }
  return { x, y, z, plane, cls };
}

export function planesFound(truth, seg) {
  const tsize = new Map(), ssize = new Map(), pair = new Map();
  for (let i = 0; i < truth.length; i++) {
    if (truth[i] >= 0) tsize.set(truth[i], (tsize.get(truth[i]) || 0) + 1);
    if (seg[i] < 0) continue;
    ssize.set(seg[i], (ssize.get(seg[i]) || 0) + 1);
    const k = `${truth[i]}/${seg[i]}`;
    pair.set(k, (pair.get(k) || 0) + 1);
  }
  let found = 0;
  for (const [t, size] of tsize) {
    let best = 0, bs = -1;
    for (const [k, c] of pair) {
      const [tt, s] = k.split('/').map(Number);
      if (tt === t && c > best) { best = c; bs = s; }
    }
    if (bs >= 0 && best >= 0.5 * size && best >= 0.8 * ssize.get(bs)) found++;
  }
  return found;
}

// LAS 1.2, point format 2 (x y z, intensity, classification, rgb) from absolute coordinates at
// a millimetre scale, offset `offset`. cols: {x, y, z, intensity, classification, red, green, blue}.
export function lasBytes(cols, offset = [0, 0, 0], scale = 0.001) {
  const n = cols.x.length;
  const header = Buffer.alloc(227);
  header.write('LASF', 0, 'latin1');
  header[24] = 1;
  header[25] = 2;
  header.write('archgram tests', 26, 'latin1');
  header.writeUInt16LE(227, 94);
  header.writeUInt32LE(227, 96); // point data offset
  header.writeUInt32LE(0, 100); // no VLRs
  header[104] = 2;
  header.writeUInt16LE(26, 105);
  header.writeUInt32LE(n, 107);
  header.writeUInt32LE(n, 111); // points by return: all first returns
  for (let k = 0; k < 3; k++) {
    header.writeDoubleLE(scale, 131 + 8 * k);
    header.writeDoubleLE(offset[k], 155 + 8 * k);
  }
  const axes = [cols.x, cols.y, cols.z];
  const lo = axes.map((a) => a.reduce((m, v) => Math.min(m, v), Infinity));
  const hi = axes.map((a) => a.reduce((m, v) => Math.max(m, v), -Infinity));
  for (let k = 0; k < 3; k++) {
    header.writeDoubleLE(hi[k], 179 + 16 * k);
    header.writeDoubleLE(lo[k], 187 + 16 * k);
  }
  const body = Buffer.alloc(26 * n);
  for (let i = 0; i < n; i++) {
    const at = 26 * i;
    for (let k = 0; k < 3; k++) body.writeInt32LE(Math.round((axes[k][i] - offset[k]) / scale), at + 4 * k);
    body.writeUInt16LE(cols.intensity?.[i] ?? 0, at + 12);
    body[at + 14] = 1 | (1 << 3); // return 1 of 1
    body[at + 15] = cols.classification?.[i] ?? 0;
    body.writeUInt16LE(cols.red?.[i] ?? 0, at + 20);
    body.writeUInt16LE(cols.green?.[i] ?? 0, at + 22);
    body.writeUInt16LE(cols.blue?.[i] ?? 0, at + 24);
  }
  return Buffer.concat([header, body]);
}

// XYZ text: "x y z" a line, with `digits` decimals.
export function xyzBytes(x, y, z, digits = 4) {
  const lines = [];
  for (let i = 0; i < x.length; i++) lines.push(`${x[i].toFixed(digits)} ${y[i].toFixed(digits)} ${z[i].toFixed(digits)}`);
  return Buffer.from(lines.join('\n') + '\n', 'latin1');
}
