// Extrusions in the web client against a real archgramd in Debian's chromium: a footprint
// batch uploaded into a city view, a building picked in 3D and edited in the plan editor
// (live preview while dragging, a plan op on release), a profile point dragged (the roof
// changes), an invalid edit refused and reverted, and the failed footprint in the report.
import assert from 'node:assert/strict';
import path from 'node:path';
import { test } from 'node:test';
import { ROOT } from './daemon.js';
import { daemonAndBrowser, openPage } from './browser.js';
import { centre, uploadAndOpen, versionOf, WAIT, waitMesh, waitVersion } from './page.js';
import { countChanged, readCanvas } from './pixels.js';

const FIXTURE = path.join(ROOT, 'tests', 'data', 'extrude_web', 'city.geojson');

const env = daemonAndBrowser();

const api = async (p, init) => fetch(`${env.daemon.url}api/v1${p}`, init);
const getJson = async (p) => {
  const res = await api(p);
  assert.equal(res.status, 200, `${p}: ${res.status}`);
  return res.json();
};

// Presses at `from`, moves by (dx, dy) in steps (so several previews go out), and waits for
// a preview to be drawn before releasing.
async function dragWithPreview(page, from, dx, dy) {
  const before = Number((await page.locator('#viewport').getAttribute('data-extrude-preview')) ?? 0);
  const previews = [];
  const onRequest = (r) => {
    if (r.url().endsWith('/api/v1/extrusions/preview') && r.method() === 'POST') previews.push(Date.now());
  };
  page.on('request', onRequest);
  await page.mouse.move(from.x, from.y);
  await page.mouse.down();
  const steps = 8;
  for (let i = 1; i <= steps; i++) {
    await page.mouse.move(from.x + (dx * i) / steps, from.y + (dy * i) / steps);
    await page.waitForTimeout(40);
  }
  return {
    previews,
    async shown() {
      await page.waitForFunction((n) => Number(document.getElementById('viewport').dataset.extrudePreview ?? 0) > n, before, WAIT);
    },
    async release() {
      await page.mouse.up();
      page.off('request', onRequest);
    },
  };
}

test('a footprint batch in the city view, edited in the plan and profile editors', async () => {
  const page = await openPage(env.browser, { user: 'carol' });
  await page.goto(env.daemon.url);

  // Upload: the extrude job runs and the new model opens.
  await page.getByTestId('extrude-style').selectOption('hip');
  const id = await uploadAndOpen(page, 'extrude-input', FIXTURE);
  const model = await getJson(`/models/${id}`);
  assert.equal(model.kind, 'extrusion');
  const v0 = model.version;
  await waitMesh(page, v0);

  // The city view: the whole batch is on screen, coloured by height.
  const city = await readCanvas(page);
  assert.ok(city.fraction > 0.01, `only ${(city.fraction * 100).toFixed(2)}% of the view shows buildings`);
  await page.getByTestId('city-summary').filter({ hasText: '4 footprints' }).waitFor(WAIT);

  // The report lists the footprint that failed, with the server's reason.
  const plan0 = await getJson(`/models/${id}/plan`);
  const bad = plan0.buildings.find((b) => b.id === 'bowtie');
  assert.equal(bad.status, 'failed');
  assert.ok(bad.reason);
  const failed = page.getByTestId('failed-footprint');
  assert.equal(await failed.count(), 1);
  assert.equal(await failed.getAttribute('data-id'), 'bowtie');
  assert.match(await failed.textContent(), new RegExp(bad.reason.replace(/[.*+?^${}()|[\]\\]/g, '\\$&')));

  // Clicking a building in 3D opens it in the plan editor.
  assert.ok(city.inside, 'no spot inside a building');
  await city.canvas.click({ position: city.inside });
  await page.getByTestId('plan-corner').first().waitFor(WAIT);
  const title = await page.getByTestId('plan-title').textContent();
  const picked = plan0.buildings.findIndex((b) => title.includes(`building ${b.id}`));
  assert.ok(picked >= 0 && plan0.buildings[picked].status === 'ok', `plan editor title: ${title}`);
  const building = plan0.buildings[picked];
  const corners = page.getByTestId('plan-corner');
  assert.equal(await corners.count(), building.plan.loops.reduce((n, l) => n + (Array.isArray(l) ? l : l.points).length, 0));

  // Drag a corner outwards: previews are requested and drawn in place of the building.
  const picked3d = await readCanvas(page); // the building is highlighted now
  const corner = corners.nth(2);
  const drag = await dragWithPreview(page, await centre(corner), 25, -20);
  await drag.shown();
  assert.ok(drag.previews.length >= 1, 'no preview request while dragging');
  // At most ~10 a second: the page starts one every 100 ms at most; the browser's request
  // events jitter by some tens of ms, so the mean gap is what is checked closely.
  const gaps = drag.previews.slice(1).map((t, i) => t - drag.previews[i]);
  const mean = gaps.reduce((x, g) => x + g, 0) / (gaps.length || 1);
  assert.ok(gaps.every((g) => g >= 40) && (!gaps.length || mean >= 85), `preview requests ${gaps.join(', ')} ms apart`);
  const previewed = await readCanvas(page);
  const changed = countChanged(picked3d, previewed);
  assert.ok(changed > 50, `the preview changed ${changed} pixels`);
  await drag.release();

  // Release: one plan op, version + 1 on the server, the stored corner moved.
  await waitVersion(page, v0 + 1);
  await waitMesh(page, v0 + 1);
  assert.equal((await getJson(`/models/${id}`)).version, v0 + 1);
  const plan1 = await getJson(`/models/${id}/plan`);
  const loop0 = (p) => (Array.isArray(p.loops[0]) ? p.loops[0] : p.loops[0].points);
  const before2 = loop0(building.plan)[2];
  const after2 = loop0(plan1.buildings[picked].plan)[2];
  assert.ok(after2[0] > before2[0] + 0.5 && after2[1] > before2[1] + 0.5, `corner 2 moved from ${before2} to ${after2}`);
  const ops = await getJson(`/models/${id}/ops`);
  assert.equal(ops.items.at(-1).op.kind, 'plan');
  assert.equal(ops.items.at(-1).op.building, picked);

  // Edit a profile point: the roof's top point dragged up makes the roof steeper.
  const profileName = await page.getByTestId('profile-select').inputValue();
  const pointsBefore = plan1.buildings[picked].plan.profiles[profileName];
  const ptsBefore = Array.isArray(pointsBefore) ? pointsBefore : pointsBefore.points;
  const top = page.getByTestId('profile-point').nth(ptsBefore.length - 1);
  const roofBefore = await readCanvas(page);
  const pdrag = await dragWithPreview(page, await centre(top), -6, -45);
  await pdrag.shown();
  await pdrag.release();
  await waitVersion(page, v0 + 2);
  await waitMesh(page, v0 + 2);
  const roofAfter = await readCanvas(page);
  const roofChanged = countChanged(roofBefore, roofAfter);
  assert.ok(roofChanged > 50, `the profile edit changed ${roofChanged} pixels`);
  const plan2 = await getJson(`/models/${id}/plan`);
  const p2 = plan2.buildings[picked].plan.profiles[profileName];
  const ptsAfter = Array.isArray(p2) ? p2 : p2.points;
  assert.ok(ptsAfter.at(-1)[1] > ptsBefore.at(-1)[1] + 0.3, `top point ${ptsBefore.at(-1)} → ${ptsAfter.at(-1)}`);
  // Only that building changed: the others keep their profiles.
  for (const [i, b] of plan2.buildings.entries()) {
    if (i !== picked) assert.deepEqual(b.plan, plan1.buildings[i].plan, `building ${b.id} changed`);
  }

  // An invalid edit: dragging a corner across the far side makes the ring cross itself. The
  // preview says why, the op is refused on release and the plan editor reverts.
  const pts2 = loop0(plan2.buildings[picked].plan);
  // Corner 0 goes past corner 1 by the first edge's length, level with the second edge's
  // middle: the closing edge then crosses the second (or a later) edge.
  const c0 = await centre(corners.nth(0));
  const c1 = await centre(corners.nth(1));
  const c2 = await centre(corners.nth(2));
  const cross = await dragWithPreview(page, c0, 2 * (c1.x - c0.x) + (c2.x - c1.x) / 2, 2 * (c1.y - c0.y) + (c2.y - c1.y) / 2);
  await page.getByTestId('plan-status').and(page.locator('[data-state="failed"]')).waitFor(WAIT);
  const reason = await page.getByTestId('plan-status').textContent();
  assert.ok(reason.length > 5, `preview reason: ${reason}`);
  await cross.release();
  const banner = page.getByTestId('error');
  await banner.waitFor({ state: 'visible', ...WAIT });
  await page.waitForFunction(
    ([x, y]) => {
      const c = document.querySelector('[data-testid="plan-corner"][data-index="0"]');
      return c && Math.abs(Number(c.getAttribute('cx')) - x) < 3 && Math.abs(Number(c.getAttribute('cy')) - y) < 3;
    },
    [c0.x - (await page.getByTestId('plan-editor').boundingBox()).x, c0.y - (await page.getByTestId('plan-editor').boundingBox()).y],
    WAIT,
  );
  assert.equal(await versionOf(page), v0 + 2);
  assert.deepEqual(loop0((await getJson(`/models/${id}/plan`)).buildings[picked].plan), pts2);

  // Double-clicking an edge inserts a corner (a plan op); Delete removes it again.
  let v = v0 + 2;
  const n0 = await corners.count();
  // (edge lines can be horizontal, zero-height boxes: aim between their corners instead)
  const mid0 = async () => {
    const [a, b] = [await centre(corners.nth(0)), await centre(corners.nth(1))];
    return { x: (a.x + b.x) / 2, y: (a.y + b.y) / 2 };
  };
  let m = await mid0();
  await page.mouse.dblclick(m.x, m.y);
  await waitVersion(page, ++v);
  await page.waitForFunction((n) => document.querySelectorAll('[data-testid="plan-corner"]').length === n, n0 + 1, WAIT);
  assert.equal(loop0((await getJson(`/models/${id}/plan`)).buildings[picked].plan).length, n0 + 1);
  assert.equal(await page.locator('[data-testid="plan-corner"].selected').getAttribute('data-index'), '1');
  await page.keyboard.press('Delete');
  await waitVersion(page, ++v);
  await page.waitForFunction((n) => document.querySelectorAll('[data-testid="plan-corner"]').length === n, n0, WAIT);
  assert.deepEqual(loop0((await getJson(`/models/${id}/plan`)).buildings[picked].plan), pts2);

  // An anchor placed at the middle of edge 0, 1.5 m up.
  await page.getByTestId('anchor-height').fill('1.5');
  await page.getByTestId('anchor-mode').click();
  m = await mid0();
  await page.mouse.click(m.x, m.y);
  await waitVersion(page, ++v);
  await page.getByTestId('plan-anchor').waitFor(WAIT);
  const anchors = (await getJson(`/models/${id}/plan`)).buildings[picked].plan.anchors;
  assert.equal(anchors.length, 1);
  assert.equal(anchors[0].edge, 0);
  assert.equal(anchors[0].height, 1.5);
  assert.ok(Math.abs(anchors[0].relative - 0.5) < 0.05, `anchor at ${anchors[0].relative} of the edge`);

  // Insert overhang at the eave: every profile of the building gets the same outward
  // horizontal segment at the same height (§3.3), in one plan op.
  const eaveZ = ptsAfter[1][1];
  await page.getByTestId('profile-point').nth(1).click();
  await page.getByTestId('overhang-width').fill('0.5');
  const roofFlat = await readCanvas(page);
  await page.getByTestId('insert-overhang').click();
  await waitVersion(page, ++v);
  await waitMesh(page, v);
  const plan3 = await getJson(`/models/${id}/plan`);
  for (const [name, prof] of Object.entries(plan3.buildings[picked].plan.profiles)) {
    const pts = Array.isArray(prof) ? prof : prof.points;
    const i = pts.findIndex((p, k) => k + 1 < pts.length && p[1] === eaveZ && pts[k + 1][1] === eaveZ);
    assert.ok(i > 0, `profile ${name} has no horizontal segment at ${eaveZ} m: ${JSON.stringify(pts)}`);
    assert.ok(Math.abs(pts[i + 1][0] - pts[i][0] + 0.5) < 1e-9, `profile ${name}: ${JSON.stringify(pts)}`);
  }
  assert.equal(plan3.buildings[picked].status, 'ok');
  assert.ok(countChanged(roofFlat, await readCanvas(page)) > 20, 'the overhang did not show');

  // The failed footprint opens in the plan editor from the report.
  await failed.click();
  await page.getByTestId('plan-title').filter({ hasText: 'bowtie' }).waitFor(WAIT);
  assert.equal(await corners.count(), 4);

  // The only logged problems are the browser's notes on the refused preview and op.
  const refused = /Failed to load resource: the server responded with a status of 422\b/;
  assert.deepEqual(page.problems.filter((p) => !refused.test(p)), [], page.problems.join('\n'));
});

test('one building from a plan: its anchor, a profile assigned to an edge, a profile op others see', async () => {
  const alice = await openPage(env.browser, { user: 'alice' });
  await alice.goto(env.daemon.url);
  const id = await uploadAndOpen(alice, 'extrude-input', path.join(ROOT, 'tests', 'data', 'extrude_web', 'house_plan.json'));
  const v0 = (await getJson(`/models/${id}`)).version;
  await waitMesh(alice, v0);

  // A single building is in the plan editor at once, with the anchor its plan has.
  const corners = alice.getByTestId('plan-corner');
  await corners.first().waitFor(WAIT);
  assert.equal(await corners.count(), 4);
  assert.equal(await alice.getByTestId('plan-anchor').count(), 1);
  assert.equal(await alice.getByTestId('failed-footprint').count(), 0);

  const bob = await openPage(env.browser, { user: 'bob' });
  await bob.goto(`${env.daemon.url}#model=${id}`);
  await bob.getByTestId('plan-corner').first().waitFor(WAIT);
  await waitMesh(bob, v0);
  await alice.getByTestId('peers').filter({ hasText: 'bob' }).waitFor(WAIT);

  // Edge 1 (a gable wall) gets the roof profile: a plan op.
  const [c1, c2] = [await centre(corners.nth(1)), await centre(corners.nth(2))];
  await alice.mouse.click((c1.x + c2.x) / 2, (c1.y + c2.y) / 2);
  await alice.locator('[data-testid="plan-edge"][data-edge="1"].selected').waitFor({ state: 'attached', ...WAIT });
  assert.equal(await alice.getByTestId('edge-profile').inputValue(), 'gable');
  const bobBefore = await readCanvas(bob);
  await alice.getByTestId('edge-profile').selectOption('roof');
  await waitVersion(alice, v0 + 1);
  const plan1 = await getJson(`/models/${id}/plan`);
  assert.deepEqual(plan1.loops[0].profiles, ['roof', 'roof', 'roof', 'gable']);
  assert.equal(plan1.anchors.length, 1, 'the anchor was lost');
  assert.equal((await getJson(`/models/${id}/ops`)).items.at(-1).op.kind, 'plan');
  // Bob sees it: his version, his plan editor and his 3D view follow.
  await waitVersion(bob, v0 + 1);
  await waitMesh(bob, v0 + 1);
  await bob.locator('[data-testid="plan-edge"][data-edge="1"][data-profile="roof"]').waitFor({ state: 'attached', ...WAIT });
  assert.ok(countChanged(bobBefore, await readCanvas(bob)) > 50, 'bob\'s view did not change');

  // The roof profile's top point dragged up: a profile op (the whole model uses it).
  await alice.getByTestId('profile-select').selectOption('roof');
  const bobPlanned = await readCanvas(bob);
  const top = alice.getByTestId('profile-point').nth(2);
  const drag = await dragWithPreview(alice, await centre(top), 0, -40);
  await drag.shown();
  await drag.release();
  await waitVersion(alice, v0 + 2);
  const last = (await getJson(`/models/${id}/ops`)).items.at(-1).op;
  assert.equal(last.kind, 'profile');
  assert.equal(last.name, 'roof');
  const plan2 = await getJson(`/models/${id}/plan`);
  assert.ok(plan2.profiles.roof.points[2][1] > 4.3, JSON.stringify(plan2.profiles.roof));
  assert.equal(plan2.profiles.roof.tag, 'tiles', 'the profile lost its tag');
  await waitMesh(bob, v0 + 2);
  await bob.waitForFunction(() => {
    const s = document.querySelector('[data-testid="profile-point"][data-index="2"] title');
    return s && /z (4\.[3-9]|[5-9])/.test(s.textContent);
  }, null, WAIT);
  const roofChanged = countChanged(bobPlanned, await readCanvas(bob));
  assert.ok(roofChanged > 50, `bob's roof changed ${roofChanged} pixels`);

  assert.deepEqual(alice.problems, []);
  assert.deepEqual(bob.problems, []);
});
