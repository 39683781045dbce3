// Walking the split tree (web/src/treewalk.js), run in node on generated trees with split
// nodes between the walked ones: the parent is the nearest ancestor that is not a split, the
// children are the walked nodes the child slots lead to, siblings are their neighbours; checked
// against the tree the generator built, independently of the walk's own code.
import assert from 'node:assert/strict';
import { test } from 'node:test';
import { rng } from '../integration/harness.js';
import { SplitTree } from '../../web/src/splittree.js';
import { describeNode, walkChildren, walkParent, walkSibling } from '../../web/src/treewalk.js';

// A random tree of walked nodes; between a node and each of its children a chain of 0 to 3
// split nodes. Returns the served JSON and, per walked node, its walked parent and children.
function generate(seed, count) {
  const r = rng(seed);
  const nodes = [{ id: 0, parent: null, children: [], kind: 'root', box: [0, 0, 0, 1, 1, 1] }];
  const walkedParent = new Map([[0, null]]);
  const walkedKids = new Map([[0, []]]);
  const walked = [0];
  const add = (parent, kind) => {
    const n = { id: nodes.length, parent, children: [], kind, box: [0, 0, 0, 1, 1, 1] };
    nodes.push(n);
    nodes[parent].children.push(n.id);
    return n.id;
  };
  while (walked.length < count) {
    const up = walked[Math.floor(r() * walked.length)];
    let at = up;
    for (let k = Math.floor(r() * 4); k > 0; k--) at = add(at, 'split');
    const id = add(at, r() < 0.2 ? 'pattern' : 'component');
    walked.push(id);
    walkedParent.set(id, up);
    walkedKids.set(id, []);
    walkedKids.get(up).push(id);
  }
  return { tree: new SplitTree({ model: 1, version: 1, root: 0, nodes }), walkedParent, walkedKids, walked };
}

// The walked children in tree order: a depth-first pass from the node, stopping at walked ones.
function expectedChildren(tree, id) {
  const out = [];
  const visit = (c) => {
    const n = tree.node(c);
    if (n.kind === 'split') n.children.forEach(visit);
    else out.push(c);
  };
  tree.node(id).children.forEach(visit);
  return out;
}

test('parent, children and siblings skip split nodes', () => {
  for (let seed = 1; seed <= 25; seed++) {
    const { tree, walkedParent, walkedKids, walked } = generate(seed, 40);
    for (const id of walked) {
      assert.equal(walkParent(tree, id), walkedParent.get(id), `seed ${seed} node ${id}: parent`);
      const kids = walkChildren(tree, id);
      assert.deepEqual(kids, expectedChildren(tree, id), `seed ${seed} node ${id}: children`);
      assert.deepEqual([...kids].sort((a, b) => a - b), [...walkedKids.get(id)].sort((a, b) => a - b));
      for (const k of kids) assert.notEqual(tree.node(k).kind, 'split');
      if (id === 0) {
        assert.equal(walkSibling(tree, id, 1), null);
        continue;
      }
      const kin = expectedChildren(tree, walkedParent.get(id));
      const i = kin.indexOf(id);
      assert.equal(walkSibling(tree, id, -1), i > 0 ? kin[i - 1] : null, `seed ${seed} node ${id}: previous`);
      assert.equal(walkSibling(tree, id, 1), i + 1 < kin.length ? kin[i + 1] : null, `seed ${seed} node ${id}: next`);
    }
  }
});

test('a malformed tree does not loop, and nodes say what they are', () => {
  const tree = new SplitTree({ root: 0, nodes: [
    { id: 0, parent: 1, children: [1], kind: 'split' },
    { id: 1, parent: 0, children: [0], kind: 'split' },
    { id: 2, parent: 0, children: [], kind: 'component', label: 'L3', rule: 'R2', box: [0, 0, 0, 1.2, 0.16, 1.8] },
    { id: 3, parent: null, children: [], kind: 'pattern', rule: 'R1', box: [0, 0, 0, 4, 1, 2], pattern: { counts: [3, 1, 2] } },
  ] });
  assert.equal(walkParent(tree, 2), null);
  assert.deepEqual(walkChildren(tree, 0), []);
  assert.equal(describeNode(tree.node(2)), 'node 2 · component · L3 · rule R2 · 1.20 × 0.16 × 1.80 m');
  assert.equal(describeNode(tree.node(3)), 'node 3 · pattern · rule R1 · 4.00 × 1.00 × 2.00 m · pattern 3×1×2');
});
