// The editor: all client state plus the signals that announce its changes, and the one path
// every op takes (execute). Panels and the viewport read state here and listen to signals;
// they never talk to each other. Parts with state of their own are sub-editors it owns:
// the selection (selection.js), the extrusion being edited (extrusioneditor.js), the parts
// library with the composition being prepared (library.js) and the point cloud on view
// (cloud.js).
import { CloudEditor, isCloud } from './cloud.js';
import { ExtrusionEditor } from './extrusioneditor.js';
import { PartsLibrary } from './library.js';
import { OP, REMESHING, RESEGMENTING, STRUCTURAL, isSendable, kinds } from './opkinds.js';
import { Selection } from './selection.js';
import { Signal } from './signal.js';

// Roles on a model that may change it (the server checks again; this only spares refusals).
const EDITING_ROLES = new Set(['editor', 'owner']);
// Ops only a proceduralized cloud has (undo, redo and restore may go either way).
const PROCEDURAL_CLOUD = kinds('proceduralize', 'grammar', ...STRUCTURAL);

export class Editor {
  constructor() {
    this.signals = {
      modelsChanged: new Signal(),     // the list (models, nextPageToken)
      modelOpened: new Signal(),       // model (or null when closed)
      modelChanged: new Signal(),      // name or version of the open model
      selectionChanged: new Signal(),  // selection (or null)
      peersChanged: new Signal(),
      historyChanged: new Signal(),
      jobChanged: new Signal(),        // job (or null when the panel should clear)
      meshChanged: new Signal(),       // model: its mesh was replaced (proceduralize, grammar edit)
      pointsChanged: new Signal(),     // model, op kind: a point cloud's segmentation changed (segment ops, undo)
      treeChanged: new Signal(),       // split tree (SplitTree or null)
      grammarChanged: new Signal(),    // grammar {text, version} (or null)
      procJobChanged: new Signal(),    // proceduralize job of the open model (or null)
      connectionChanged: new Signal(), // 'offline' | 'connecting' | 'online' | 'lost'
      accountChanged: new Signal(),    // {name, role} of the signed-in account
      roleChanged: new Signal(),       // the account's role on the open model (or null)
      cameraChanged: new Signal(),     // {position, target} from the viewport
      problem: new Signal(),           // {title, detail, ...}: shown to the person
      notice: new Signal(),            // short informational message
    };

    this.models = [];
    this.nextPageToken = null;

    this.model = null;      // the open model object, name/version kept current by ops
    this.selected = new Selection(() => this.tree, this.signals.selectionChanged);
    this.tree = null;       // SplitTree of the open model once proceduralized
    this.grammar = null;    // {text, version} of the open model once proceduralized
    this.procJob = null;
    this.peers = new Map(); // peer id -> {peer, user, state}
    this.ops = new Map();   // version -> op entry of the open model
    this.job = null;
    this.connection = 'offline';
    this.account = null;    // {name, role, auth} from GET /api/v1/me (auth.js)
    this.role = null;       // 'owner' | 'editor' | 'viewer' on the open model
    this.camera = null;
    this.transport = null;  // sends ops: the live connection (REST while it is down)
    this.extrusion = new ExtrusionEditor(this);
    this.library = new PartsLibrary(this);
    this.cloud = new CloudEditor(this);
  }

  // The selection's value ({component, group, node?, nodes?, components?} or null).
  get selection() {
    return this.selected.value;
  }

  // The signed-in account's name: the author of its ops, the name others see.
  get user() {
    return this.account?.name ?? '';
  }

  // May the person change the open model? Viewers get no edit tools and send no ops.
  get canEdit() {
    return !!this.model && EDITING_ROLES.has(this.role);
  }

  // --- ops ----------------------------------------------------------------------------------
  useTransport(transport) {
    this.transport = transport;
  }

  // Every op this client makes goes through here: it is sent against the current version, and
  // a refusal (nack, problem), a lost connection or a failed request is told to the person
  // once, after which the views drop what they showed of it. Resolves with the version the op
  // got, or null when it was not applied.
  async execute(op) {
    if (!op || !isSendable(op.kind)) {
      this.fail({ title: 'Not an op', detail: `"${op?.kind}" is not a kind of op this client sends` });
      return null;
    }
    if (!this.model || !this.transport) {
      this.fail({ title: 'Edit not sent', detail: this.model ? 'not connected to the server' : 'no model is open' });
      return null;
    }
    if (!this.canEdit) {
      this.fail({ title: 'Read only', detail: `You are a ${this.role ?? 'guest'} of this model: ask an owner to make you an editor.` });
      return null;
    }
    try {
      return await this.transport.sendOp(op);
    } catch (err) {
      this.fail(err);
      this.refreshModel();
      return null;
    }
  }

  // --- model list ---------------------------------------------------------------------------
  setModels(items, nextPageToken, append = false) {
    this.models = append ? mergeById(this.models, items) : items.slice();
    this.nextPageToken = nextPageToken ?? null;
    this.signals.modelsChanged.dispatch(this.models);
  }

  upsertModel(model) {
    this.models = mergeById(this.models, [model]);
    this.signals.modelsChanged.dispatch(this.models);
  }

  // --- the open model -----------------------------------------------------------------------
  openModel(model) {
    this.model = model ? { ...model } : null;
    this.role = model?.role ?? null;
    this.selected.reset();
    this.tree = null;
    this.grammar = null;
    this.procJob = null;
    this.peers.clear();
    this.ops.clear();
    this.signals.modelOpened.dispatch(this.model);
    this.signals.roleChanged.dispatch(this.role);
    this.signals.treeChanged.dispatch(null);
    this.signals.grammarChanged.dispatch(null);
    this.signals.procJobChanged.dispatch(null);
    this.signals.selectionChanged.dispatch(null);
    this.signals.peersChanged.dispatch(this.peers);
    this.signals.historyChanged.dispatch(this.history());
  }

  get version() {
    return this.model ? this.model.version : null;
  }

  // Op entries {version, author, cid, op, at}, possibly overlapping what we already have.
  addHistory(entries) {
    let changed = false;
    for (const e of entries) {
      if (!this.ops.has(e.version)) {
        this.ops.set(e.version, e);
        changed = true;
      }
    }
    if (changed) this.signals.historyChanged.dispatch(this.history());
  }

  history() {
    return [...this.ops.values()].sort((a, b) => a.version - b.version);
  }

  // Applies one sequenced op to the open model; entries at or below the current version are
  // already part of it and only join the history.
  applyOp(entry) {
    if (!this.model) return;
    this.addHistory([entry]);
    if (entry.version <= this.model.version) return;
    this.model.version = entry.version;
    const op = entry.op || {};
    if (op.kind === OP.rename && typeof op.name === 'string') this.model.name = op.name;
    // a point cloud's segmentation is what the segment ops change; once proceduralized its
    // derived points, tree and grammar change as a mesh model's do
    const cloud = isCloud(this.model);
    const resegmented = cloud && RESEGMENTING.has(op.kind);
    const remeshed = REMESHING.has(op.kind);
    // an undo may take a cloud back before its proceduralization: the model's figures tell
    const madeProcedural = remeshed && (!cloud || PROCEDURAL_CLOUD.has(op.kind));
    if (madeProcedural) this.model.proceduralized = true;
    const listed = this.models.find((m) => m.id === this.model.id);
    if (listed) {
      listed.name = this.model.name;
      listed.version = entry.version;
      if (madeProcedural) listed.proceduralized = true;
      this.signals.modelsChanged.dispatch(this.models);
    }
    this.signals.modelChanged.dispatch(this.model);
    if (remeshed) {
      // Component numbers refer to the old mesh: drop the pick before the views reload.
      this.selected.clear();
      this.signals.meshChanged.dispatch(this.model);
    }
    if (resegmented) this.signals.pointsChanged.dispatch(this.model, op.kind);
  }

  // Fresh figures of the open model (e.g. re-read after its mesh changed).
  updateModel(model) {
    if (!this.model || model.id !== this.model.id || model.version < this.model.version) return;
    const was = !!this.model.proceduralized;
    this.model = { ...this.model, stats: model.stats, proceduralized: model.proceduralized };
    this.signals.modelChanged.dispatch(this.model);
    // a cloud proceduralized (or no longer) is drawn from other points
    if (isCloud(this.model) && was !== !!model.proceduralized) this.signals.pointsChanged.dispatch(this.model);
  }

  // The server told us the current version (welcome) without ops to carry us there.
  setVersion(version) {
    if (!this.model || version <= this.model.version) return;
    this.model.version = version;
    this.signals.modelChanged.dispatch(this.model);
  }

  // Re-announces the model so views drop unconfirmed edits (e.g. a title typed but refused).
  refreshModel() {
    if (this.model) this.signals.modelChanged.dispatch(this.model);
  }

  // --- camera -------------------------------------------------------------------------------
  setCamera(camera) {
    this.camera = camera;
    this.signals.cameraChanged.dispatch(camera);
  }

  // --- peers --------------------------------------------------------------------------------
  setPeers(list) {
    this.peers.clear();
    for (const p of list || []) this.peers.set(p.peer, { peer: p.peer, user: p.user, state: p.state ?? null });
    this.signals.peersChanged.dispatch(this.peers);
  }

  updatePeer(peer, fields) {
    const prev = this.peers.get(peer) || { peer, user: fields.user ?? peer, state: null };
    this.peers.set(peer, { ...prev, ...fields });
    this.signals.peersChanged.dispatch(this.peers);
  }

  removePeer(peer) {
    if (this.peers.delete(peer)) this.signals.peersChanged.dispatch(this.peers);
  }

  // --- the account ----------------------------------------------------------------------------
  setAccount(account) {
    this.account = account ? { ...account } : null;
    this.signals.accountChanged.dispatch(this.account);
  }

  // The role on the open model changed (the room told us, or a share did).
  setRole(role) {
    if (!this.model || role === this.role) return;
    this.role = role;
    this.model.role = role;
    const listed = this.models.find((m) => m.id === this.model.id);
    if (listed) listed.role = role;
    this.signals.roleChanged.dispatch(role);
  }

  setJob(job) {
    this.job = job;
    this.signals.jobChanged.dispatch(job);
  }

  setProcJob(job) {
    this.procJob = job;
    this.signals.procJobChanged.dispatch(job);
  }

  // --- proceduralization --------------------------------------------------------------------
  setTree(tree) {
    this.tree = tree;
    this.signals.treeChanged.dispatch(tree);
    this.selected.treeReplaced(); // the pick's node belongs to the previous tree
  }

  setGrammar(grammar) {
    this.grammar = grammar;
    this.signals.grammarChanged.dispatch(grammar);
  }

  setConnection(state) {
    if (state === this.connection) return;
    this.connection = state;
    this.signals.connectionChanged.dispatch(state);
  }

  // Every failure the person should know about goes through here.
  fail(problem) {
    const p = toProblem(problem);
    console.warn(`archgram: ${p.title}${p.detail ? `: ${p.detail}` : ''}`);
    this.signals.problem.dispatch(p);
  }

  notify(text) {
    this.signals.notice.dispatch(text);
  }
}

function mergeById(list, items) {
  const out = list.slice();
  for (const item of items) {
    const i = out.findIndex((m) => m.id === item.id);
    if (i >= 0) out[i] = item;
    else out.push(item);
  }
  return out.sort((a, b) => a.id - b.id);
}

export function toProblem(x) {
  if (x && x.problem) return x.problem; // ApiError
  if (x instanceof Error) return { title: 'Unexpected error', detail: x.message };
  if (x && typeof x === 'object') return { title: x.title || 'Error', ...x };
  return { title: String(x) };
}
