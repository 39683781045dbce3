// The parts library sub-editor, owned by the Editor: the page of parts the search shows (words,
// a tag), the part whose details are open, and the composition being prepared — a part (at a
// version) glued into a target node of the open model with a mode and a scope — with the state
// of its preview. The library panel (librarypanel.js) reads this state, talks to the service
// and draws the preview; committing is one compose op through editor.execute.
import { OP } from './opkinds.js';
import { Signal } from './signal.js';

export const MODES = ['replace', 'insert', 'fill'];
export const SCOPES = ['node', 'rule'];

export class PartsLibrary {
  constructor(editor) {
    this.editor = editor;
    this.signals = {
      listChanged: new Signal(),    // the search's page (items) changed
      openChanged: new Signal(),    // the part shown in detail (part or null)
      composeChanged: new Signal(), // the composition being prepared (draft or null)
      previewChanged: new Signal(), // its preview: {state: 'busy'|'ok'|'failed', instances?, problem?} or null
    };
    this.query = { q: '', tag: '' };
    this.items = [];
    this.nextPageToken = null;
    this.tags = new Set(); // every tag seen, for the tag filter
    this.open = null;
    this.draft = null;     // {part, name, version, target, mode, scope, base}
    this.preview = null;
    this.previews = 0;     // previews asked for (a data attribute for tests)
    const s = editor.signals;
    // A composition names nodes of the tree it was prepared on.
    s.modelOpened.add(() => this.cancelCompose());
    s.treeChanged.add((tree) => {
      if (this.draft && (!tree || tree.version !== this.draft.base)) this.cancelCompose();
    });
  }

  // --- the list -----------------------------------------------------------------------------
  setQuery(q, tag) {
    this.query = { q: q ?? this.query.q, tag: tag ?? this.query.tag };
  }

  setItems(items, nextPageToken, append = false) {
    this.items = append ? [...this.items, ...items.filter((p) => !this.items.some((o) => o.id === p.id))] : items.slice();
    this.nextPageToken = nextPageToken ?? null;
    for (const p of items) for (const t of p.tags || []) this.tags.add(t);
    this.signals.listChanged.dispatch(this.items);
  }

  // A part shown in detail (with its versions), or null.
  setOpen(part) {
    this.open = part;
    if (part) for (const t of part.tags || []) this.tags.add(t);
    this.signals.openChanged.dispatch(part);
  }

  // --- composing ----------------------------------------------------------------------------
  // Prepares part (its newest version unless one is named) for a target node of the open
  // model's tree.
  startCompose(part, target, { version, mode = 'replace', scope = 'node' } = {}) {
    const tree = this.editor.tree;
    if (!tree || !tree.node(target)) return;
    this.draft = { part: part.id, name: part.name, version: version ?? part.version, target, mode, scope, base: tree.version };
    this.setPreview(null);
    this.signals.composeChanged.dispatch(this.draft);
  }

  // Changes the target, mode, scope or version of the prepared composition.
  updateCompose(fields) {
    if (!this.draft) return;
    this.draft = { ...this.draft, ...fields };
    this.setPreview(null);
    this.signals.composeChanged.dispatch(this.draft);
  }

  cancelCompose() {
    if (!this.draft && !this.preview) return;
    this.draft = null;
    this.setPreview(null);
    this.signals.composeChanged.dispatch(null);
  }

  setPreview(state) {
    this.preview = state;
    this.signals.previewChanged.dispatch(state);
  }

  // The compose op of the draft.
  op() {
    const d = this.draft;
    return d ? { kind: OP.compose, part: d.part, version: d.version, target: d.target, mode: d.mode, scope: d.scope } : null;
  }

  // Sends the composition; resolves with the version it made (null when refused).
  async commit() {
    const op = this.op();
    if (!op) return null;
    const v = await this.editor.execute(op);
    if (v !== null) this.cancelCompose();
    return v;
  }
}
