// The facade the proceduralization and editing browser tests start from (y-up OBJ text): a wall
// slab and a cols × rows grid of identical boxed windows, a group each.
export function facadeObj(cols, rows) {
  const v = [];
  const f = [];
  const box = (name, x0, y0, z0, x1, y1, z1) => {
    f.push(`g ${name}`);
    const b = v.length + 1;
    for (const z of [z0, z1]) for (const y of [y0, y1]) for (const x of [x0, x1]) v.push(`v ${x} ${y} ${z}`);
    for (const q of [[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]]) {
      f.push(`f ${q.map((i) => b + i).join(' ')}`);
    }
  };
  box('wall', 0, 0, 0, 2.5 * cols + 0.5, 3.2 * rows + 0.6, 0.3);
  for (let j = 0; j < rows; j++) {
    for (let i = 0; i < cols; i++) box(`window_${j}_${i}`, 1 + 2.5 * i, 1 + 3.2 * j, 0.3, 2.3 + 2.5 * i, 2.86 + 3.2 * j, 0.5);
  }
  return `${v.join('\n')}\n${f.join('\n')}\n`;
}
