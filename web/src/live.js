// The live connection: one websocket to archgramd for a model's room and for job progress.
// It turns server messages into editor changes, reconnects with backoff after a loss and
// resumes the room with hello {since} so no op is missed.
import { OP } from './opkinds.js';

const PRESENCE_INTERVAL_MS = 100; // at most 10 presence messages a second
const PRESENCE_MAX_SELECTION = 1000; // keeps a presence state well under the server's 16 KiB
const BACKOFF_MS = [500, 1000, 2000, 4000, 8000, 15000];

let cidCounter = 0;
function newCid() {
  cidCounter += 1;
  return `c-${Date.now().toString(36)}-${Math.random().toString(36).slice(2, 6)}-${cidCounter}`;
}

export class Live {
  constructor(editor, api) {
    this.editor = editor;
    this.api = api;
    this.ws = null;
    this.room = null;         // model id we want to be in
    this.pending = new Map(); // cid -> op awaiting ack/nack
    this.watchers = new Map(); // job id -> callback(message)
    this.attempt = 0;
    this.retryTimer = null;
    this.opening = null;
    this.presenceTimer = null;
    this.presenceDue = false;
    this.lastPresence = 0;
    this.handlers = new Map(); // message type -> callback(msg, inRoom) for types added by tools
  }

  // Lets a tool (e.g. the live drag preview) receive a message type this class does not handle.
  on(type, callback) {
    this.handlers.set(type, callback);
  }

  get open() {
    return this.ws !== null && this.ws.readyState === WebSocket.OPEN;
  }

  // Resolves once the socket is open (or rejects if it cannot be opened now).
  async connect() {
    if (this.open) return;
    if (this.opening) return this.opening;
    this.opening = this.openSocket().finally(() => {
      this.opening = null;
    });
    return this.opening;
  }

  async openSocket() {
    clearTimeout(this.retryTimer);
    let health;
    try {
      health = await this.api.getHealth();
    } catch (err) {
      this.lost(); // the server itself is away: keep retrying
      throw err;
    }
    const port = health.ws_port;
    if (!port) throw new Error('the server announced no websocket port');
    const scheme = location.protocol === 'https:' ? 'wss' : 'ws';
    const url = `${scheme}://${location.hostname}:${port}/`;
    this.editor.setConnection(this.attempt ? 'lost' : 'connecting');
    await new Promise((resolve, reject) => {
      let ws;
      try {
        // a browser cannot set headers on a websocket: the token rides as a second subprotocol
        const token = this.api.auth?.token;
        ws = new WebSocket(url, token ? ['archgram', `archgram.bearer.${token}`] : 'archgram');
      } catch (err) {
        reject(err);
        return;
      }
      this.ws = ws;
      let opened = false;
      ws.onopen = () => {
        opened = true;
        const wasLost = this.attempt > 0;
        this.attempt = 0;
        this.editor.setConnection('online');
        if (wasLost) this.editor.notify('Live connection restored');
        this.resume();
        resolve();
      };
      ws.onmessage = (ev) => this.receive(ev.data);
      ws.onclose = () => {
        if (this.ws === ws) this.ws = null;
        if (!opened) reject(new Error(`cannot reach ${url}`));
        this.lost();
      };
      ws.onerror = () => {
        // onclose follows and handles it
      };
    });
  }

  // After a loss: tell the person once, then retry with growing pauses.
  lost() {
    const first = this.attempt === 0;
    const delay = BACKOFF_MS[Math.min(this.attempt, BACKOFF_MS.length - 1)];
    this.attempt += 1;
    this.api.health = null; // a restarted server may announce another websocket port
    this.editor.setConnection('lost');
    if (first) {
      this.editor.fail({
        type: 'urn:archgram:problem:connection',
        title: 'Live connection lost',
        detail: 'Reconnecting… edits made meanwhile are sent over REST.',
      });
    }
    // Unacknowledged ops may or may not have been applied: the resync on reconnect tells.
    for (const p of this.pending.values()) {
      p.reject(Object.assign(new Error('connection lost'), {
        problem: { title: 'Edit not confirmed', detail: 'The live connection dropped before the server answered; the model resyncs on reconnect.' },
      }));
    }
    this.pending.clear();
    clearTimeout(this.retryTimer);
    this.retryTimer = setTimeout(() => {
      this.connect().catch(() => {
        // onclose already scheduled the next attempt
      });
    }, delay);
  }

  // Re-enters the room and re-subscribes to jobs after (re)connecting.
  resume() {
    if (this.room !== null) this.hello();
    for (const job of this.watchers.keys()) this.send({ type: 'watch', job });
  }

  send(msg) {
    if (!this.open) return false;
    this.ws.send(JSON.stringify(msg));
    return true;
  }

  // --- room ---------------------------------------------------------------------------------
  async join(modelId) {
    this.room = modelId;
    // A socket being opened says hello itself once open (resume()).
    if (this.open) this.hello();
    else await this.connect();
  }

  hello() {
    const ed = this.editor;
    if (this.room === null || !ed.model || ed.model.id !== this.room) return;
    this.send({ type: 'hello', model: this.room, since: ed.model.version });
  }

  // Sends an op made against the current version; resolves with the version it got, rejects
  // with the problem of a nack or a failed REST request. Only editor.execute calls this.
  sendOp(op) {
    const ed = this.editor;
    const cid = newCid();
    if (!ed.model) return Promise.reject(new Error('no model is open'));
    if (!this.open) return this.sendOpRest(cid, op);
    return new Promise((resolve, reject) => {
      this.pending.set(cid, { op, resolve, reject });
      this.send({ type: 'op', base: ed.model.version, cid, op });
    });
  }

  async sendOpRest(cid, op) {
    const ed = this.editor;
    const { id, version } = ed.model;
    let newVersion;
    if (op.kind === OP.rename) {
      const model = await this.api.rename(id, version, op.name);
      newVersion = model.version;
    } else {
      newVersion = (await this.api.postOp(id, version, cid, op)).version;
    }
    ed.applyOp({ version: newVersion, author: ed.user, cid, op, at: new Date().toISOString() });
    return newVersion;
  }

  presence() {
    this.presenceDue = true;
    if (this.presenceTimer) return;
    const wait = Math.max(0, this.lastPresence + PRESENCE_INTERVAL_MS - Date.now());
    this.presenceTimer = setTimeout(() => {
      this.presenceTimer = null;
      if (!this.presenceDue) return;
      this.presenceDue = false;
      this.lastPresence = Date.now();
      const ed = this.editor;
      if (this.room === null) return;
      this.send({
        type: 'presence',
        state: {
          name: ed.user,
          selection: ed.selected.components().slice(0, PRESENCE_MAX_SELECTION),
          camera: ed.camera,
        },
      });
    }, wait);
  }

  // --- jobs ---------------------------------------------------------------------------------
  watch(jobId, callback) {
    this.watchers.set(jobId, callback);
    this.send({ type: 'watch', job: jobId });
  }

  unwatch(jobId) {
    this.watchers.delete(jobId);
  }

  // --- incoming -----------------------------------------------------------------------------
  receive(data) {
    let msg;
    try {
      msg = JSON.parse(data);
    } catch {
      this.editor.fail({ title: 'Bad message from the server', detail: String(data).slice(0, 200) });
      return;
    }
    const ed = this.editor;
    const inRoom = ed.model && this.room === ed.model.id;
    switch (msg.type) {
      case 'welcome':
        if (!inRoom || msg.model !== ed.model.id) return;
        if (msg.role) ed.setRole(msg.role);
        ed.setPeers(msg.peers);
        this.applyOps(msg.ops || []);
        // A long absence is replayed in slices: ask for the next one from where we are now.
        if (msg.more) this.hello();
        else ed.setVersion(msg.version);
        this.presence();
        break;
      case 'join':
        if (inRoom) ed.updatePeer(msg.peer, { user: msg.user, state: null });
        break;
      case 'leave':
        if (inRoom) ed.removePeer(msg.peer);
        break;
      case 'presence':
        if (inRoom) ed.updatePeer(msg.peer, { user: msg.user, state: msg.state ?? null });
        break;
      case 'op':
        if (inRoom) this.applyOps([msg]);
        break;
      case 'ack': {
        const p = this.pending.get(msg.cid);
        if (!p) return;
        this.pending.delete(msg.cid);
        if (ed.model && msg.version === ed.model.version + 1) {
          ed.applyOp({ version: msg.version, author: ed.user, cid: msg.cid, op: p.op, at: new Date().toISOString() });
        } else {
          this.hello(); // ops we have not seen came first: catch up, ours is among them
        }
        p.resolve(msg.version);
        break;
      }
      case 'nack': {
        const p = this.pending.get(msg.cid);
        this.pending.delete(msg.cid);
        const problem = msg.problem || { title: 'Edit refused' };
        this.hello(); // resync from our version
        if (p) {
          p.reject(Object.assign(new Error(problem.title), { problem })); // editor.execute tells
        } else {
          ed.fail(problem); // an op of an earlier connection
          ed.refreshModel();
        }
        break;
      }
      case 'job.progress':
      case 'job.done': {
        const cb = this.watchers.get(msg.job);
        if (cb) cb(msg);
        break;
      }
      case 'access':
        // an owner changed who may use the model
        if (!inRoom || msg.model !== ed.model.id) return;
        if (msg.role === 'none') {
          this.room = null;
          ed.fail({ title: 'No access', detail: 'An owner took your access to this model away.' });
          ed.openModel(null);
          history.replaceState(null, '', location.pathname);
        } else {
          ed.setRole(msg.role);
          ed.notify(`You are now a${msg.role === 'owner' ? 'n' : ''} ${msg.role} of this model`);
        }
        break;
      case 'error':
        ed.fail(msg.problem || { title: 'Live connection error' });
        break;
      default: {
        // newer servers may add types; a registered tool may want them
        const handler = this.handlers.get(msg.type);
        if (handler) handler(msg, inRoom);
        break;
      }
    }
  }

  // Applies sequenced ops in order; a gap means we missed some, so ask for them.
  applyOps(ops) {
    const ed = this.editor;
    for (const entry of [...ops].sort((a, b) => a.version - b.version)) {
      if (!ed.model) return;
      if (entry.version > ed.model.version + 1) {
        ed.addHistory([entry]);
        this.hello();
        return;
      }
      ed.applyOp(entry);
    }
  }
}
