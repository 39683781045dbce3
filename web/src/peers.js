// Who else is in the open model's room, and what each has selected.
import { el } from './dom.js';

const COLOURS = ['#e07a5f', '#3d85c6', '#81b29a', '#c38bd6', '#f2cc8f', '#5fb3b3', '#e06c9f'];

// A person's colour: their dot here and their selection in the viewport.
export function colourOf(name) {
  let h = 0;
  for (const ch of name) h = (h * 31 + ch.codePointAt(0)) >>> 0;
  return COLOURS[h % COLOURS.length];
}

// What the others in the room have selected: component -> the colour (a '#rrggbb' string) of
// the first of them who has it.
export function peerSelections(peers) {
  const out = new Map();
  for (const p of peers.values()) {
    const sel = p.state?.selection;
    if (!Array.isArray(sel)) continue;
    const colour = colourOf(p.state?.name || p.user || p.peer);
    for (const c of sel) if (!out.has(c)) out.set(c, colour);
  }
  return out;
}

export class PeersPanel {
  constructor(editor, container) {
    this.editor = editor;
    this.list = el('ul.peers', { 'data-testid': 'peers' });
    container.append(el('h2', {}, 'In this model'), this.list);
    editor.signals.peersChanged.add(() => this.render());
    editor.signals.modelOpened.add(() => this.render());
    this.render();
  }

  render() {
    const ed = this.editor;
    if (!ed.model) {
      this.list.replaceChildren();
      return;
    }
    const peers = [...ed.peers.values()];
    if (!peers.length) {
      this.list.replaceChildren(el('li.empty', {}, 'Nobody else here'));
      return;
    }
    this.list.replaceChildren(
      ...peers.map((p) => {
        const name = p.state?.name || p.user || p.peer;
        const sel = p.state?.selection;
        const what = !Array.isArray(sel) || !sel.length
          ? 'no selection'
          : sel.length <= 3 ? `component ${sel.join(', ')}` : `${sel.length} components`;
        return el(
          'li.peer',
          { dataset: { peer: p.peer, colour: colourOf(name) } },
          el('span.dot', { style: `background:${colourOf(name)}` }),
          el('span.peer-name', {}, name),
          el('span.peer-sel', {}, what),
        );
      }),
    );
  }
}
