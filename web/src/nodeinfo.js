// What the node under the pointer is (label, rule, box, pattern of its parent), as the
// viewport's tooltip, so the person knows what they are about to select, save or compose into.
import { describeNode, walkParent } from './treewalk.js';

const INTERVAL_MS = 80; // at most this often a ray is cast while the pointer moves

export class NodeInfo {
  constructor(editor, viewport) {
    this.editor = editor;
    this.viewport = viewport;
    this.last = 0;
    this.node = null;
    viewport.canvas.addEventListener('pointermove', (e) => {
      if (e.buttons || Date.now() - this.last < INTERVAL_MS) return;
      this.last = Date.now();
      this.show(e.clientX, e.clientY);
    });
    viewport.canvas.addEventListener('pointerleave', () => this.set(null));
    editor.signals.treeChanged.add(() => this.set(null));
  }

  show(x, y) {
    const tree = this.editor.tree;
    const owner = tree ? this.viewport.layers.model.hit(this.viewport.ray(x, y)) : null;
    this.set(owner ? tree.nodeOfComponent(owner.userData.component) : null);
  }

  set(id) {
    if (id === this.node) return;
    this.node = id;
    const tree = this.editor.tree;
    const n = id !== null && tree ? tree.node(id) : null;
    if (!n) {
      this.viewport.canvas.removeAttribute('title');
      this.viewport.mark('hoverNode', null);
      return;
    }
    // a repeated node: the pattern it is a cell of
    const up = walkParent(tree, id);
    const parent = up !== null ? tree.node(up) : null;
    const within = parent?.kind === 'pattern' ? ` · in ${describeNode(parent)}` : '';
    this.viewport.canvas.title = `${describeNode(n)}${within}`;
    this.viewport.mark('hoverNode', id);
  }
}
