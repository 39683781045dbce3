// Problems and notices shown to the person: one banner for the latest problem (kept until
// dismissed or replaced by the next) and a
// short-lived notice line.
import { el } from './dom.js';

const NOTICE_MS = 4000;

export class Toast {
  constructor(editor, container) {
    this.count = 0;
    this.text = el('div.toast-text');
    this.close = el('button.toast-close', { type: 'button', title: 'Dismiss', 'aria-label': 'Dismiss' }, '×');
    this.banner = el('div.toast.error', { role: 'alert', 'data-testid': 'error', hidden: true }, this.text, this.close);
    this.close.addEventListener('click', () => {
      this.banner.hidden = true;
    });
    this.notice = el('div.toast.notice', { role: 'status', 'data-testid': 'notice', hidden: true });
    container.append(this.banner, this.notice);
    editor.signals.problem.add((p) => this.showProblem(p));
    editor.signals.notice.add((t) => this.showNotice(t));
    editor.signals.connectionChanged.add((state) => {
      // a lost connection that came back is no longer a problem
      if (state === 'online' && this.problemType === 'urn:archgram:problem:connection') this.banner.hidden = true;
    });
  }

  showProblem(p) {
    this.count += 1;
    let where = p.line ? ` (line ${p.line})` : p.element !== undefined && p.element !== null ? ` (element ${p.element})` : '';
    if (p.detail && where && p.detail.includes(where.slice(2, -1))) where = ''; // already said
    // A problem may offer one way out (e.g. reload what someone else changed).
    const action = p.action && typeof p.action.run === 'function'
      ? el('button.toast-action', {
        type: 'button',
        'data-testid': 'error-action',
        onclick: () => {
          this.banner.hidden = true;
          p.action.run();
        },
      }, p.action.label || 'Retry')
      : '';
    this.text.replaceChildren(
      el('strong', {}, p.title || 'Error'),
      p.status ? el('span.status', {}, ` ${p.status}`) : '',
      p.detail ? el('div.detail', {}, `${p.detail}${where}`) : where ? el('div.detail', {}, where) : '',
      action,
    );
    this.problemType = p.type;
    this.banner.title = p.type || '';
    this.banner.hidden = false;
    this.banner.classList.remove('flash');
    void this.banner.offsetWidth; // restart the animation for a repeated problem
    this.banner.classList.add('flash');
  }

  showNotice(text) {
    this.notice.textContent = text;
    this.notice.hidden = false;
    clearTimeout(this.timer);
    this.timer = setTimeout(() => {
      this.notice.hidden = true;
    }, NOTICE_MS);
  }
}
