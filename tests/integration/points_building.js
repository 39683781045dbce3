// A generated point cloud building with known windows, shared by the CLI and service tests of
// point models: a 16 x 8 x 7 m block with 5 x 2 recessed windows in its front at RD New-like
// coordinates, and the windows of a cloud counted geometrically (not by archgram's labels).
import fs from 'node:fs';
import { parsePly, plyBytes, rng } from './clouds.js';

// A 16 x 8 x 7 m block with a flat roof and 5 x 2 recessed windows (1.2 x 1.5 m, glass 0.25 m
// behind the wall) in its front (y = 0), at RD New-like coordinates, as double x y z plus the
// int `window` (-1 for wall and roof). Area-uniform samples, 2 mm noise along the normal.
export const ORIGIN = [85000.5, 446000.25, 1.5];
export const WIN = [];
for (const z0 of [1.0, 4.4]) for (let k = 0; k < 5; k++) WIN.push([1.0 + 3.2 * k, z0]);
export function building(n) {
  const r = rng(5);
  const surfaces = []; // [area, sample(u, v) -> [x, y, z], window]
  const add = (area, f, w = -1) => surfaces.push([area, f, w]);
  add(16 * 7, (u, v) => [u * 16, 0, v * 7], -2); // the front, holes rejected below
  add(16 * 7, (u, v) => [u * 16, 8, v * 7]);
  add(8 * 7, (u, v) => [0, u * 8, v * 7]);
  add(8 * 7, (u, v) => [16, u * 8, v * 7]);
  add(16 * 8, (u, v) => [u * 16, v * 8, 7]);
  WIN.forEach(([x0, z0], w) => {
    add(1.2 * 1.5, (u, v) => [x0 + 1.2 * u, 0.25, z0 + 1.5 * v], w);
    add(0.25 * 1.5, (u, v) => [x0, 0.25 * u, z0 + 1.5 * v], w);
    add(0.25 * 1.5, (u, v) => [x0 + 1.2, 0.25 * u, z0 + 1.5 * v], w);
    add(1.2 * 0.25, (u, v) => [x0 + 1.2 * u, 0.25 * v, z0], w);
    add(1.2 * 0.25, (u, v) => [x0 + 1.2 * u, 0.25 * v, z0 + 1.5], w);
  });
  const total = surfaces.reduce((s, [a]) => s + a, 0);
  const x = [], y = [], z = [], window = [];
  while (x.length < n) {
    let pick = r() * total, s = 0;
    while (pick > surfaces[s][0]) pick -= surfaces[s++][0];
    const [, f, w] = surfaces[s];
    const p = f(r(), r());
    if (w === -2 && WIN.some(([x0, z0]) => p[0] > x0 && p[0] < x0 + 1.2 && p[2] > z0 && p[2] < z0 + 1.5)) continue;
    const e = (r() - 0.5) * 0.004;
    x.push(p[0] + ORIGIN[0] + (p[0] === 0 || p[0] === 16 ? e : 0));
    y.push(p[1] + ORIGIN[1] + (p[1] === 0 || p[1] === 8 || p[1] === 0.25 ? e : 0));
    z.push(p[2] + ORIGIN[2] + (p[2] === 7 ? e : 0));
    window.push(w < 0 ? -1 : w);
  }
  return { x, y, z, window };
}

// Windows in a cloud, found geometrically: glass points (0.15..0.35 m behind the front, off the
// side walls at both ends) binned by 0.2 m in x and z, 4-connected runs of occupied bins counted.
export function countWindows(c) {
  const cells = new Map();
  // the far side wall: the 99.5th percentile of x (a few stray points may lie beyond)
  const xs = Float64Array.from(c.props.x, (v) => v - ORIGIN[0]).sort();
  const xmax = xs[Math.floor(0.995 * (xs.length - 1))];
  for (let i = 0; i < c.n; i++) {
    const y = c.props.y[i] - ORIGIN[1], x = c.props.x[i] - ORIGIN[0], z = c.props.z[i] - ORIGIN[2];
    if (y < 0.15 || y > 0.35 || x < 0.4 || x > xmax - 0.4 || z < 0.3 || z > 6.7) continue;
    const k = `${Math.floor(x / 0.2)},${Math.floor(z / 0.2)}`;
    cells.set(k, (cells.get(k) || 0) + 1);
  }
  const seen = new Set();
  let blobs = 0;
  for (const [k, cnt] of cells) {
    if (cnt < 2 || seen.has(k)) continue;
    let size = 0;
    const stack = [k];
    seen.add(k);
    while (stack.length) {
      const [a, b] = stack.pop().split(',').map(Number);
      size++;
      for (const [da, db] of [[1, 0], [-1, 0], [0, 1], [0, -1]]) {
        const q = `${a + da},${b + db}`;
        if (!seen.has(q) && (cells.get(q) || 0) >= 2) { seen.add(q); stack.push(q); }
      }
    }
    if (size >= 10) blobs++;
  }
  return blobs;
}

export const windowBox = (w, pad = 0.1) => {
  const [x0, z0] = WIN[w];
  return [x0 - pad + ORIGIN[0], -pad + ORIGIN[1], z0 - pad + ORIGIN[2],
    x0 + 1.2 + pad + ORIGIN[0], 0.25 + pad + ORIGIN[1], z0 + 1.5 + pad + ORIGIN[2]].join(',');
};


// The building as a binary PLY of double x y z and the int `window` (-1 for wall and roof).
export function buildingPly(n = 60000) {
  const b = building(n);
  return { b, bytes: plyBytes([['x', 'double', b.x], ['y', 'double', b.y], ['z', 'double', b.z], ['window', 'int', b.window]]) };
}

export function writeBuilding(file, n = 60000) {
  const { b, bytes } = buildingPly(n);
  fs.writeFileSync(file, bytes);
  return b;
}

// The tree node (GET …/tree, boxes in the cloud's coordinates) of window w's glass: its box
// centred on the window, at most a little larger.
export const glassOf = (tree, w) => tree.nodes.find((nd) => nd.kind === 'component' && nd.box &&
  Math.abs((nd.box[0] + nd.box[3]) / 2 - (WIN[w][0] + 0.6 + ORIGIN[0])) < 0.2 &&
  Math.abs((nd.box[2] + nd.box[5]) / 2 - (WIN[w][1] + 0.75 + ORIGIN[2])) < 0.2 &&
  nd.box[3] - nd.box[0] < 2 && nd.box[5] - nd.box[2] < 2.2 && nd.box[4] - ORIGIN[1] < 0.6);

// The front wall's nodes: those in the plane y = 0 at least `minWidth` m wide and 6 m tall.
export const frontsOf = (tree, minWidth = 14) => tree.nodes.filter((nd) => nd.kind === 'component' && nd.box &&
  nd.box[3] - nd.box[0] > minWidth && nd.box[4] - nd.box[1] < 0.6 && Math.abs(nd.box[1] - ORIGIN[1]) < 0.2 &&
  nd.box[5] - nd.box[2] > 6);

// A PLY (a file, or a derived.ply answer) with absolute coordinates (its offset comment added),
// as {n, props}.
export function absolutePly(buf) {
  const c = parsePly(buf);
  const line = c.comments.find((x) => x.startsWith('offset'));
  const o = line ? line.split(' ').slice(1).map(Number) : [0, 0, 0];
  const n = c.props.x.length;
  for (let i = 0; i < n; i++) { c.props.x[i] += o[0]; c.props.y[i] += o[1]; c.props.z[i] += o[2]; }
  return { n, props: c.props };
}
