// A model's split tree as the server describes it (GET …/tree), indexed for the two questions
// the views ask: which mesh components lie under a node, and which node a component is.
export class SplitTree {
  constructor(json) {
    this.model = json.model;
    this.version = json.version;
    this.root = json.root ?? 0;
    this.nodes = new Map();
    for (const n of json.nodes || []) this.nodes.set(n.id, n);
    this.labels = json.labels || [];
    this.rules = json.rules || [];
    this.colours = new Map(this.labels.map((l) => [l.label, l.color]));
    this.byComponent = new Map();
    for (const n of this.nodes.values()) {
      if (typeof n.component === 'number') this.byComponent.set(n.component, n.id);
    }
  }

  node(id) {
    return this.nodes.get(id) ?? null;
  }

  nodeOfComponent(component) {
    return this.byComponent.get(component) ?? null;
  }

  colourOf(label) {
    return this.colours.get(label) ?? null;
  }

  // The components of a node's visible descendants (itself included), in tree order.
  componentsUnder(id) {
    const out = [];
    const stack = [id];
    while (stack.length) {
      const n = this.nodes.get(stack.pop());
      if (!n) continue;
      if (n.visible && typeof n.component === 'number') out.push(n.component);
      for (let i = (n.children || []).length - 1; i >= 0; i--) stack.push(n.children[i]);
    }
    return out;
  }

  // The node's ancestors, root first (without the node itself).
  ancestors(id) {
    const out = [];
    const seen = new Set();
    for (let n = this.nodes.get(id); n && n.parent !== null && n.parent !== undefined; n = this.nodes.get(n.parent)) {
      if (seen.has(n.parent)) break; // a malformed tree must not loop
      seen.add(n.parent);
      out.unshift(n.parent);
    }
    return out;
  }
}

// A node's one-line title in the tree: kind, then what makes it recognisable.
export function nodeTitle(n) {
  const parts = [n.kind];
  if (n.rule) parts.push(n.rule);
  if (n.pattern?.counts) parts.push(n.pattern.counts.join('×'));
  if (n.terminal) parts.push(n.terminal);
  return parts.join(' ');
}

// Box size in metres, "1.30 × 0.20 × 1.86 m".
export function boxSize(box) {
  if (!Array.isArray(box) || box.length !== 6) return '–';
  return `${[0, 1, 2].map((i) => (box[i + 3] - box[i]).toFixed(2)).join(' × ')} m`;
}
