// Making a model from a file: a mesh or a point cloud (PLY, LAS, LAZ, XYZ) to import, or footprints (GeoJSON) / a building
// description to extrude. The file is uploaded, its job followed (websocket job.progress, or
// polling when the live connection is unavailable), then the new model is listed and opened.
import { followJob } from './jobs.js';

export function formatOf(fileName) {
  const dot = fileName.lastIndexOf('.');
  return dot > 0 ? fileName.slice(dot + 1).toLowerCase() : '';
}

const baseName = (file) => file.name.replace(/\.[^.]*$/, '') || file.name;

export class Upload {
  constructor(editor, api, live, session) {
    this.editor = editor;
    this.api = api;
    this.live = live;
    this.session = session;
  }

  // A mesh or point cloud file → an import job.
  run(file, { up } = {}) {
    const format = formatOf(file.name);
    if (!format) {
      this.editor.fail({ title: 'Unknown file type', detail: `${file.name} has no extension to tell its format` });
      return Promise.resolve(null);
    }
    return this.follow(file, 'Import', (progress) =>
      this.api.uploadModel(file, { name: baseName(file), format, up }, progress));
  }

  // Footprints or a plan and a style → an extrude job (a model of kind "extrusion").
  extrusion(file, style) {
    return this.follow(file, 'Extrusion', () => this.api.uploadExtrusion(file, { name: baseName(file), style }));
  }

  // Starts the job with start(onProgress), follows it and opens the model it made; resolves
  // with the finished job (or null when the upload itself failed).
  async follow(file, what, start) {
    const ed = this.editor;
    const show = (job) => ed.setJob({ ...job, name: file.name });
    show({ status: 'uploading', progress: 0, stage: 'upload' });
    let job;
    try {
      job = await start((f) => show({ status: 'uploading', progress: f, stage: 'upload' }));
    } catch (err) {
      show({ status: 'failed', progress: 0, stage: 'upload' });
      ed.fail(err);
      return null;
    }
    show(job);
    const done = await followJob(ed, this.api, this.live, job, show);
    if (done.status === 'succeeded') {
      const id = done.result?.model;
      await this.session.loadModels();
      if (id != null) await this.session.open(id);
      show(done);
    } else {
      show(done);
      ed.fail(done.error || { title: `${what} ${done.status}`, detail: file.name });
    }
    return done;
  }
}
