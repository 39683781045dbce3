// The client's building-description edits (web/src/plandoc.js) and its op kind list, run in
// node: steps placed on edges of rotated and far-off plans (checked with a point-in-polygon
// test of their own), segment priorities kept in step when points come and go, offset-event
// overrides, edge renumbering, and every edited description valid against
// schema/plan.schema.json.
import assert from 'node:assert/strict';
import { readFileSync } from 'node:fs';
import path from 'node:path';
import { test } from 'node:test';
import Ajv2020 from 'ajv/dist/2020.js';
import { ROOT } from './daemon.js';
import {
  makeStep, mergeEdges, normalizePlan, parsePoints, pointsText, shiftEdges, stepOutline, toggleOffsetEdge,
  withItem, withoutItem, withPoints, withPriority, withSegmentPriority,
} from '../../web/src/plandoc.js';
import { withOverhang } from '../../web/src/profileeditor.js';
import { EXTRUSION, OP, OP_KINDS, REMESHING, SERVER_MADE, STRUCTURAL, UNDOABLE } from '../../web/src/opkinds.js';

const schema = JSON.parse(readFileSync(path.join(ROOT, 'schema', 'plan.schema.json'), 'utf8'));
const validate = new Ajv2020({ allErrors: true, strict: false }).compile(schema);
const assertValid = (plan, what) => assert.ok(validate(plan), `${what}: ${JSON.stringify(validate.errors)}`);

// A w × d rectangle turned by `angle` about its first corner, moved to (ox, oy); counter-
// clockwise, as outer rings are.
function rectangle(w, d, angle, ox, oy) {
  const [c, s] = [Math.cos(angle), Math.sin(angle)];
  return [[0, 0], [w, 0], [w, d], [0, d]].map(([x, y]) => [ox + c * x - s * y, oy + s * x + c * y]);
}

const plan = (points) => normalizePlan({
  profiles: { roof: { points: [[0, 0], [0, 3], [1, 4]], tag: 'tiles' }, wall: [[0, 0], [0, 1]] },
  loops: [{ points, profiles: points.map(() => 'roof') }],
});

// Even-odd point in polygon (an independent check of which side of an edge a step lies on).
function inside([x, y], ring) {
  let odd = false;
  for (let i = 0, j = ring.length - 1; i < ring.length; j = i++) {
    const [xi, yi] = ring[i];
    const [xj, yj] = ring[j];
    if ((yi > y) !== (yj > y) && x < ((xj - xi) * (y - yi)) / (yj - yi) + xi) odd = !odd;
  }
  return odd;
}
const centroid = (pts) => pts.reduce(([a, b], [x, y]) => [a + x / pts.length, b + y / pts.length], [0, 0]);

test('steps on an edge stand outside (or cut inside) the plan, whatever its rotation and offset', () => {
  for (const angle of [0, 0.3, Math.PI / 2, 2.5, -1.1]) {
    for (const [ox, oy] of [[0, 0], [85123.4, 446789.1], [500000, 5700000]]) {
      const p = plan(rectangle(10, 6, angle, ox, oy));
      const ring = p.loops[0].points;
      for (let edge = 0; edge < 4; edge++) {
        const what = `angle ${angle}, origin ${ox}, edge ${edge}`;
        const base = { loop: 0, edge, relative: 0.4, height: 3.5, width: 2, depth: 1.2, profile: 'wall', name: 's' };
        const out = makeStep('natural', base);
        assert.equal(out.points, undefined);
        const bump = stepOutline(p, out);
        assert.ok(!inside(centroid(bump), ring), `${what}: a protrusion drawn inside`);
        const edgeLen = Math.hypot(bump[1][0] - bump[0][0], bump[1][1] - bump[0][1]);
        assert.ok(Math.abs(edgeLen - 2) < 1e-6, `${what}: width ${edgeLen}`);
        const recess = stepOutline(p, makeStep('natural', { ...base, depth: -1.2 }));
        assert.ok(inside(centroid(recess), ring), `${what}: a recess drawn outside`);
        // forced: the square is centred on the edge, so half of it is outside
        const forced = makeStep('forced', { ...base, width: 0.8, depth: 0.8 });
        assert.deepEqual(forced.points, [[-0.4, -0.4], [0.4, -0.4], [0.4, 0.4], [-0.4, 0.4]]);
        assert.equal(forced.width, undefined);
        const sq = stepOutline(p, forced);
        assert.equal(sq.filter((q) => inside(q, ring)).length, 2, `${what}: forced corners inside`);
        const withSteps = withItem(withItem(p, 'steps', 0, out), 'steps', 1, forced);
        assertValid(withSteps, what);
      }
    }
  }
  // A forced step without an edge is in plan coordinates: drawn as it is.
  const free = { name: 'annex', height: 2, profile: 'wall', points: [[12, 0], [14, 0], [14, 2]] };
  assert.deepEqual(stepOutline(plan(rectangle(10, 6, 0, 0, 0)), free), free.points);
});

test('segment priorities follow the points: dragged, inserted, removed, an overhang cut in', () => {
  const roof = { points: [[0, 0], [0, 3], [1, 4]], tag: 'tiles', segment_priority: [1, 2] };
  // dragged: same segments
  assert.deepEqual(withPoints(roof, [[0, 0], [0, 3.5], [1.2, 4.5]]).segment_priority, [1, 2]);
  // a point inserted in segment 1, then in segment 0: both halves keep its tag
  assert.deepEqual(withPoints(roof, [[0, 0], [0, 3], [0.5, 3.5], [1, 4]]).segment_priority, [1, 2, 2]);
  assert.deepEqual(withPoints(roof, [[0, 0], [0, 1.5], [0, 3], [1, 4]]).segment_priority, [1, 1, 2]);
  // the last point removed: the segment below it is gone with it
  assert.deepEqual(withPoints(roof, [[0, 0], [0, 3]]).segment_priority, [1]);
  // an overhang at the eave: a new horizontal segment (untagged) between the two
  const oh = withOverhang(roof.points, 3, 0.5);
  assert.deepEqual(oh, [[0, 0], [0, 3], [-0.5, 3], [0.5, 4]]);
  const cut = withPoints(roof, oh);
  assert.deepEqual(cut.segment_priority, [1, null, 2]);
  assert.equal(cut.tag, 'tiles');
  // array-form profiles stay arrays
  assert.deepEqual(withPoints([[0, 0], [0, 1]], [[0, 0], [0, 2]]), [[0, 0], [0, 2]]);
  for (const p of [roof, cut, withPoints(roof, [[0, 0], [0, 1.5], [0, 3], [1, 4]])]) {
    assert.equal(p.segment_priority.length, p.points.length - 1);
    assertValid({ profiles: { roof: p }, loops: [[[0, 0], [1, 0], [0, 1]]] }, JSON.stringify(p));
  }
});

test('priority tags: set, cleared, per segment', () => {
  const arr = [[0, 0], [0, 3], [1, 4]];
  assert.deepEqual(withPriority(arr, 3), { points: arr, priority: 3 });
  assert.deepEqual(withPriority({ points: arr, tag: 't', priority: 3 }, 0), { points: arr, tag: 't' });
  const one = withSegmentPriority(arr, 1, 5);
  assert.deepEqual(one, { points: arr, segment_priority: [null, 5] });
  assert.deepEqual(withSegmentPriority(one, 0, -2).segment_priority, [-2, 5]);
  assert.deepEqual(withSegmentPriority(one, 1, null), { points: arr });
  // a list of the wrong length (points changed elsewhere) is started afresh
  assert.deepEqual(withSegmentPriority({ points: arr, segment_priority: [1] }, 0, 4).segment_priority, [4, null]);
});

test('offset events: edges left out and put back, renumbered with the plan', () => {
  let p = withItem(plan(rectangle(10, 6, 0, 0, 0)), 'offsets', 0, { height: 3, outside: 0.5 });
  p = toggleOffsetEdge(p, 0, 0, 1);
  p = toggleOffsetEdge(p, 0, 0, 3);
  assert.deepEqual(p.offsets[0].edges, [{ loop: 0, edge: 1, disabled: true }, { loop: 0, edge: 3, disabled: true }]);
  assertValid(p, 'two edges left out');
  // an override with its own distance keeps it when the edge is put back
  p.offsets[0].edges[0].outside = 0.8;
  p = toggleOffsetEdge(p, 0, 0, 1);
  assert.deepEqual(p.offsets[0].edges, [{ loop: 0, edge: 1, outside: 0.8 }, { loop: 0, edge: 3, disabled: true }]);
  p = toggleOffsetEdge(toggleOffsetEdge(p, 0, 0, 3), 0, 0, 1); // 3 back in; 1 out again
  assert.deepEqual(p.offsets[0].edges, [{ loop: 0, edge: 1, outside: 0.8, disabled: true }]);
  p.offsets[0].edges[0] = { loop: 0, edge: 1, disabled: true };
  assert.equal(toggleOffsetEdge(p, 0, 0, 1).offsets[0].edges, undefined);
  assert.deepEqual(withoutItem(p, 'offsets', 0).offsets, undefined);

  // A corner inserted after corner 0, then removed again: every edge reference follows.
  const q = withItem(p, 'steps', 0, makeStep('natural', { loop: 0, edge: 2, relative: 0.5, height: 3.5, width: 2, depth: 1, profile: 'wall', name: 's' }));
  q.anchors = [{ name: 'a', loop: 0, edge: 3, relative: 0.5, height: 1 }];
  q.offsets[0].edges.push({ loop: 0, edge: 2, outside: 1 });
  shiftEdges(q, 0, 0, 1);
  assert.deepEqual([q.steps[0].edge, q.anchors[0].edge, q.offsets[0].edges.map((e) => e.edge)], [3, 4, [2, 3]]);
  // removing corner 3 merges edges 2 and 3: both overrides now name edge 2, the first stays
  mergeEdges(q, 0, 3, 2);
  assert.deepEqual([q.steps[0].edge, q.anchors[0].edge, q.offsets[0].edges], [2, 3, [{ loop: 0, edge: 2, disabled: true }]]);
});

test('forced step corners as text', () => {
  const pts = [[-0.4, -0.4], [0.4, -0.4], [0.4, 0.4]];
  assert.deepEqual(parsePoints(pointsText(pts)), pts);
  assert.deepEqual(parsePoints(' 1 2,3 4 , 5   6 '), [[1, 2], [3, 4], [5, 6]]);
  for (const bad of ['', '1 2, 3 4', '1 2, 3, 5 6', '1 2, 3 x, 5 6', '1 2 3, 4 5, 6 7']) assert.equal(parsePoints(bad), null, bad);
});

test('the op kinds the client sends: one list, and the groups it reacts to', () => {
  const text = readFileSync(path.join(ROOT, 'web', 'src', 'opkinds.js'), 'utf8');
  // the form a unit test of the service reads: one array literal of double-quoted strings
  const m = /export const OP_KINDS = \[((?:"[a-z_]+"(?:, )?)+)\];/.exec(text);
  assert.ok(m, 'OP_KINDS is not one array literal of double-quoted strings');
  assert.deepEqual(JSON.parse(`[${m[1]}]`), OP_KINDS);
  assert.equal(text.split('OP_KINDS = [').length, 2, 'OP_KINDS is declared more than once');
  assert.equal(new Set(OP_KINDS).size, OP_KINDS.length);
  assert.equal(OP.resize, 'resize');
  assert.throws(() => OP.resise, /not an op kind/);
  for (const k of SERVER_MADE) assert.ok(!OP_KINDS.includes(k), `${k} is made by the server only`);
  for (const group of [STRUCTURAL, UNDOABLE, EXTRUSION]) for (const k of group) assert.ok(OP_KINDS.includes(k), k);
  for (const k of REMESHING) assert.ok(OP_KINDS.includes(k) || SERVER_MADE.includes(k), k);
});
