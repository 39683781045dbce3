// Importing a file: upload it, follow the import job (websocket job.progress, or polling
// when the live connection is unavailable), then list and open the new model.
const POLL_MS = 300;
const POLL_BACKSTOP_MS = 2000; // also poll, slowly, while the websocket reports

export function formatOf(fileName) {
  const dot = fileName.lastIndexOf('.');
  return dot > 0 ? fileName.slice(dot + 1).toLowerCase() : '';
}

export class Upload {
  constructor(editor, api, live, session) {
    this.editor = editor;
    this.api = api;
    this.live = live;
    this.session = session;
  }

  async run(file, { up } = {}) {
    const ed = this.editor;
    const format = formatOf(file.name);
    if (!format) {
      ed.fail({ title: 'Unknown file type', detail: `${file.name} has no extension to tell its format` });
      return;
    }
    const name = file.name.replace(/\.[^.]*$/, '') || file.name;
    ed.setJob({ status: 'uploading', progress: 0, stage: 'upload', name: file.name });
    let job;
    try {
      job = await this.api.uploadModel(file, { name, format, up }, (f) =>
        ed.setJob({ status: 'uploading', progress: f, stage: 'upload', name: file.name }),
      );
    } catch (err) {
      ed.setJob({ status: 'failed', progress: 0, stage: 'upload', name: file.name });
      ed.fail(err);
      return;
    }
    ed.setJob({ ...job, name: file.name });
    const done = await this.follow(job, file.name);
    if (done.status === 'succeeded') {
      const id = done.result?.model;
      await this.session.loadModels();
      if (id != null) await this.session.open(id);
      ed.setJob({ ...done, name: file.name });
    } else {
      ed.setJob({ ...done, name: file.name });
      const problem = done.error || { title: `Import ${done.status}`, detail: file.name };
      ed.fail(problem);
    }
  }

  // Resolves with the finished job ({status, result, error}).
  follow(job, fileName) {
    const ed = this.editor;
    const id = job.id;
    return new Promise((resolve) => {
      let finished = false;
      let timer = 0;
      let lastLive = 0;
      const finish = (j) => {
        if (finished) return;
        finished = true;
        clearTimeout(timer);
        this.live.unwatch(id);
        resolve(j);
      };
      const update = (j) => {
        if (finished) return;
        if (['succeeded', 'failed', 'cancelled'].includes(j.status)) finish(j);
        else ed.setJob({ ...j, name: fileName });
      };
      const poll = async () => {
        if (finished) return;
        const quiet = Date.now() - lastLive;
        if (!this.live.open || quiet >= POLL_BACKSTOP_MS) {
          try {
            update(await this.api.getJob(id));
          } catch (err) {
            ed.fail(err);
            finish({ ...job, status: 'failed', error: err.problem });
            return;
          }
        }
        if (!finished) timer = setTimeout(poll, this.live.open ? POLL_BACKSTOP_MS : POLL_MS);
      };
      this.live.connect().catch(() => {
        // polling carries on alone
      });
      this.live.watch(id, (msg) => {
        lastLive = Date.now();
        if (msg.type === 'job.done') finish({ id, status: msg.status, result: msg.result, error: msg.error });
        else update({ id, status: msg.status, progress: msg.progress, stage: msg.stage });
      });
      timer = setTimeout(poll, POLL_MS);
    });
  }
}
