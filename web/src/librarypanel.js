// The parts library panel: selecting what to save (select-by-window, click then walk the tree
// with the arrow keys, the common ancestors of a selection offered at tree and rule level, what
// each selected node is), "save selection as part" (name, tags, description), the library
// (thumbnails, a search box, a tag filter, a part's details with its versions), and
// composing: drag a part onto the building, or pick a target with the selection, choose mode
// and scope, see the result previewed in the viewport (POST …/compose-preview, nothing
// stored), then commit it as one compose op (editor.execute). State lives in editor.library.
import * as THREE from 'three';
import { GLTFLoader } from 'three/examples/jsm/loaders/GLTFLoader.js';
import { isCloud } from './cloud.js';
import { el, timeAgo } from './dom.js';
import { MODES, SCOPES } from './library.js';
import { describeNode } from './treewalk.js';

const SEARCH_DELAY_MS = 200;
const PREVIEW_DELAY_MS = 120;
const SHOWN_NODES = 6;
const DRAG_TYPE = 'application/x-archgram-part';
const NEW_COLOUR = 0xe0a030; // what a composition brings in, in the preview

export class LibraryPanel {
  constructor(editor, api, viewport, windowSelect, container) {
    this.editor = editor;
    this.lib = editor.library;
    this.api = api;
    this.viewport = viewport;
    this.windowSelect = windowSelect;
    this.searchTimer = 0;
    this.searchToken = 0;
    this.selToken = 0;
    this.previewTimer = 0;
    this.previewToken = 0;
    this.previewObject = null;
    this.ancestors = null; // {nodes, tree, rule} of the current selection

    // --- selecting and saving
    this.windowBtn = el('button', { type: 'button', 'data-testid': 'window-select', title: 'Drag a rectangle over the view to select the nodes inside it' }, 'Select by window');
    this.windowBtn.addEventListener('click', () => windowSelect.setActive(!windowSelect.active));
    windowSelect.changed.add((on) => this.windowBtn.classList.toggle('on', on));
    this.selText = el('ul.lib-nodes', { 'data-testid': 'library-selection' });
    this.ancestorText = el('div.lib-ancestors', { 'data-testid': 'library-ancestors' });
    this.nameInput = el('input', { type: 'text', placeholder: 'name', maxLength: 200, 'data-testid': 'part-name' });
    this.tagsInput = el('input', { type: 'text', placeholder: 'tags, comma-separated', 'data-testid': 'part-tags' });
    this.descInput = el('input', { type: 'text', placeholder: 'description', maxLength: 4000, 'data-testid': 'part-description' });
    this.saveBtn = el('button.primary', { type: 'button', 'data-testid': 'save-part' }, 'Save selection as part');
    this.saveBtn.addEventListener('click', () => this.save());
    this.saveBox = el(
      'div.lib-save',
      {},
      el('div.edit-row', {}, this.windowBtn, el('span.edit-note', {}, '↑ parent · ↓ child · ← → siblings')),
      this.selText,
      this.ancestorText,
      el('div.edit-row', {}, this.nameInput),
      el('div.edit-row', {}, this.tagsInput),
      el('div.edit-row', {}, this.descInput),
      el('div.edit-row', {}, this.saveBtn),
    );

    // --- the library
    this.search = el('input', { type: 'search', placeholder: 'search parts', 'data-testid': 'library-search' });
    this.search.addEventListener('input', () => {
      clearTimeout(this.searchTimer);
      this.searchTimer = setTimeout(() => this.load(), SEARCH_DELAY_MS);
    });
    this.tagSel = el('select', { 'data-testid': 'library-tag' });
    this.tagSel.addEventListener('change', () => this.load());
    this.list = el('ul.lib-list', { 'data-testid': 'library-list' });
    this.more = el('button', { type: 'button', 'data-testid': 'library-more', hidden: true }, 'More');
    this.more.addEventListener('click', () => this.load(true));
    this.details = el('div.lib-details', { 'data-testid': 'part-details', hidden: true });

    // --- composing
    this.modeSel = el('select', { 'data-testid': 'compose-mode' }, MODES.map((m) => el('option', { value: m }, m)));
    this.scopeSel = el('select', { 'data-testid': 'compose-scope' }, SCOPES.map((s) => el('option', { value: s }, s === 'node' ? 'this node' : 'every instance of its rule')));
    this.versionSel = el('select', { 'data-testid': 'compose-version' });
    this.modeSel.addEventListener('change', () => this.lib.updateCompose({ mode: this.modeSel.value }));
    this.scopeSel.addEventListener('change', () => this.lib.updateCompose({ scope: this.scopeSel.value }));
    this.versionSel.addEventListener('change', () => this.lib.updateCompose({ version: Number(this.versionSel.value) }));
    this.targetText = el('div.edit-note', { 'data-testid': 'compose-target' });
    this.composeStatus = el('div.edit-note', { 'data-testid': 'compose-status' });
    this.retarget = el('button', { type: 'button', 'data-testid': 'compose-retarget', title: 'The selected node becomes the target' }, 'Target: selection');
    this.retarget.addEventListener('click', () => {
      const t = this.selectionTarget();
      if (t !== null) this.lib.updateCompose({ target: t });
    });
    this.commitBtn = el('button.primary', { type: 'button', 'data-testid': 'compose-commit' }, 'Compose');
    this.commitBtn.addEventListener('click', () => this.commit());
    this.cancelBtn = el('button', { type: 'button', 'data-testid': 'compose-cancel' }, 'Cancel');
    this.cancelBtn.addEventListener('click', () => this.lib.cancelCompose());
    this.composeBox = el(
      'div.lib-compose',
      { 'data-testid': 'compose-form', hidden: true },
      el('h3', {}, 'Compose'),
      this.targetText,
      el('div.edit-row', {}, this.modeSel, this.scopeSel),
      el('div.edit-row', {}, this.versionSel, this.retarget),
      this.composeStatus,
      el('div.edit-row', {}, this.commitBtn, this.cancelBtn),
    );

    this.empty = el('div.empty', {}, 'Proceduralize a model to save parts of it or compose parts into it.');
    container.append(
      el('h2', {}, 'Parts library'),
      this.empty,
      this.saveBox,
      this.composeBox,
      el('div.edit-row', {}, this.search, this.tagSel),
      this.list,
      this.more,
      this.details,
    );

    // a part dragged from the library onto the building: its target is the node under the drop
    const vp = viewport.container;
    vp.addEventListener('dragover', (e) => {
      if (e.dataTransfer?.types?.includes(DRAG_TYPE) && this.editor.tree) e.preventDefault();
    });
    vp.addEventListener('drop', (e) => {
      const id = Number(e.dataTransfer?.getData(DRAG_TYPE));
      if (!id) return;
      e.preventDefault();
      this.dropAt(id, e.clientX, e.clientY);
    });

    const s = editor.signals;
    s.selectionChanged.add(() => this.renderSelection());
    s.treeChanged.add(() => this.renderSelection());
    s.modelOpened.add(() => this.renderSelection());
    s.meshChanged.add(() => this.dropPreview());
    const ls = this.lib.signals;
    ls.listChanged.add(() => this.renderList());
    ls.openChanged.add(() => this.renderDetails());
    ls.composeChanged.add(() => {
      this.renderCompose();
      this.schedulePreview();
    });
    ls.previewChanged.add(() => this.renderCompose());
    this.renderSelection();
    this.renderCompose();
    // the library is read with the account's token: once signed in (again)
    editor.signals.accountChanged.add((account) => account && this.load());
  }

  // --- the library ----------------------------------------------------------------------------
  async load(append = false) {
    const lib = this.lib;
    lib.setQuery(this.search.value.trim(), this.tagSel.value);
    const token = ++this.searchToken;
    try {
      const page = await this.api.listParts({ ...lib.query, pageToken: append ? lib.nextPageToken : null });
      if (token !== this.searchToken) return;
      lib.setItems(page.items, page.next_page_token, append);
    } catch (err) {
      if (token === this.searchToken) this.editor.fail(err);
    }
  }

  async openPart(id) {
    try {
      this.lib.setOpen(await this.api.getPart(id));
    } catch (err) {
      this.editor.fail(err);
    }
  }

  renderList() {
    const lib = this.lib;
    const chosen = this.tagSel.value;
    this.tagSel.replaceChildren(
      el('option', { value: '' }, 'any tag'),
      ...[...lib.tags].sort().map((t) => el('option', { value: t, selected: t === chosen }, t)),
    );
    this.list.replaceChildren(
      ...lib.items.map((p) => {
        const card = el(
          'li.lib-part',
          {
            draggable: true,
            tabIndex: 0,
            title: `${p.name}${p.description ? ` — ${p.description}` : ''} (drag onto the building to compose it)`,
            'data-testid': 'library-part',
            dataset: { part: p.id, name: p.name },
            onclick: () => this.openPart(p.id),
            onkeydown: (e) => e.key === 'Enter' && this.openPart(p.id),
            ondragstart: (e) => {
              e.dataTransfer.setData(DRAG_TYPE, String(p.id));
              e.dataTransfer.effectAllowed = 'copy';
            },
          },
          this.thumbnail(el('img', { alt: p.name, width: 64, height: 64, draggable: false }), p),
          el('span.lib-name', {}, p.name),
          el('span.lib-tags', {}, (p.tags || []).join(' · ')),
        );
        if (lib.open?.id === p.id) card.classList.add('selected');
        return card;
      }),
    );
    if (!lib.items.length) this.list.append(el('li.empty', {}, lib.query.q || lib.query.tag ? 'No part matches.' : 'The library is empty.'));
    this.more.hidden = !lib.nextPageToken;
    this.list.dataset.count = String(lib.items.length);
  }

  // Thumbnails are fetched with the token (api.imageUrl); a part without one stays blank.
  thumbnail(img, p) {
    if (p.thumbnail) this.api.imageUrl(p.thumbnail).then((url) => (img.src = url), () => {});
    return img;
  }

  renderDetails() {
    const p = this.lib.open;
    this.details.hidden = !p;
    if (!p) {
      this.details.replaceChildren();
      return;
    }
    const newest = p.versions?.[0];
    const size = newest?.stats?.size ? `${newest.stats.size.map((v) => v.toFixed(2)).join(' × ')} m` : '–';
    const here = el('button.primary', { type: 'button', 'data-testid': 'compose-here', title: 'Compose this part into the selected node' }, 'Compose into selection');
    here.disabled = !this.editor.tree || this.selectionTarget() === null;
    here.addEventListener('click', () => {
      const t = this.selectionTarget();
      if (t !== null) this.lib.startCompose(p, t);
    });
    this.details.dataset.part = String(p.id);
    this.details.replaceChildren(
      this.thumbnail(el('img.lib-thumb', { alt: p.name, width: 128, height: 128 }), p),
      el('h3', { 'data-testid': 'part-title' }, p.name),
      p.description ? el('p.lib-desc', {}, p.description) : '',
      el('div.lib-tags', {}, (p.tags || []).join(' · ') || 'no tags'),
      el('div.edit-note', {}, `${newest?.stats?.visible ?? '–'} visible nodes · ${newest?.stats?.rules ?? '–'} rules · ${size}`),
      el(
        'ol.lib-versions',
        {},
        (p.versions || []).map((v) => el(
          'li',
          { 'data-testid': 'part-version', dataset: { version: v.version } },
          `version ${v.version} · ${timeAgo(v.created_at)}${v.source ? ` · from “${v.source.name ?? 'a model'}” v${v.source.version}, node ${v.source.node}` : ''}`,
        )),
      ),
      el('div.edit-row', {}, here),
    );
  }

  // --- selecting and saving -----------------------------------------------------------------
  // The node a save or a composition takes from the selection: the one node, or the common
  // ancestor (tree level) of several once the service has said which it is.
  selectionTarget() {
    const ids = this.editor.selected.nodeIds();
    if (ids.length === 1) return ids[0];
    const a = this.ancestors;
    return ids.length > 1 && a && a.nodes.join(',') === ids.join(',') ? a.tree : null;
  }

  renderSelection() {
    const ed = this.editor;
    const tree = ed.tree;
    // parts are saved from and composed into meshes (the service refuses point models)
    const cloud = isCloud(ed.model);
    const ready = !!(ed.model && tree) && !cloud;
    this.saveBox.hidden = !ready;
    this.empty.hidden = ready;
    this.empty.textContent = cloud
      ? 'Parts are saved from and composed into mesh models.'
      : 'Proceduralize a model to save parts of it or compose parts into it.';
    const ids = ed.selected.nodeIds();
    this.saveBtn.disabled = !ready || !ids.length;
    this.selText.replaceChildren(
      ...(ready ? ids.slice(0, SHOWN_NODES).map((id) => el('li', { dataset: { node: id } }, describeNode(tree.node(id)))) : []),
      ...(ready && ids.length > SHOWN_NODES ? [el('li.empty', {}, `and ${ids.length - SHOWN_NODES} more`)] : []),
      ...(ready && !ids.length ? [el('li.empty', {}, 'Select nodes to save: click the model, walk with the arrow keys, or select by window.')] : []),
    );
    this.ancestors = null;
    this.ancestorText.replaceChildren();
    if (ready && ids.length > 1) this.loadAncestors(ids);
    this.renderDetails();
  }

  // The common ancestors of several selected nodes (the service runs the paper's stacks).
  async loadAncestors(ids) {
    const ed = this.editor;
    const token = ++this.selToken;
    try {
      const a = await this.api.selectionOf(ed.model.id, ed.tree.version, ids);
      if (token !== this.selToken) return;
      this.ancestors = a;
      const tree = ed.tree;
      const pick = (id, level) => el(
        'button',
        { type: 'button', 'data-testid': `ancestor-${level}`, dataset: { node: id }, title: describeNode(tree?.node(id)), onclick: () => ed.selected.node(id) },
        `node ${id}`,
      );
      this.ancestorText.replaceChildren(
        el('span', {}, 'saves their common ancestor '), pick(a.tree, 'tree'),
        el('span', {}, ' · at rule level: '), ...a.rule.map((id) => pick(id, 'rule')),
      );
      this.renderDetails();
    } catch (err) {
      if (token === this.selToken) this.ancestorText.textContent = err.problem?.detail || err.message;
    }
  }

  async save() {
    const ed = this.editor;
    const ids = ed.selected.nodeIds();
    const name = this.nameInput.value.trim();
    if (!ed.model || !ed.tree || !ids.length) return;
    if (!name) {
      ed.fail({ title: 'Name the part', detail: 'a part needs a name' });
      this.nameInput.focus();
      return;
    }
    const tags = this.tagsInput.value.split(',').map((t) => t.trim()).filter(Boolean);
    const body = { model: ed.model.id, version: ed.tree.version, name, tags };
    const desc = this.descInput.value.trim();
    if (desc) body.description = desc;
    if (ids.length === 1) body.node = ids[0];
    else body.nodes = ids;
    this.saveBtn.disabled = true;
    try {
      const part = await this.api.savePart(body);
      ed.notify(`Saved “${part.name}” to the library`);
      this.nameInput.value = '';
      this.tagsInput.value = '';
      this.descInput.value = '';
      this.lib.setOpen(part);
      await this.load();
    } catch (err) {
      ed.fail(err);
    } finally {
      this.saveBtn.disabled = !ed.selected.nodeIds().length;
    }
  }

  // --- composing ------------------------------------------------------------------------------
  async dropAt(id, x, y) {
    const ed = this.editor;
    const owner = this.viewport.layers.model.hit(this.viewport.ray(x, y));
    const target = owner ? ed.tree?.nodeOfComponent(owner.userData.component) ?? null : null;
    if (target === null) {
      ed.fail({ title: 'Drop it on the building', detail: 'the part must be dropped on a part of the proceduralized model' });
      return;
    }
    try {
      const part = this.lib.open?.id === id ? this.lib.open : await this.api.getPart(id);
      this.lib.setOpen(part);
      ed.selected.node(target);
      this.lib.startCompose(part, target);
    } catch (err) {
      ed.fail(err);
    }
  }

  renderCompose() {
    const d = this.lib.draft;
    this.composeBox.hidden = !d;
    if (!d) {
      this.viewport.mark('composePreview', null);
      return;
    }
    const tree = this.editor.tree;
    this.targetText.textContent = `“${d.name}” into ${describeNode(tree?.node(d.target))}`;
    this.modeSel.value = d.mode;
    this.scopeSel.value = d.scope;
    const versions = this.lib.open?.id === d.part ? this.lib.open.versions.map((v) => v.version) : [d.version];
    this.versionSel.replaceChildren(...versions.map((v) => el('option', { value: v, selected: v === d.version }, `version ${v}`)));
    const p = this.lib.preview;
    this.composeStatus.dataset.state = p?.state ?? '';
    this.composeStatus.textContent = !p ? '' : p.state === 'busy' ? 'previewing…'
      : p.state === 'ok' ? `preview: ${p.instances} instance${p.instances === 1 ? '' : 's'} changed`
        : `cannot compose: ${p.problem?.detail || p.problem?.title || 'refused'}`;
    this.commitBtn.disabled = p?.state !== 'ok';
  }

  schedulePreview() {
    clearTimeout(this.previewTimer);
    this.dropPreview();
    if (!this.lib.draft) return;
    this.previewTimer = setTimeout(() => this.runPreview(), PREVIEW_DELAY_MS);
  }

  async runPreview() {
    const lib = this.lib;
    const d = lib.draft;
    const op = lib.op();
    if (!d || !op || !this.editor.model) return;
    const token = ++this.previewToken;
    lib.previews += 1;
    lib.setPreview({ state: 'busy' });
    try {
      const { buffer, instances } = await this.api.previewCompose(this.editor.model.id, d.base, op);
      if (token !== this.previewToken || lib.draft !== d) return;
      const gltf = await new GLTFLoader().parseAsync(buffer, '');
      if (token !== this.previewToken || lib.draft !== d) return;
      this.showPreview(gltf.scene);
      lib.setPreview({ state: 'ok', instances });
      this.viewport.mark('composePreview', instances);
    } catch (err) {
      if (token === this.previewToken && lib.draft === d) lib.setPreview({ state: 'failed', problem: err.problem || { title: err.message } });
    }
  }

  // The composed model drawn in place of the model: its labels in the tree's colours, what the
  // part brings in a colour of its own.
  showPreview(scene) {
    const { model, preview } = this.viewport.layers;
    this.dropPreview();
    model.hide([...model.byComponent.keys()]);
    const tree = this.editor.tree;
    scene.traverse((o) => {
      if (!o.isMesh) return;
      let label = null;
      for (let x = o; x && label === null; x = x.parent) if (typeof x.userData?.label === 'string') label = x.userData.label;
      const known = label && tree ? tree.colourOf(label) : null;
      for (const m of [].concat(o.material)) m.dispose();
      o.material = new THREE.MeshStandardMaterial({ color: known ? new THREE.Color(known) : new THREE.Color(NEW_COLOUR), roughness: 0.85, metalness: 0, side: THREE.DoubleSide });
    });
    this.previewObject = preview.add(scene);
  }

  dropPreview() {
    if (!this.previewObject) return;
    this.viewport.layers.preview.remove(this.previewObject);
    this.previewObject = null;
    this.viewport.layers.model.unhide();
    this.viewport.mark('composePreview', null);
  }

  async commit() {
    const v = await this.lib.commit();
    if (v === null) return;
    // the op's broadcast reloads mesh and tree; the preview stays up until then
    this.editor.notify(`Composed (version ${v})`);
  }
}
