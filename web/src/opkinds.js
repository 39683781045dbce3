// Every op kind this client sends (schema/websocket.md), and the groups of kinds it reacts to.
// The list below stays one array literal of double-quoted strings: a unit test of the service
// reads it and checks it against the server's op table and the schema documents.
export const OP_KINDS = ["rename", "note", "resize", "split", "join", "paste", "remove", "compose", "segment_roi", "mark_template", "undo", "redo", "restore", "plan", "profile"];

// Kinds the server logs itself (a proceduralize job, a grammar PUT); clients never send them.
export const SERVER_MADE = ['proceduralize', 'grammar', 'segment'];

const KNOWN = new Set([...OP_KINDS, ...SERVER_MADE]);
const unknown = (name) => new Error(`archgram: "${String(name)}" is not an op kind`);

// The kinds by name, where the client makes or tests an op: OP.resize is "resize", and a name
// that is not a kind (a typing mistake) throws where it is used instead of never matching.
export const OP = new Proxy(Object.freeze(Object.fromEntries([...KNOWN].map((k) => [k, k]))), {
  get(table, name) {
    if (typeof name === 'string' && !(name in table)) throw unknown(name);
    return table[name];
  },
});

// A set of known kinds; a name that is not a kind is a mistake in this client, caught at load.
export function kinds(...names) {
  for (const n of names) if (!KNOWN.has(n)) throw unknown(n);
  return new Set(names);
}

export const isSendable = (kind) => OP_KINDS.includes(kind);

// Structural edits of a proceduralized model (a composition of a part is one too).
export const STRUCTURAL = kinds('resize', 'split', 'join', 'paste', 'remove', 'compose');
// After these the model's mesh, tree and grammar must be read again.
export const REMESHING = kinds('proceduralize', 'grammar', ...STRUCTURAL, 'undo', 'redo', 'restore');
// Point cloud ops: each changes the segmentation (the segment and label of points).
export const SEGMENTING = kinds('segment', 'segment_roi', 'mark_template');
// After these a point cloud model's points.glb must be read again (undo and redo are logged
// as the restore they become).
export const RESEGMENTING = kinds(...SEGMENTING, 'undo', 'redo', 'restore');
// The kinds in a person's undo history (the server's undo works on these).
export const UNDOABLE = kinds(...STRUCTURAL, 'segment_roi', 'mark_template', 'restore', 'undo', 'redo');
// Extrusion edits: each re-extrudes the buildings it touches.
export const EXTRUSION = kinds('plan', 'profile');
