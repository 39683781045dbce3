// What a person does to a model (open, rename, add a note), carried out over REST and the
// live connection; the results land in the editor, which tells the views.
import { OP } from './opkinds.js';

export class Session {
  constructor(editor, api, live) {
    this.editor = editor;
    this.api = api;
    this.live = live;
    editor.signals.selectionChanged.add(() => live.presence());
    editor.signals.cameraChanged.add(() => live.presence());
  }

  async loadModels(more = false) {
    const ed = this.editor;
    try {
      const page = await this.api.listModels(more ? ed.nextPageToken : null);
      ed.setModels(page.items || [], page.next_page_token, more);
    } catch (err) {
      ed.fail(err);
    }
  }

  async open(id) {
    const ed = this.editor;
    if (ed.model && ed.model.id === id) return;
    this.wanted = id; // the latest click wins over slower earlier ones
    try {
      const model = await this.api.getModel(id);
      if (this.wanted !== id) return;
      ed.upsertModel(model);
      ed.openModel(model);
      if (location.hash !== `#model=${id}`) history.replaceState(null, '', `#model=${id}`);
      const [ops] = await Promise.all([
        this.loadOps(id, model.version).catch((err) => {
          ed.fail(err);
          return { items: [] };
        }),
        this.live.join(id).catch((err) => ed.fail({ title: 'Live connection unavailable', detail: err.message })),
      ]);
      if (ed.model && ed.model.id === id) {
        const items = ops.items || [];
        ed.addHistory(items);
        // Ops logged after the model was read: apply them (the room catches up the same way).
        for (const entry of items) if (entry.version > ed.model.version) this.live.applyOps([entry]);
      }
    } catch (err) {
      ed.fail(err);
    }
  }

  // The op log up to at least `version`, read in as many slices as the server cuts it into.
  async loadOps(id, version) {
    const items = [];
    let since = 0;
    for (;;) {
      const page = (await this.api.getOps(id, since)).items || [];
      items.push(...page);
      const last = page.length ? page[page.length - 1].version : since;
      if (!page.length || last >= version || last <= since) break;
      since = last;
    }
    return { items };
  }

  async rename(name) {
    const ed = this.editor;
    const clean = name.trim();
    if (!ed.model || !clean || clean === ed.model.name) {
      ed.refreshModel();
      return;
    }
    await ed.execute({ kind: OP.rename, name: clean });
  }

  async note(text) {
    const ed = this.editor;
    const clean = text.trim();
    if (!ed.model || !clean) return false;
    return (await ed.execute({ kind: OP.note, text: clean })) !== null;
  }
}
