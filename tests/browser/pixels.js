// Reads a screenshot of the viewport canvas: which pixels show the model, and where to
// click to hit it or to miss it.
import { decodePng } from './png.js';

const MARGIN = 48; // a pixel shows the model when some channel is this far from the background

export async function readCanvas(page) {
  // Two animation frames: whatever was last drawn has been composited.
  await page.evaluate(() => new Promise((r) => requestAnimationFrame(() => requestAnimationFrame(r))));
  const canvas = page.locator('#viewport canvas');
  const { width, height, data } = decodePng(await canvas.screenshot());

  // The background is the most common colour of the view.
  const counts = new Map();
  for (let i = 0; i < data.length; i += 4) {
    const key = (data[i] << 16) | (data[i + 1] << 8) | data[i + 2];
    counts.set(key, (counts.get(key) || 0) + 1);
  }
  const bgKey = [...counts].sort((a, b) => b[1] - a[1])[0][0];
  const bg = [(bgKey >> 16) & 255, (bgKey >> 8) & 255, bgKey & 255];
  const differs = (x, y) => {
    const o = (y * width + x) * 4;
    return Math.max(Math.abs(data[o] - bg[0]), Math.abs(data[o + 1] - bg[1]), Math.abs(data[o + 2] - bg[2])) > MARGIN;
  };
  // A pixel with only model (or only background) pixels within r around it.
  const around = (x, y, r, want) => {
    for (let dy = -r; dy <= r; dy++) for (let dx = -r; dx <= r; dx++) if (differs(x + dx, y + dy) !== want) return false;
    return true;
  };

  let n = 0;
  let cx = 0;
  let cy = 0;
  for (let y = 0; y < height; y++) {
    for (let x = 0; x < width; x++) {
      if (differs(x, y)) {
        n++;
        cx += x;
        cy += y;
      }
    }
  }
  cx /= n || 1;
  cy /= n || 1;

  // The clicking spot: well inside the drawn model, nearest to the drawn pixels' centroid.
  let inside = null;
  let outside = null;
  for (let y = 6; y < height - 6; y += 2) {
    for (let x = 6; x < width - 6; x += 2) {
      if (around(x, y, 4, true)) {
        const d = (x - cx) ** 2 + (y - cy) ** 2;
        if (!inside || d < inside.d) inside = { x, y, d };
      } else if (!outside && around(x, y, 5, false)) {
        outside = { x, y };
      }
    }
  }
  const pixel = ({ x, y }) => {
    const o = (y * width + x) * 4;
    return [data[o], data[o + 1], data[o + 2]];
  };
  return {
    canvas,
    pixel,
    width,
    height,
    background: bg,
    fraction: n / (width * height),
    inside: inside && { x: inside.x, y: inside.y },
    outside,
  };
}

// How many pixels of a view pass test([r, g, b]).
export function countWhere(view, test) {
  let n = 0;
  for (let y = 0; y < view.height; y++) for (let x = 0; x < view.width; x++) if (test(view.pixel({ x, y }))) n++;
  return n;
}

// How many pixels differ by more than `margin` in some channel between two views of one size.
export function countChanged(a, b, margin = 40) {
  let n = 0;
  for (let y = 0; y < a.height; y++) {
    for (let x = 0; x < a.width; x++) {
      const p = a.pixel({ x, y });
      const q = b.pixel({ x, y });
      if (Math.max(Math.abs(p[0] - q[0]), Math.abs(p[1] - q[1]), Math.abs(p[2] - q[2])) > margin) n++;
    }
  }
  return n;
}

// A spot whose pixels within r all pass test, nearest to the middle of all passing pixels.
export function spotWhere(view, test, r = 3) {
  let n = 0;
  let cx = 0;
  let cy = 0;
  for (let y = 0; y < view.height; y++) {
    for (let x = 0; x < view.width; x++) {
      if (test(view.pixel({ x, y }))) {
        n++;
        cx += x;
        cy += y;
      }
    }
  }
  if (!n) return null;
  cx /= n;
  cy /= n;
  let best = null;
  for (let y = r; y < view.height - r; y++) {
    for (let x = r; x < view.width - r; x++) {
      if (!test(view.pixel({ x, y }))) continue;
      let all = true;
      for (let dy = -r; dy <= r && all; dy++) for (let dx = -r; dx <= r && all; dx++) all = test(view.pixel({ x: x + dx, y: y + dy }));
      if (!all) continue;
      const d = (x - cx) ** 2 + (y - cy) ** 2;
      if (!best || d < best.d) best = { x, y, d };
    }
  }
  return best && { x: best.x, y: best.y };
}

// Hue in degrees and saturation of an [r, g, b] colour.
export function hueOf([r, g, b]) {
  const max = Math.max(r, g, b);
  const min = Math.min(r, g, b);
  const d = max - min;
  const s = max ? d / max : 0;
  if (!d) return { h: 0, s };
  let h;
  if (max === r) h = ((g - b) / d) % 6;
  else if (max === g) h = (b - r) / d + 2;
  else h = (r - g) / d + 4;
  return { h: (h * 60 + 360) % 360, s };
}
