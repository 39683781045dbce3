// Walking the split tree from a selection, as the parts library's selection does (paper §4.1;
// server/core/parts/select.h): only visible and pattern nodes are walked, intermediate split
// nodes are skipped — a node's parent is its nearest ancestor that is not a split, its children
// the nodes its child slots lead to. The keys: ↑ parent, ↓ first child, ← / → previous / next
// sibling, on the one selected node, while the person is not typing. Pure functions of a
// SplitTree (splittree.js), so they are tested in node too.
import { isTyping } from './edittools.js';

const walked = (n) => n && n.kind !== 'split' && n.kind !== 'dead';

// The parent (null for the root).
export function walkParent(tree, id) {
  const seen = new Set();
  for (let n = tree.node(id); n && n.parent !== null && n.parent !== undefined; ) {
    if (seen.has(n.parent)) return null; // a malformed tree must not loop
    seen.add(n.parent);
    const p = tree.node(n.parent);
    if (walked(p)) return p.id;
    n = p;
  }
  return null;
}

// The children, in order: through split nodes to the first walked node of each branch.
export function walkChildren(tree, id) {
  const out = [];
  const stack = [...(tree.node(id)?.children || [])].reverse();
  const seen = new Set();
  while (stack.length) {
    const c = stack.pop();
    if (seen.has(c)) continue;
    seen.add(c);
    const n = tree.node(c);
    if (!n) continue;
    if (walked(n)) out.push(c);
    else if (n.kind === 'split') for (let i = (n.children || []).length - 1; i >= 0; i--) stack.push(n.children[i]);
  }
  return out;
}

// The previous (dir −1) or next (dir +1) sibling, null at either end.
export function walkSibling(tree, id, dir) {
  const parent = walkParent(tree, id);
  if (parent === null) return null;
  const kin = walkChildren(tree, parent);
  const i = kin.indexOf(id);
  const j = i + dir;
  return i >= 0 && j >= 0 && j < kin.length ? kin[j] : null;
}

// What a node is, in one line: its kind, label, rule, size and pattern.
export function describeNode(n) {
  if (!n) return '';
  const parts = [`node ${n.id}`, n.kind];
  if (n.label) parts.push(n.label);
  if (n.rule) parts.push(`rule ${n.rule}`);
  if (Array.isArray(n.box) && n.box.length === 6) {
    parts.push(`${[0, 1, 2].map((i) => (n.box[i + 3] - n.box[i]).toFixed(2)).join(' × ')} m`);
  }
  if (n.pattern?.counts) parts.push(`pattern ${n.pattern.counts.join('×')}`);
  return parts.join(' · ');
}

// The walking keys on the editor's selection.
export class TreeWalk {
  constructor(editor) {
    this.editor = editor;
    window.addEventListener('keydown', (e) => this.key(e));
  }

  // parent | child | previous | next from the one selected node; returns the node walked to.
  step(way) {
    const ed = this.editor;
    const tree = ed.tree;
    const id = ed.selected.single();
    if (!tree || id === null) return null;
    const to = way === 'parent' ? walkParent(tree, id)
      : way === 'child' ? walkChildren(tree, id)[0] ?? null
        : walkSibling(tree, id, way === 'previous' ? -1 : 1);
    if (to !== null) ed.selected.node(to);
    return to;
  }

  key(e) {
    if (isTyping(e.target) || e.ctrlKey || e.metaKey || e.altKey) return;
    if (e.target instanceof Element && e.target.closest('[role="tree"]')) return; // the tree's own keys
    const way = { ArrowUp: 'parent', ArrowDown: 'child', ArrowLeft: 'previous', ArrowRight: 'next' }[e.key];
    if (!way || this.editor.selected.single() === null) return;
    e.preventDefault();
    this.step(way);
  }
}
