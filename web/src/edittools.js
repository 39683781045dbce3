// The edit panel: resize mode (global, or local within a region), the split-plane tool, join,
// copy/paste (insert | replace × fill | derive, also from another model), remove. Every edit
// is one op (editor.execute); the op's broadcast reloads mesh, tree and grammar for everyone.
// The tools work on the selected split-tree nodes (Shift+click selects several).
import * as THREE from 'three';
import { isCloud } from './cloud.js';
import { el } from './dom.js';
import { OP } from './opkinds.js';
import { worldBox } from './previewlayer.js';

const AXES = ['x', 'y', 'z'];
const PLANE_COLOUR = 0xff3df2; // magenta: no label or highlight colour uses it

export class EditTools {
  constructor(editor, api, viewport, container) {
    this.editor = editor;
    this.api = api;
    this.viewport = viewport;
    this.mode = 'global';   // resize mode of the handles
    this.region = 'auto';   // local mode: 'auto' (the server's: old ∪ new box) | 'parent' | 'grandparent' | 'model'
    this.clipboard = null;  // {model, version, nodes, name}
    this.plane = null;      // the split plane drawn in the view
    this.splitting = false; // the split-plane tool is open

    const radio = (name, value, text) =>
      el('label.opt', {}, el('input', { type: 'radio', name, value, checked: value === 'global', 'data-testid': `mode-${value}` }), text);
    this.modeBox = el('div.edit-row', {}, el('span.edit-key', {}, 'resize'), radio('resize-mode', 'global', 'global'), radio('resize-mode', 'local', 'local'));
    this.modeBox.addEventListener('change', (e) => {
      if (e.target.name !== 'resize-mode') return;
      this.mode = e.target.value;
      this.render();
    });
    this.regionSel = el(
      'select',
      { 'data-testid': 'region', title: 'Local mode: how far the resize may reach' },
      el('option', { value: 'auto' }, 'region: around the node'),
      el('option', { value: 'parent' }, 'region: parent'),
      el('option', { value: 'grandparent' }, 'region: grandparent'),
      el('option', { value: 'model' }, 'region: whole model'),
    );
    this.regionSel.addEventListener('change', () => {
      this.region = this.regionSel.value;
    });

    // Split plane: an axis and a position along it (metres), drawn while the tool is open.
    this.axisSel = el('select', { 'data-testid': 'split-axis' }, AXES.map((a) => el('option', { value: a }, a)));
    this.atInput = el('input', { type: 'range', min: 0, max: 1, step: 0.001, value: 0.5, 'data-testid': 'split-at' });
    this.atText = el('span.edit-value', { 'data-testid': 'split-at-text' });
    this.splitBtn = el('button', { type: 'button', 'data-testid': 'split' }, 'Split');
    this.toolBtn = button('Split plane', 'split-tool', () => {
      this.splitting = !this.splitting;
      this.render();
    }, 'Show a plane through the selected node to split it by');
    this.splitRow = el('div.edit-row', {}, this.axisSel, this.atInput, this.atText, this.splitBtn);
    this.axisSel.addEventListener('change', () => this.renderPlane());
    this.atInput.addEventListener('input', () => this.renderPlane());
    this.splitBtn.addEventListener('click', () => this.split());

    this.joinBtn = button('Join', 'join', () => this.join(), 'Join the selected nodes (Shift+click to select several)');
    this.removeBtn = button('Remove', 'remove', () => this.remove(), 'Remove the selected nodes');
    this.copyBtn = button('Copy', 'copy', () => this.copy(), 'Copy the selected nodes');
    this.pasteBtn = button('Paste', 'paste', () => this.paste(), 'Paste the copied nodes into the selected node');
    this.placementSel = el('select', { 'data-testid': 'paste-placement' }, el('option', { value: 'insert' }, 'insert'), el('option', { value: 'replace' }, 'replace'));
    this.fitSel = el('select', { 'data-testid': 'paste-fit' }, el('option', { value: 'fill' }, 'fill'), el('option', { value: 'derive' }, 'derive'));
    this.clipText = el('div.edit-note', { 'data-testid': 'clipboard' });
    this.undoSlot = el('div.edit-row.undo-row');

    this.body = el(
      'div.edit-body',
      {},
      this.undoSlot,
      this.modeBox,
      el('div.edit-row', {}, this.regionSel),
      el('div.edit-row', {}, this.toolBtn, this.joinBtn, this.removeBtn),
      this.splitRow,
      el('div.edit-row', {}, this.copyBtn, this.pasteBtn, this.placementSel, this.fitSel),
      this.clipText,
    );
    this.empty = el('div.empty', {}, 'Proceduralize the model to edit it.');
    this.readOnly = el('div.empty.read-only', { 'data-testid': 'read-only' }, 'Read only: you are a viewer of this model.');
    container.append(el('h2', {}, 'Edit'), this.empty, this.readOnly, this.body);

    const s = editor.signals;
    s.roleChanged.add(() => this.render());
    s.selectionChanged.add(() => this.render());
    s.treeChanged.add(() => this.render());
    s.modelOpened.add(() => this.render());
    editor.cloud.signals.viewChanged.add(() => this.render());
    window.addEventListener('keydown', (e) => this.key(e));
    this.render();
  }

  // --- the ops ------------------------------------------------------------------------------
  // The resize op of the handles for `node` → `box`, in the current mode.
  resizeOp(node, box) {
    const op = { kind: OP.resize, node: node === this.editor.tree?.root ? 'root' : node, box: box.map(round), mode: this.mode };
    if (this.mode === 'local') {
      const region = this.regionBox(node);
      if (region) op.region = region.map(round);
    }
    return op;
  }

  // The local area of effect; null leaves the server's default (the node's old and new box).
  regionBox(node) {
    const tree = this.editor.tree;
    if (!tree || this.region === 'auto') return null;
    if (this.region === 'model') return tree.node(tree.root)?.box ?? null;
    const up = tree.ancestors(node);
    const k = this.region === 'parent' ? 1 : 2;
    const id = up.length >= k ? up[up.length - k] : tree.root;
    return tree.node(id)?.box ?? null;
  }

  splitPlane() {
    const n = this.single();
    if (!n || !Array.isArray(n.box)) return null;
    const axis = AXES.indexOf(this.axisSel.value);
    const lo = n.box[axis];
    const hi = n.box[axis + 3];
    return { node: n.id, axis, at: lo + (hi - lo) * Number(this.atInput.value) };
  }

  async split() {
    const p = this.splitPlane();
    if (!p) return;
    await this.editor.execute({ kind: OP.split, node: p.node, axis: AXES[p.axis], at: round(p.at) });
  }

  async join() {
    const nodes = this.editor.selected.nodeIds();
    if (nodes.length < 2) return;
    await this.editor.execute({ kind: OP.join, nodes });
  }

  async remove() {
    const nodes = this.editor.selected.nodeIds();
    if (!nodes.length) return;
    await this.editor.execute({ kind: OP.remove, nodes });
  }

  copy() {
    const ed = this.editor;
    const nodes = ed.selected.nodeIds();
    if (!ed.model || !nodes.length) return;
    this.clipboard = { model: ed.model.id, version: ed.model.version, nodes: nodes.slice(), name: ed.model.name };
    ed.notify(`Copied ${nodes.length} node${nodes.length === 1 ? '' : 's'}`);
    this.render();
  }

  // Pastes into the selected node. Nodes copied from another model travel as `source_model`
  // (style transfer); their ids belong to that model's tree at the version they were copied at.
  async paste() {
    const ed = this.editor;
    const clip = this.clipboard;
    const target = ed.selected.nodeIds();
    if (!ed.model || !clip || target.length !== 1) return;
    const op = {
      kind: OP.paste,
      source: clip.nodes,
      target: target[0],
      placement: this.placementSel.value,
      fit: this.fitSel.value,
    };
    let sourceVersion = ed.model.version;
    if (clip.model !== ed.model.id) {
      op.source_model = clip.model;
      try {
        sourceVersion = (await this.api.getModel(clip.model)).version;
      } catch (err) {
        ed.fail(err.problem || { title: 'Cannot paste', detail: `“${clip.name}” cannot be read: ${err.message}` });
        return;
      }
    }
    if (clip.version !== sourceVersion) {
      // node numbers belong to the tree they were copied from
      ed.fail({ title: 'Copy again', detail: `“${clip.name}” changed since the copy; its node numbers no longer apply.` });
      return;
    }
    await ed.execute(op);
  }

  key(e) {
    if (isTyping(e.target) || !(e.ctrlKey || e.metaKey) || e.altKey || !this.editor.canEdit) return;
    const k = e.key.toLowerCase();
    if (k === 'c' && this.editor.selected.nodeIds().length && !window.getSelection()?.toString()) {
      this.copy();
    } else if (k === 'v' && this.clipboard) {
      e.preventDefault();
      this.paste();
    } else if (k === 'j') {
      e.preventDefault();
      this.join();
    }
  }

  // --- view ---------------------------------------------------------------------------------
  single() {
    const id = this.editor.selected.single();
    return id !== null ? this.editor.tree?.node(id) ?? null : null;
  }

  render() {
    const ed = this.editor;
    const ready = !!(ed.model && ed.tree) && editsShown(ed);
    this.empty.textContent = ed.tree
      ? 'Show the derived points to edit the point model.'
      : 'Proceduralize the model to edit it.';
    // viewers get no edit tools at all (and no undo: they have no edits)
    if (ed.model && !ed.canEdit && this.splitting) this.splitting = false;
    this.readOnly.hidden = !ed.model || ed.canEdit;
    this.body.hidden = !ready || !ed.canEdit;
    this.empty.hidden = ready || !ed.model || !ed.canEdit;
    const nodes = ed.selected.nodeIds();
    const one = this.single();
    this.regionSel.hidden = this.mode !== 'local';
    this.toolBtn.classList.toggle('on', this.splitting);
    this.toolBtn.disabled = !one && !this.splitting;
    this.splitRow.hidden = !this.splitting;
    this.splitBtn.disabled = !one;
    this.axisSel.disabled = !one;
    this.atInput.disabled = !one;
    this.joinBtn.disabled = nodes.length < 2;
    this.removeBtn.disabled = !nodes.length;
    this.copyBtn.disabled = !nodes.length;
    this.pasteBtn.disabled = !this.clipboard || nodes.length !== 1;
    const clip = this.clipboard;
    this.clipText.textContent = clip
      ? `clipboard: node${clip.nodes.length === 1 ? '' : 's'} ${clip.nodes.join(', ')}${clip.model !== ed.model?.id ? ` of “${clip.name}”` : ''}`
      : '';
    this.renderPlane();
  }

  // The split plane through the selected node's box, in magenta.
  renderPlane() {
    const layer = this.viewport.layers.handles;
    layer.remove(this.plane);
    this.plane = null;
    const p = this.splitting ? this.splitPlane() : null;
    const n = this.single();
    this.atText.textContent = p ? `${p.at.toFixed(2)} m` : '';
    if (!p || !n) return;
    const b = n.box.slice();
    b[p.axis] = p.at;
    b[p.axis + 3] = p.at;
    const box = worldBox(b);
    const size = box.getSize(new THREE.Vector3());
    const centre = box.getCenter(new THREE.Vector3());
    const pad = Math.max(size.x, size.y, size.z) * 0.04;
    // world axes: archgram x → x, y → z, z → y; the flat axis gets a sliver
    const dims = [size.x, size.y, size.z].map((d) => (d < 1e-9 ? pad * 0.05 : d + 2 * pad));
    this.plane = new THREE.Mesh(
      new THREE.BoxGeometry(...dims),
      new THREE.MeshBasicMaterial({ color: PLANE_COLOUR, transparent: true, opacity: 0.35, depthWrite: false, side: THREE.DoubleSide }),
    );
    this.plane.position.copy(centre);
    this.plane.renderOrder = 5;
    this.plane.userData.tool = 'split-plane';
    layer.add(this.plane);
  }
}

// Whether what is on screen is what the edit tools change: a mesh model, or a point model's
// derived points (its uploaded points are refined by boxes instead, cloud.js).
export function editsShown(editor) {
  return !isCloud(editor.model) || editor.cloud.showsDerived();
}

function button(text, testid, onclick, title) {
  return el('button', { type: 'button', 'data-testid': testid, title, onclick }, text);
}

function round(v) {
  return Math.round(v * 1e6) / 1e6;
}

export function isTyping(target) {
  if (!target || !(target instanceof Element)) return false;
  return target.isContentEditable || /^(INPUT|TEXTAREA|SELECT)$/.test(target.tagName);
}
