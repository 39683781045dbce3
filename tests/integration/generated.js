// Generated inputs shared by tests and benchmarks.

// A ring of 838 corners with a hip profile (a plan whose sweep takes a few hundred
// milliseconds): the extrusion preview load of the robustness tests and benchmarks.
export function plan838() {
  const pts = [];
  let seed = 7;
  const rnd = () => { seed = (seed * 1103515245 + 12345) % 2147483648; return seed / 2147483648; };
  for (let i = 0; i < 838; i++) {
    const a = (2 * Math.PI * i) / 838;
    const r = 40 + 3 * Math.sin(17 * a) + 1.5 * Math.sin(41 * a) + (rnd() - 0.5) * 0.6;
    pts.push([+(r * Math.cos(a)).toFixed(4), +(r * Math.sin(a)).toFixed(4)]);
  }
  return { profiles: { hip: { points: [[0, 0], [0, 6], [1, 7]] } }, default_profile: 'hip', loops: [{ points: pts }] };
}
