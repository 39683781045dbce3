// The facade the proceduralization and editing browser tests start from: the integration
// tests' facade with its wall sized to the window grid.
import { facadeObj as facade } from '../integration/harness.js';

export const facadeObj = (cols, rows) => facade(cols, rows, [2.5 * cols + 0.5, 3.2 * rows + 0.6]);
