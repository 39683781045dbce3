// Building descriptions (schema/plan.md) as the editors change them: pure functions that take
// a description and return a changed copy, so every edit is one new draft.
export const STYLES = ['hip', 'gable', 'mansard', 'overhang', 'flat'];

export const clone = (x) => (x === undefined ? undefined : JSON.parse(JSON.stringify(x)));
export const round3 = (v) => Math.round(v * 1000) / 1000;

// --- loops ----------------------------------------------------------------------------------
// A loop as {points, profiles} whatever form the description used ([[x, y], …] or an object).
export function loopOf(plan, i) {
  const l = plan.loops[i];
  const points = Array.isArray(l) ? l : l.points;
  const fallback = plan.default_profile ?? Object.keys(plan.profiles || {})[0] ?? null;
  const profiles = !Array.isArray(l) && Array.isArray(l.profiles) ? l.profiles : points.map(() => fallback);
  return { points, profiles };
}

// The description with every loop in object form, so edits can change per-edge profiles.
export function normalizePlan(plan) {
  const p = clone(plan);
  p.loops = (p.loops || []).map((_, i) => {
    const { points, profiles } = loopOf(plan, i);
    return { points: clone(points), profiles: profiles.slice() };
  });
  return p;
}

// Edge e of loop l of a normalized description: its corners, direction and outward normal
// (the inside is on the left of every edge).
export function edgeFrame(plan, loop, edge) {
  const pts = plan.loops[loop]?.points;
  const p = pts?.[edge];
  const q = pts?.[(edge + 1) % (pts?.length || 1)];
  if (!p || !q) return null;
  const len = Math.hypot(q[0] - p[0], q[1] - p[1]) || 1;
  const d = [(q[0] - p[0]) / len, (q[1] - p[1]) / len];
  return { p, q, len, d, n: [d[1], -d[0]] };
}

// Where an anchor-like item ({loop, edge, relative | absolute}) lies on its input edge: the
// point, the fraction along the edge and the edge's frame.
export function anchorSpot(plan, a) {
  const f = edgeFrame(plan, a.loop ?? 0, a.edge);
  if (!f) return null;
  const t = typeof a.relative === 'number' ? a.relative : (a.absolute ?? 0) / f.len;
  return { x: f.p[0] + (f.q[0] - f.p[0]) * t, y: f.p[1] + (f.q[1] - f.p[1]) * t, t, frame: f };
}

// Everything in a description that names an edge: anchors, steps, offset-event overrides.
function edgeRefs(plan) {
  return [plan.anchors, plan.steps, ...(plan.offsets || []).map((o) => o.edges)];
}

// A corner inserted after corner `from` of `loop`: the edges past it move up by one.
export function shiftEdges(plan, loop, from, by) {
  for (const list of edgeRefs(plan)) {
    for (const a of list || []) {
      if ((a.loop ?? 0) === loop && typeof a.edge === 'number' && a.edge > from) a.edge += by;
    }
  }
}

// Corner `index` of `loop` removed: edges index-1 and index became one (`merged`).
export function mergeEdges(plan, loop, index, merged) {
  for (const list of edgeRefs(plan)) {
    for (const a of list || []) {
      if ((a.loop ?? 0) !== loop || typeof a.edge !== 'number') continue;
      if (a.edge === index) a.edge = merged;
      else if (a.edge > index) a.edge -= 1;
    }
  }
  // Two overrides of one offset event may now name the same edge: the earlier one stays.
  for (const o of plan.offsets || []) {
    if (!Array.isArray(o.edges)) continue;
    const seen = new Set();
    o.edges = o.edges.filter((e) => {
      const key = `${e.loop ?? 0}:${e.edge}`;
      if (seen.has(key)) return false;
      seen.add(key);
      return true;
    });
  }
}

// --- steps (plan edits) ---------------------------------------------------------------------
export function stepKind(step) {
  return Array.isArray(step?.points) ? 'forced' : 'natural';
}

// A step at a point of an edge. Natural: a `width` × `depth` rectangle grown outwards (depth
// > 0) or cut in (< 0). Forced: a `width` × `depth` rectangle in the anchor's frame, centred
// on the edge, so it stands half outside the active plan (a chimney through the roof edge).
export function makeStep(kind, { loop, edge, relative, height, width, depth, profile, name }) {
  const s = { name, loop, edge, relative: round3(relative), height, profile };
  if (kind === 'forced') {
    const hw = round3(width / 2);
    const hd = round3(Math.abs(depth) / 2);
    s.points = [[-hw, -hd], [hw, -hd], [hw, hd], [-hw, hd]];
  } else {
    s.width = width;
    s.depth = depth;
  }
  return s;
}

// The step's outline in plan coordinates as drawn on the input edge (the step itself is placed
// on the active plan at its height, which lies inside that edge on a sloped roof).
export function stepOutline(plan, step) {
  if (stepKind(step) === 'forced' && typeof step.edge !== 'number') return step.points.map((p) => p.slice());
  const spot = anchorSpot(plan, step);
  if (!spot) return null;
  const { d, n } = spot.frame;
  const at = (u, v) => [spot.x + u * d[0] + v * n[0], spot.y + u * d[1] + v * n[1]];
  if (stepKind(step) === 'forced') return step.points.map(([u, v]) => at(u, v));
  const hw = (step.width || 0) / 2;
  const depth = step.depth || 0;
  return [at(-hw, 0), at(hw, 0), at(hw, depth), at(-hw, depth)];
}

// A forced step's rectangle resized (the points of other polygons are kept as they are).
export function resizeForced(step, width, depth) {
  const hw = round3(width / 2);
  const hd = round3(Math.abs(depth) / 2);
  return { ...step, points: [[-hw, -hd], [hw, -hd], [hw, hd], [-hw, hd]] };
}

// Polygon text "x y, x y, …" ↔ points (either orientation is accepted by the server).
export function pointsText(points) {
  return (points || []).map(([x, y]) => `${x} ${y}`).join(', ');
}

export function parsePoints(text) {
  const pts = String(text).split(',').map((pair) => pair.trim().split(/\s+/).map(Number));
  if (pts.length < 3 || !pts.every((p) => p.length === 2 && p.every(Number.isFinite))) return null;
  return pts;
}

// --- offset events --------------------------------------------------------------------------
// This event's override of an edge, or null.
export function offsetEdge(offset, loop, edge) {
  return (offset?.edges || []).find((e) => (e.loop ?? 0) === loop && e.edge === edge) ?? null;
}

// Disables edge (loop, edge) for offset event i, or enables it again.
export function toggleOffsetEdge(plan, i, loop, edge) {
  const p = clone(plan);
  const o = p.offsets[i];
  const edges = o.edges || [];
  const at = edges.findIndex((e) => (e.loop ?? 0) === loop && e.edge === edge);
  if (at < 0) edges.push({ loop, edge, disabled: true });
  else if (edges[at].disabled) {
    delete edges[at].disabled;
    if (Object.keys(edges[at]).every((k) => k === 'loop' || k === 'edge')) edges.splice(at, 1);
  } else edges[at].disabled = true;
  if (edges.length) o.edges = edges;
  else delete o.edges;
  return p;
}

// --- lists of steps and offsets -------------------------------------------------------------
// A copy of the description with item i of list `key` ('steps' | 'offsets') changed by
// `fields`: undefined or null values are removed; i === list length appends.
export function withItem(plan, key, i, fields) {
  const p = clone(plan);
  const list = p[key] ? p[key] : (p[key] = []);
  const item = { ...(list[i] || {}), ...fields };
  for (const [k, v] of Object.entries(item)) if (v === undefined || v === null) delete item[k];
  list[i] = item;
  return p;
}

export function withoutItem(plan, key, i) {
  const p = clone(plan);
  p[key]?.splice(i, 1);
  if (p[key] && !p[key].length) delete p[key];
  return p;
}

// --- profiles -------------------------------------------------------------------------------
// A profile's points whichever form it is written in.
export function profilePoints(profile) {
  return Array.isArray(profile) ? profile : profile?.points || [];
}

// The profile with new points. Its per-segment priorities follow: by index when the number of
// segments is unchanged (a point dragged), else each new segment takes the priority of the old
// segment at its height (a point inserted or removed, an overhang cut in).
export function withPoints(profile, points) {
  if (Array.isArray(profile)) return points;
  const out = { ...profile, points };
  const seg = profile.segment_priority;
  if (Array.isArray(seg) && points.length - 1 !== seg.length) {
    out.segment_priority = remapSegments(profile.points, seg, points);
  }
  return out;
}

function remapSegments(old, seg, points) {
  const out = [];
  for (let j = 0; j + 1 < points.length; j++) {
    const [a, b] = [points[j], points[j + 1]];
    if (a[1] === b[1]) {
      // a horizontal segment: the old one at that height, if there was one
      const k = old.findIndex((p, i) => i + 1 < old.length && p[1] === a[1] && old[i + 1][1] === a[1]);
      out.push(k >= 0 ? seg[k] ?? null : null);
      continue;
    }
    const mid = (a[1] + b[1]) / 2;
    let k = old.findIndex((p, i) => i + 1 < old.length && p[1] < old[i + 1][1] && p[1] <= mid && mid <= old[i + 1][1]);
    if (k < 0) k = old.length - 2; // above the old last point: its last segment carries on
    out.push(seg[k] ?? null);
  }
  return out;
}

// The profile in object form ({points, tag?, priority?, segment_priority?}).
export function profileObject(profile) {
  return Array.isArray(profile) ? { points: profile.map((p) => p.slice()) } : clone(profile);
}

// The priority tag of the whole profile (0, the default, is left out).
export function withPriority(profile, priority) {
  const p = profileObject(profile);
  if (priority) p.priority = priority;
  else delete p.priority;
  return p;
}

// The priority tag of one segment (null: the profile's); all-null lists are left out.
export function withSegmentPriority(profile, segment, priority) {
  const p = profileObject(profile);
  const n = Math.max(0, p.points.length - 1);
  const seg = Array.isArray(p.segment_priority) && p.segment_priority.length === n ? p.segment_priority.slice() : new Array(n).fill(null);
  seg[segment] = priority;
  if (seg.every((v) => v === null)) delete p.segment_priority;
  else p.segment_priority = seg;
  return p;
}

// The priority that decides for segment i: its own tag, else the profile's, else 0.
export function segmentPriority(profile, i) {
  if (Array.isArray(profile)) return { own: null, value: 0 };
  const own = profile.segment_priority?.[i] ?? null;
  return { own, value: own ?? profile.priority ?? 0 };
}
