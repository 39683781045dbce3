// An extruded shell read straight from a model's GLB, checked without the service's own
// verdict: positions from the binary chunk (plus each node's translation), turned back into
// archgram axes (z up), welded, and every edge's triangles counted.
import assert from 'node:assert/strict';
import { parseGlb } from '../integration/harness.js';

const FLOAT = 5126;
const WELD = 1e-4; // metres: corners closer than this are one

// {bounds: {min, max} in archgram axes, triangles, edges: Map(count → edges with that many
// triangles)} of every triangle in the GLB.
export function readShell(buffer) {
  const glb = parseGlb(Buffer.from(buffer));
  assert.equal(glb.magic, 'glTF');
  const { json, bin } = glb;
  const min = [Infinity, Infinity, Infinity];
  const max = [-Infinity, -Infinity, -Infinity];
  const ids = new Map();
  const edges = new Map();
  let triangles = 0;
  const weld = (p) => {
    const key = p.map((v) => Math.round(v / WELD)).join(',');
    if (!ids.has(key)) ids.set(key, ids.size);
    return ids.get(key);
  };
  for (const node of json.nodes || []) {
    if (node.mesh === undefined) continue;
    const t = node.translation || [0, 0, 0];
    for (const prim of json.meshes[node.mesh].primitives) {
      const acc = json.accessors[prim.attributes.POSITION];
      assert.equal(acc.componentType, FLOAT);
      assert.equal(prim.indices, undefined, 'indexed primitives are not expected');
      const view = json.bufferViews[acc.bufferView];
      const base = (view.byteOffset || 0) + (acc.byteOffset || 0);
      const stride = view.byteStride || 12;
      const corner = (i) => {
        const o = base + i * stride;
        const [x, y, z] = [0, 1, 2].map((k) => bin.readFloatLE(o + 4 * k) + t[k]);
        return [x, -z, y]; // glTF is y-up: archgram x = x, y = −z, z = y
      };
      for (let i = 0; i + 2 < acc.count; i += 3) {
        const tri = [corner(i), corner(i + 1), corner(i + 2)];
        for (const p of tri) for (let k = 0; k < 3; k++) {
          min[k] = Math.min(min[k], p[k]);
          max[k] = Math.max(max[k], p[k]);
        }
        const w = tri.map(weld);
        for (let k = 0; k < 3; k++) {
          const [a, b] = [w[k], w[(k + 1) % 3]].sort((u, v) => u - v);
          const key = `${a}-${b}`;
          edges.set(key, (edges.get(key) || 0) + 1);
        }
        triangles++;
      }
    }
  }
  const byCount = new Map();
  for (const n of edges.values()) byCount.set(n, (byCount.get(n) || 0) + 1);
  return { bounds: { min, max }, triangles, edges: byCount };
}

// A closed 2-manifold: every welded edge is shared by exactly two triangles.
export function assertClosed(shell, what) {
  assert.ok(shell.triangles > 0, `${what}: no triangles`);
  const other = [...shell.edges].filter(([n]) => n !== 2);
  assert.deepEqual(other, [], `${what}: edges by number of triangles ${JSON.stringify([...shell.edges])}`);
}

// The shell's bounds are these (archgram axes; omitted members are not checked).
export function assertBounds(shell, want, what, tol = 1e-3) {
  for (const [side, k, v] of [
    ['min', 0, want.x0], ['max', 0, want.x1], ['min', 1, want.y0], ['max', 1, want.y1], ['max', 2, want.top],
  ]) {
    if (v === undefined) continue;
    const got = shell.bounds[side][k];
    assert.ok(Math.abs(got - v) < tol, `${what}: ${side} ${'xyz'[k]} is ${got}, not ${v}`);
  }
}
