// Collapsible panel sections: a section's heading folds it away; the choice is remembered.
const KEY = 'archgram.collapsed';

function load() {
  try {
    return new Set(JSON.parse(localStorage.getItem(KEY) || '[]'));
  } catch {
    return new Set();
  }
}

function save(set) {
  try {
    localStorage.setItem(KEY, JSON.stringify([...set]));
  } catch {
    // storage disabled: the choice lasts for this visit
  }
}

// Makes each section's first h2 a toggle; sections are told apart by their id.
export function collapsible(sections) {
  const folded = load();
  for (const section of sections) {
    const head = section.querySelector(':scope > h2');
    if (!head || !section.id) continue;
    head.classList.add('fold');
    head.tabIndex = 0;
    head.setAttribute('role', 'button');
    const set = (on) => {
      section.classList.toggle('collapsed', on);
      head.setAttribute('aria-expanded', on ? 'false' : 'true');
    };
    set(folded.has(section.id));
    const flip = () => {
      const on = !section.classList.contains('collapsed');
      set(on);
      if (on) folded.add(section.id);
      else folded.delete(section.id);
      save(folded);
    };
    head.addEventListener('click', flip);
    head.addEventListener('keydown', (e) => {
      if (e.key === 'Enter' || e.key === ' ') {
        e.preventDefault();
        flip();
      }
    });
  }
}
