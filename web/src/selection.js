// What the person has selected in the open model: a picked component, one split-tree node, or
// several nodes (Shift+click) with all the components under them. The editor owns one
// Selection; every change is announced once through the editor's selectionChanged signal.
//
// The value is null or {component, group, node?, nodes?, components?}:
//   component  the picked mesh component (null for a node picked in the tree)
//   group      the component's group or the node's label
//   node       the split-tree node (the last one of `nodes` when several are selected)
//   nodes      the selected nodes in selection order, when more than one
//   components every component those nodes cover, when nodes were selected
export class Selection {
  // tree(): the open model's SplitTree (or null); changed: the signal to announce with.
  constructor(tree, changed) {
    this.tree = tree;
    this.changed = changed;
    this.value = null;
  }

  // A pick; a picked component also selects its split-tree node once the model has a tree.
  set(selection) {
    let sel = selection;
    const tree = this.tree();
    if (sel && sel.node == null && tree && typeof sel.component === 'number') {
      const node = tree.nodeOfComponent(sel.component);
      if (node !== null) sel = { ...sel, node };
    }
    const same = keyOf(this.value) === keyOf(sel);
    this.value = sel;
    if (!same) this.changed.dispatch(sel);
  }

  clear() {
    this.set(null);
  }

  // One split-tree node: all components of its visible descendants light up.
  node(id) {
    const tree = this.tree();
    const n = tree?.node(id);
    if (!n) {
      this.clear();
      return;
    }
    this.set({
      node: id,
      component: typeof n.component === 'number' ? n.component : null,
      group: n.label ?? null,
      components: tree.componentsUnder(id),
    });
  }

  // Several split-tree nodes at once (in this order).
  nodes(ids) {
    const tree = this.tree();
    const list = [...new Set(ids)].filter((id) => tree?.node(id));
    if (list.length <= 1) {
      if (list.length) this.node(list[0]);
      else this.clear();
      return;
    }
    const components = [...new Set(list.flatMap((id) => tree.componentsUnder(id)))];
    this.set({ node: list[list.length - 1], nodes: list, component: null, group: null, components });
  }

  // Shift+click: adds the node to the selection, or takes it out.
  toggle(id) {
    const now = this.nodeIds();
    this.nodes(now.includes(id) ? now.filter((n) => n !== id) : [...now, id]);
  }

  // The selected nodes, in selection order.
  nodeIds() {
    const sel = this.value;
    if (!sel) return [];
    if (Array.isArray(sel.nodes)) return sel.nodes;
    return sel.node !== undefined && sel.node !== null ? [sel.node] : [];
  }

  // The one selected node's id, or null (none, or several).
  single() {
    const ids = this.nodeIds();
    return ids.length === 1 ? ids[0] : null;
  }

  // The components the selection covers.
  components() {
    const sel = this.value;
    if (!sel) return [];
    if (Array.isArray(sel.components)) return sel.components;
    return typeof sel.component === 'number' ? [sel.component] : [];
  }

  // A new tree numbers nodes afresh: keep a picked component (its node is looked up again),
  // drop a node pick.
  treeReplaced() {
    const sel = this.value;
    if (!sel) return;
    this.value = null;
    if (typeof sel.component === 'number' && !sel.components) this.set({ component: sel.component, group: sel.group });
    else this.changed.dispatch(null);
  }

  // Forgets the selection without announcing it (a model being opened announces everything).
  reset() {
    this.value = null;
  }
}

function keyOf(sel) {
  if (!sel) return '';
  return `${sel.component ?? ''}|${sel.node ?? ''}|${Array.isArray(sel.components) ? sel.components.join(',') : ''}`;
}
