// The points a proceduralized cloud's grammar derives (GET …/derived.ply), made ready for the
// viewport's model layer: one THREE.Points per placement, marked with the placement as its
// component (the split tree's `component` of the node that placed it), so picking, the
// selection, the drag preview and the resize handles treat placements as a mesh model's
// components. Each point keeps `_segment` (its placement) and `_label` (its terminal) as
// points.glb's points keep theirs, so cloudview.js colours both alike.
//
// Coordinates: the PLY's float positions are relative to its `comment offset X Y Z` line; each
// Points object is placed at that offset, so the scene is in the cloud's coordinates (those of
// the tree's boxes) while the GPU sees small numbers. glTF's axes as everywhere in the view:
// archgram's (x, y, z) is (x, z, -y) of the scene.
//
// The budget: the server sends at most `budget` points (derived.ply?budget=N, every k-th of
// the derivation, placement by placement so each keeps its share); a larger file is thinned
// here the same way.
import * as THREE from 'three';
import { PLYLoader } from 'three/examples/jsm/loaders/PLYLoader.js';

const HEADER_MAX = 64 * 1024; // a PLY header longer than this is not archgram's

// The `comment offset X Y Z` of a PLY header, or [0, 0, 0].
export function plyOffset(buffer) {
  const head = new TextDecoder('latin1').decode(new Uint8Array(buffer, 0, Math.min(buffer.byteLength, HEADER_MAX)));
  const end = head.indexOf('end_header');
  const lines = (end >= 0 ? head.slice(0, end) : head).split(/\r?\n/);
  for (const line of lines) {
    const m = /^comment offset (\S+) (\S+) (\S+)\s*$/.exec(line);
    if (m) {
      const o = m.slice(1, 4).map(Number);
      if (o.every(Number.isFinite)) return o;
    }
  }
  return [0, 0, 0];
}

// A THREE.Group of the derived points of `buffer` (a derived.ply), at most `budget` of them;
// its userData describes what is drawn ({derived, points, shown, budget, offset, segmented,
// segments, labels}) as points.glb's extras do.
export function derivedScene(buffer, budget, model = null) {
  const loader = new PLYLoader();
  loader.setCustomPropertyNameMapping({ _segment: ['segment'], _label: ['label'] });
  const geometry = loader.parse(buffer);
  const offset = plyOffset(buffer);
  const pos = geometry.getAttribute('position');
  const seg = geometry.getAttribute('_segment');
  const lab = geometry.getAttribute('_label');
  const n = pos ? pos.count : 0;
  const root = new THREE.Group();
  root.name = 'derived points';
  if (!n || !seg || !lab) {
    geometry.dispose();
    root.userData = { derived: true, model, points: n, shown: 0, budget, offset, segmented: false, segments: 0, labels: 0 };
    return root;
  }
  const step = Math.max(1, Math.ceil(n / Math.max(1, budget)));
  // count the drawn points per placement, then fill each placement's arrays
  const counts = new Map();
  const labels = new Set();
  for (let i = 0; i < n; i += step) {
    const s = seg.getX(i);
    counts.set(s, (counts.get(s) || 0) + 1);
    labels.add(lab.getX(i));
  }
  const parts = new Map();
  for (const [s, c] of counts) parts.set(s, { at: 0, xyz: new Float32Array(3 * c), seg: new Float32Array(c), lab: new Float32Array(c) });
  let shown = 0;
  for (let i = 0; i < n; i += step) {
    const p = parts.get(seg.getX(i));
    const k = p.at++;
    p.xyz[3 * k] = pos.getX(i);
    p.xyz[3 * k + 1] = pos.getZ(i);
    p.xyz[3 * k + 2] = -pos.getY(i);
    p.seg[k] = seg.getX(i);
    p.lab[k] = lab.getX(i);
    shown++;
  }
  geometry.dispose();
  for (const s of [...parts.keys()].sort((a, b) => a - b)) {
    const p = parts.get(s);
    const g = new THREE.BufferGeometry();
    g.setAttribute('position', new THREE.BufferAttribute(p.xyz, 3));
    g.setAttribute('_segment', new THREE.BufferAttribute(p.seg, 1));
    g.setAttribute('_label', new THREE.BufferAttribute(p.lab, 1));
    const points = new THREE.Points(g, new THREE.PointsMaterial({ size: 3, sizeAttenuation: false }));
    points.position.set(offset[0], offset[2], -offset[1]);
    points.userData.component = s;
    points.userData.label = null;
    root.add(points);
  }
  root.userData = {
    derived: true,
    model,
    points: n,
    shown,
    budget,
    offset,
    segmented: true,
    segments: parts.size,
    labels: labels.size,
  };
  return root;
}
