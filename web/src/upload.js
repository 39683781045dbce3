// Importing a file: upload it, follow the import job (websocket job.progress, or polling
// when the live connection is unavailable), then list and open the new model.
import { followJob } from './jobs.js';

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
    const done = await followJob(ed, this.api, this.live, job, (j) => ed.setJob({ ...j, name: file.name }));
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
}
