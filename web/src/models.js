// The model list: import (file input or drop), the import job's progress, the paged list.
import { el, timeAgo } from './dom.js';

export class ModelsPanel {
  constructor(editor, session, upload, container) {
    this.editor = editor;
    this.session = session;

    this.file = el('input', { type: 'file', 'data-testid': 'upload-input', accept: '.obj,.ply,.glb,.gltf,.stl,.fbx,.dae,.3ds,.las,.laz,.xyz' });
    this.up = el(
      'select.up',
      { title: 'Up axis of the file', 'aria-label': 'Up axis' },
      el('option', { value: '' }, 'up: auto'),
      el('option', { value: 'y' }, 'up: y'),
      el('option', { value: 'z' }, 'up: z'),
    );
    const send = (file) => {
      if (file) upload.run(file, { up: this.up.value || undefined });
    };
    this.file.addEventListener('change', () => {
      send(this.file.files[0]);
      this.file.value = '';
    });
    this.drop = el(
      'label.drop',
      { 'data-testid': 'drop-zone' },
      this.file,
      el('span.drop-main', {}, 'Import a mesh or point cloud'),
      el('span.drop-sub', {}, 'drop a file here or click to choose'),
    );
    for (const type of ['dragenter', 'dragover']) {
      this.drop.addEventListener(type, (e) => {
        e.preventDefault();
        this.drop.classList.add('over');
      });
    }
    this.drop.addEventListener('dragleave', () => this.drop.classList.remove('over'));
    this.drop.addEventListener('drop', (e) => {
      e.preventDefault();
      this.drop.classList.remove('over');
      send(e.dataTransfer?.files?.[0]);
    });

    this.bar = el('div.bar-fill');
    this.jobText = el('div.job-text');
    this.job = el('div.job', { 'data-testid': 'job', hidden: true }, el('div.bar', {}, this.bar), this.jobText);

    this.list = el('ul.models', { 'data-testid': 'model-list' });
    this.more = el('button.more', { type: 'button', 'data-testid': 'load-more', hidden: true }, 'Load more');
    this.more.addEventListener('click', () => session.loadModels(true));

    // viewer accounts make no models: no import for them
    this.importRow = el('div.import', {}, this.drop, this.up);
    container.append(
      el('h2', {}, 'Models'),
      this.importRow,
      this.job,
      this.list,
      this.more,
    );

    const s = editor.signals;
    s.modelsChanged.add(() => this.renderList());
    s.modelOpened.add(() => this.renderList());
    s.modelChanged.add(() => this.renderList());
    s.jobChanged.add((job) => this.renderJob(job));
    s.accountChanged.add((a) => {
      this.importRow.hidden = a?.role === 'viewer';
    });
  }

  renderList() {
    const ed = this.editor;
    const current = ed.model?.id;
    if (!ed.models.length) {
      this.list.replaceChildren(el('li.empty', {}, 'No models yet — import one.'));
    } else {
      this.list.replaceChildren(
        ...ed.models.map((m) => {
          const tris = m.stats?.triangles;
          return el(
            'li.model',
            {
              dataset: { id: m.id },
              'data-testid': 'model-item',
              tabIndex: 0,
              onclick: () => this.session.open(m.id),
              onkeydown: (e) => e.key === 'Enter' && this.session.open(m.id),
              className: `model${m.id === current ? ' active' : ''}`,
            },
            el('span.model-title', {}, m.name),
            el(
              'span.model-meta',
              {},
              `#${m.id} · v${m.version}`,
              tris != null ? ` · ${tris.toLocaleString()} tris` : '',
              m.updated_at ? ` · ${timeAgo(m.updated_at)}` : '',
            ),
          );
        }),
      );
    }
    this.more.hidden = !ed.nextPageToken;
  }

  renderJob(job) {
    if (!job) {
      this.job.hidden = true;
      return;
    }
    this.job.hidden = false;
    const p = Math.max(0, Math.min(1, job.progress ?? 0));
    const done = ['succeeded', 'failed', 'cancelled'].includes(job.status);
    this.bar.style.width = `${Math.round((done ? 1 : p) * 100)}%`;
    this.job.className = `job ${job.status}`;
    this.job.dataset.status = job.status;
    const stage = job.stage ? ` · ${job.stage}` : '';
    const pct = done ? '' : ` ${Math.round(p * 100)}%`;
    this.jobText.textContent = `${job.name ?? 'import'} — ${job.status}${stage}${pct}`;
  }
}
