// What the node under the pointer is (label, rule, box, pattern of its parent), as the
// viewport's tooltip, so the person knows what they are about to select, save or compose into.
import { describeNode, walkParent } from './treewalk.js';

const INTERVAL_MS = 80; // at most this often a ray is cast while the pointer moves
// a ray against points tests every one of them: past this many drawn, no tooltip on hover
const HOVER_POINTS_MAX = 300000;

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
    const vp = this.viewport;
    if (!tree) {
      this.set(null);
      return;
    }
    // a derived cloud's points stand for their placements (derivedpoints.js)
    const points = vp.layers.model.points;
    let owner = null;
    if (!points.length) owner = vp.layers.model.hit(vp.ray(x, y));
    else if (typeof points[0].userData.component === 'number' && drawnPoints(points) <= HOVER_POINTS_MAX) owner = vp.hitPoint(x, y)?.points;
    const component = owner?.userData.component;
    this.set(typeof component === 'number' ? tree.nodeOfComponent(component) : null);
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

function drawnPoints(points) {
  let n = 0;
  for (const p of points) n += p.geometry.getAttribute('position').count;
  return n;
}
