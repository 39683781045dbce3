// The op kinds this client sends (the "kind" of an op message), one list for the whole client;
// the server's op table (server/app/optable.c) has a row for each, and a unit test keeps the
// two in step.
export const OP_KINDS = [
  'rename', 'note',
  'resize', 'split', 'join', 'paste', 'remove',
  'undo', 'redo', 'restore',
  'plan', 'profile',
];
