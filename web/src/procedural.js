// The open model's procedural side: runs the proceduralize job, keeps the split tree and the
// grammar current (after opening, and whenever a proceduralize or grammar op arrives, from
// anyone), and applies grammar edits.
import { isCloud } from './cloud.js';
import { SplitTree } from './splittree.js';
import { finished, followJob } from './jobs.js';

export class Procedural {
  constructor(editor, api, live) {
    this.editor = editor;
    this.api = api;
    this.live = live;
    this.token = 0;
    const s = editor.signals;
    s.modelOpened.add((model) => {
      this.token++;
      if (model?.proceduralized) this.reload();
    });
    s.meshChanged.add(() => this.reload({ model: true }));
  }

  get running() {
    const j = this.editor.procJob;
    return !!j && !finished(j);
  }

  // Reads the tree and the grammar (and, after a change, the model's figures) again.
  async reload({ model = false } = {}) {
    const ed = this.editor;
    if (!ed.model) return;
    const id = ed.model.id;
    const token = ++this.token;
    const current = () => token === this.token && ed.model?.id === id;
    const [tree, grammar, fresh] = await Promise.all([
      this.api.getTree(id).catch((err) => err),
      this.api.getGrammar(id).catch((err) => err),
      model ? this.api.getModel(id).catch(() => null) : null,
    ]);
    if (!current()) return;
    if (fresh) ed.updateModel(fresh);
    for (const r of [tree, grammar]) {
      // 404: not proceduralized (yet); the panels say so.
      if (r instanceof Error && r.status !== 404) ed.fail(r);
    }
    ed.setTree(tree instanceof Error ? null : new SplitTree(tree));
    ed.setGrammar(grammar instanceof Error ? null : grammar);
  }

  // Starts proceduralizing the open model and follows the job; the resulting op (over the
  // websocket, or read from the op log when that is down) reloads mesh, tree and grammar.
  async run() {
    const ed = this.editor;
    if (!ed.model || this.running) return;
    const { id, version } = ed.model;
    const name = ed.model.name;
    ed.setProcJob({ kind: 'proceduralize', status: 'queued', progress: 0, stage: null, model: id, name });
    let job;
    try {
      // a point cloud's template boxes, when the person marked some (cloud.js)
      job = await this.api.proceduralize(id, version, isCloud(ed.model) ? ed.cloud.procOptions() : {});
    } catch (err) {
      ed.setProcJob({ kind: 'proceduralize', status: 'failed', progress: 0, stage: null, model: id, name });
      ed.fail(err);
      return;
    }
    const mine = () => ed.model?.id === id;
    if (mine()) ed.setProcJob({ ...job, model: id, name });
    const done = await followJob(ed, this.api, this.live, job, (j) => {
      if (mine()) ed.setProcJob({ ...j, model: id, name });
    });
    if (!mine()) return;
    ed.setProcJob({ ...done, progress: done.status === 'succeeded' ? 1 : ed.procJob?.progress ?? 0, model: id, name });
    if (done.status === 'succeeded') {
      if (isCloud(ed.model)) ed.cloud.clearProcTemplates(); // they made this version
      await this.catchUp(id);
    } else if (done.status === 'failed') {
      ed.fail(done.error || { title: 'Proceduralization failed', detail: name });
    }
  }

  cancel() {
    const j = this.editor.procJob;
    if (!j?.id || finished(j)) return;
    this.api.cancelJob(j.id).catch((err) => this.editor.fail(err));
  }

  // Applies the ops logged after our version (ours among them); ops already applied are skipped.
  async catchUp(id) {
    const ed = this.editor;
    if (!ed.model || ed.model.id !== id) return;
    try {
      const page = await this.api.getOps(id, ed.model.version);
      if (ed.model?.id === id) this.live.applyOps(page.items || []);
    } catch (err) {
      ed.fail(err);
    }
  }

  // Replaces the grammar with `text`, edited from the grammar of version `base`.
  // Resolves with {ok: true}, {problem} (422: the line and column are in it) or {conflict}.
  async applyGrammar(text, base) {
    const ed = this.editor;
    if (!ed.model) return { problem: { title: 'No model is open' } };
    const { id } = ed.model;
    // If the grammar changed on the server since the edit began, claim the old version so
    // the server refuses (412) instead of silently overwriting someone else's grammar.
    const version = ed.grammar && base !== ed.grammar.version ? base : ed.model.version;
    try {
      await this.api.putGrammar(id, version, text);
    } catch (err) {
      const problem = err.problem || { title: 'Cannot apply the grammar', detail: err.message };
      // a conflict is told by the caller, who can offer the reload
      if (problem.status !== 412) ed.fail(problem);
      return { conflict: problem.status === 412, problem };
    }
    await this.catchUp(id);
    return { ok: true };
  }
}
