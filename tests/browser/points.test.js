// Point clouds in the web client against a real archgramd in Debian's chromium: a LAZ upload
// through the page is drawn as points, the point budget changes how many, the segment job
// runs from the panel, colouring switches between segment and label, clicking a point picks
// the segment the server gave it (checked against points.ply), and box drags send an ROI
// op that segments again and a template op — both acknowledged, each a new version whose
// points the page then shows.
import assert from 'node:assert/strict';
import path from 'node:path';
import { test } from 'node:test';
import { parsePly } from '../integration/clouds.js';
import { daemonAndBrowser, openPage } from './browser.js';
import { ROOT } from './daemon.js';
import { uploadAndOpen, versionOf, WAIT, waitVersion } from './page.js';
import { countChanged, countWhere, readCanvas } from './pixels.js';

const FIXTURE = path.join(ROOT, 'tests', 'data', 'points', 'box_walls.laz'); // 3000 points, 5 faces
const POINTS = 3000;

const env = daemonAndBrowser();
const api = async (p, init) => fetch(`${env.daemon.url}api/v1${p}`, init);

const yellow = ([r, g, b]) => r - b > 90 && g - b > 60; // the picked segment's colour
const drawn = (page) => page.evaluate(() => Number(document.getElementById('viewport').dataset.points ?? -1));
const waitDrawn = (page, n) =>
  page.waitForFunction((want) => document.getElementById('viewport').dataset.points === String(want), n, WAIT);
// The viewport shows the points of version v.
const waitPoints = (page, v) => page.locator(`#viewport[data-version="${v}"][data-points]`).waitFor({ state: 'attached', ...WAIT });

async function pointsPly(id) {
  const res = await api(`/models/${id}/points.ply`);
  assert.equal(res.status, 200, await res.clone().text());
  return parsePly(Buffer.from(await res.arrayBuffer()));
}

// Drags with the left button from a to b (canvas pixels), in steps.
async function drag(page, canvas, a, b) {
  const box = await canvas.boundingBox();
  await page.mouse.move(box.x + a.x, box.y + a.y);
  await page.mouse.down();
  for (let i = 1; i <= 8; i++) await page.mouse.move(box.x + a.x + ((b.x - a.x) * i) / 8, box.y + a.y + ((b.y - a.y) * i) / 8);
  await page.mouse.up();
}

// The newest logged op, which must be `kind` by `author` at `version`.
async function lastOp(id, kind, author, version) {
  const items = (await (await api(`/models/${id}/ops`)).json()).items;
  const e = items[items.length - 1];
  assert.equal(e.op.kind, kind, JSON.stringify(e));
  assert.equal(e.author, author);
  assert.equal(e.version, version);
  return e;
}

test('a point cloud: drawn with a budget, segmented, coloured by segment or label, picked, and refined by ROI and template boxes', async () => {
  const page = await openPage(env.browser, { user: 'pia' });
  await page.goto(env.daemon.url);
  const id = await uploadAndOpen(page, 'upload-input', FIXTURE);
  const model = await (await api(`/models/${id}`)).json();
  assert.equal(model.kind, 'pointcloud');
  assert.equal(model.stats.points, POINTS);

  // every point is drawn (the budget is larger), and they show on the canvas
  await waitDrawn(page, POINTS);
  await page.getByTestId('cloud-shown').filter({ hasText: `${POINTS.toLocaleString('en')} of ${POINTS.toLocaleString('en')} points drawn` }).waitFor(WAIT);
  const all = await readCanvas(page);
  assert.ok(all.fraction > 0.003, `only ${(all.fraction * 100).toFixed(3)}% of the canvas shows points`);
  assert.ok(all.fraction < 0.9);
  await page.getByTestId('cloud-figures').filter({ hasText: 'not segmented' }).waitFor(WAIT);

  // a smaller budget draws fewer points: the first 500 of the server's order
  await page.getByTestId('cloud-budget').fill('500');
  await page.getByTestId('cloud-budget').press('Tab');
  await waitDrawn(page, 500);
  const few = await readCanvas(page);
  assert.ok(few.fraction > 0 && few.fraction < all.fraction * 0.6, `500 points cover ${few.fraction}, 3000 cover ${all.fraction}`);
  // a budget the server would refuse is told, and the budget in force stays
  await page.getByTestId('cloud-budget').fill('0');
  await page.getByTestId('cloud-budget').press('Tab');
  await page.getByTestId('error').filter({ hasText: 'Not a point budget' }).waitFor({ state: 'visible', ...WAIT });
  assert.equal(await drawn(page), 500);
  assert.equal(await page.getByTestId('cloud-budget').inputValue(), '500');
  await page.getByTestId('cloud-budget').fill('3000');
  await page.getByTestId('cloud-budget').press('Tab');
  await waitDrawn(page, POINTS);

  // the segment job from the panel: a new version, its points shown coloured by segment
  const v0 = await versionOf(page);
  await page.getByTestId('cloud-segment').click();
  await page.locator('[data-testid="cloud-job"][data-status="succeeded"]').waitFor(WAIT);
  await waitVersion(page, v0 + 1);
  await waitPoints(page, v0 + 1);
  const segmented = await lastOp(id, 'segment', 'pia', v0 + 1);
  assert.ok(segmented.op.report.planes >= 5, JSON.stringify(segmented.op.report));
  await page.getByTestId('cloud-figures').filter({ hasText: `${segmented.op.report.segments} segments` }).waitFor(WAIT);
  await page.locator('#viewport[data-colour-by="segment"]').waitFor({ state: 'attached', ...WAIT });
  await page.waitForFunction(() => !/not segmented/.test(document.getElementById('inspector').textContent), null, WAIT);
  const bySegment = await readCanvas(page);
  assert.ok(countChanged(all, bySegment) > 100, 'segment colours did not change the view');

  // colour by label, and back
  await page.getByTestId('cloud-colour').selectOption('label');
  await page.locator('#viewport[data-colour-by="label"]').waitFor({ state: 'attached', ...WAIT });
  const byLabel = await readCanvas(page);
  assert.ok(countChanged(bySegment, byLabel) > 100, 'label colours look like segment colours');
  await page.getByTestId('cloud-colour').selectOption('segment');
  await page.locator('#viewport[data-colour-by="segment"]').waitFor({ state: 'attached', ...WAIT });

  // click the drawn point nearest the camera: its segment is the one points.ply gives it
  const target = await page.evaluate(() => {
    const vp = window.archgramTools.viewport;
    const pts = vp.layers.model.points[0];
    const pos = pts.geometry.getAttribute('position');
    const P = pts.position.clone(); // a THREE.Vector3 (three is not a global of the page)
    let best = null;
    for (let i = 0; i < pos.count; i++) {
      P.fromBufferAttribute(pos, i).applyMatrix4(pts.matrixWorld);
      const d = P.distanceTo(vp.camera.position);
      if (!best || d < best.d) best = { d, world: [P.x, P.y, P.z] };
    }
    P.set(...best.world);
    const s = vp.toScreen(P);
    return { screen: s, model: [best.world[0], -best.world[2], best.world[1]] };
  });
  const canvas = page.locator('#viewport canvas');
  await canvas.click({ position: { x: Math.round(target.screen.x), y: Math.round(target.screen.y) } });
  await page.getByTestId('cloud-picked').filter({ hasText: /segment \d+/ }).waitFor(WAIT);
  const picked = Number(/segment (\d+)/.exec(await page.getByTestId('cloud-picked').textContent())[1]);
  const ply = await pointsPly(id);
  let nearest = -1, nd = Infinity;
  for (let i = 0; i < ply.n; i++) {
    const d = Math.hypot(ply.props.x[i] - target.model[0], ply.props.y[i] - target.model[1], ply.props.z[i] - target.model[2]);
    if (d < nd) { nd = d; nearest = i; }
  }
  assert.ok(nd < 1e-3, `the clicked point is ${nd} m from every stored point`);
  assert.equal(picked, ply.props.segment[nearest], 'the picked segment is not the clicked point\'s');
  const lit = await readCanvas(page);
  const litCount = countWhere(lit, yellow);
  const members = ply.props.segment.filter((s) => s === picked).length;
  assert.ok(litCount > 0 && members > 0, `segment ${picked} (${members} points) drawn in ${litCount} yellow pixels`);

  // a second person in the room, who only watches
  const bo = await openPage(env.browser, { user: 'bo' });
  await bo.goto(`${env.daemon.url}#model=${id}`);
  await bo.getByTestId('peers').filter({ hasText: 'pia' }).waitFor(WAIT);
  await waitPoints(bo, await versionOf(page));

  // an ROI box dragged over the middle of the view: acked, logged, the points of the new
  // version shown (to the other person too); the box holds the points points.ply has inside it
  await page.getByTestId('cloud-roi').click();
  await page.locator('#viewport[data-cloud-tool="roi"]').waitFor({ state: 'attached', ...WAIT });
  const w = lit.width, h = lit.height;
  const v1 = await versionOf(page);
  await drag(page, canvas, { x: Math.round(w * 0.3), y: Math.round(h * 0.3) }, { x: Math.round(w * 0.7), y: Math.round(h * 0.7) });
  await waitVersion(page, v1 + 1);
  await waitPoints(page, v1 + 1);
  const roi = await lastOp(id, 'segment_roi', 'pia', v1 + 1);
  await waitPoints(bo, v1 + 1);
  const b = roi.op.box;
  assert.equal(b.length, 6);
  let inside = 0;
  for (let i = 0; i < ply.n; i++) {
    const p = [ply.props.x[i], ply.props.y[i], ply.props.z[i]];
    if (p.every((v, k) => v >= b[k] && v <= b[3 + k])) inside++;
  }
  assert.ok(inside > 100, `the ROI box ${JSON.stringify(b)} holds ${inside} points`);
  assert.equal(roi.op.report.inside, inside, JSON.stringify(roi.op.report));
  assert.equal(await page.evaluate(() => document.getElementById('viewport').dataset.cloudTool ?? null), null, 'the tool stays on');

  // a template box on a picked segment: the roof, whose points are drawn nearest the camera
  const after = await pointsPly(id);
  await canvas.click({ position: { x: Math.round(target.screen.x), y: Math.round(target.screen.y) } });
  await page.waitForFunction(() => document.getElementById('viewport').dataset.segment !== undefined, null, WAIT);
  const seg = Number(await page.evaluate(() => document.getElementById('viewport').dataset.segment));
  const v2 = await versionOf(page);
  await page.getByTestId('cloud-template').click();
  const t = { x: target.screen.x, y: target.screen.y };
  await drag(page, canvas, { x: Math.round(t.x - w * 0.12), y: Math.round(t.y - h * 0.12) }, { x: Math.round(t.x + w * 0.12), y: Math.round(t.y + h * 0.12) });
  await waitVersion(page, v2 + 1);
  await waitPoints(page, v2 + 1);
  const tmpl = await lastOp(id, 'mark_template', 'pia', v2 + 1);
  assert.equal(tmpl.op.segment, seg);
  const tb = tmpl.op.box;
  let members2 = 0;
  for (let i = 0; i < after.n; i++) {
    const p = [after.props.x[i], after.props.y[i], after.props.z[i]];
    if (after.props.segment[i] === seg && p.every((v, k) => v >= tb[k] && v <= tb[3 + k])) members2++;
  }
  assert.ok(members2 >= 10, `the template box holds ${members2} points of segment ${seg}`);
  assert.equal(tmpl.op.report.template_points, members2, JSON.stringify(tmpl.op.report));
  console.log(`# points drawn cover ${(all.fraction * 100).toFixed(2)}% of the view (500: ${(few.fraction * 100).toFixed(2)}%); ` +
    `segment ${picked} lit in ${litCount} pixels; ROI box held ${inside} points, ${roi.op.report.segments_before} → ${roi.op.report.segments} segments; ` +
    `template of ${members2} points, ${tmpl.op.report.copies} copies`);
  await waitPoints(bo, v2 + 1);
  assert.deepEqual(page.problems.filter((p) => !/Not a point budget/.test(p)), [], 'the page reported errors');
  assert.deepEqual(bo.problems, [], 'the second page reported errors');
});
