// Plan edits and priority tags in the web client against a real archgramd in Debian's
// chromium: a forced and a natural step placed on an edge of the plan editor, a step's height
// typed in the plan edits panel (previewed, then committed), an offset event added, edges
// left out of it and its distance typed; the profile editor's priority tags (a profile's, a
// segment's) and the plan's rule for ties. Each edit must go out as a plan or profile op, be held by the stored plan
// (GET …/plan), and change the model's mesh the way the geometry says: the GLB is read here,
// welded and checked to be closed, and its bounds compared with values worked out by hand.
import assert from 'node:assert/strict';
import path from 'node:path';
import { test } from 'node:test';
import { ROOT } from './daemon.js';
import { daemonAndBrowser, openPage } from './browser.js';
import { centre, uploadAndOpen, WAIT, waitMesh, waitVersion } from './page.js';
import { countChanged, readCanvas } from './pixels.js';
import { assertBounds, assertClosed, readShell } from './shell.js';

const HOUSE = path.join(ROOT, 'tests', 'data', 'extrude_web', 'house_plan.json');

const env = daemonAndBrowser();

const getJson = async (p) => {
  const res = await fetch(`${env.daemon.url}api/v1${p}`);
  assert.equal(res.status, 200, `${p}: ${res.status}`);
  return res.json();
};
const shellOf = async (id) => {
  const res = await fetch(`${env.daemon.url}api/v1/models/${id}/mesh.glb`);
  assert.equal(res.status, 200);
  return readShell(await res.arrayBuffer());
};

// A page that records the ops it sends over the websocket and the previews it asks for.
async function recordingPage(user) {
  const page = await openPage(env.browser, { user });
  page.opsSent = [];
  page.previewPlans = [];
  page.on('websocket', (ws) => ws.on('framesent', (f) => {
    const msg = JSON.parse(f.payload);
    if (msg.type === 'op') page.opsSent.push(msg.op);
  }));
  page.on('request', (r) => {
    if (r.url().endsWith('/api/v1/extrusions/preview') && r.method() === 'POST') page.previewPlans.push(JSON.parse(r.postData()));
  });
  return page;
}

// The last op the page sent and the last op the server logged: the same edit, of this kind.
async function lastOp(page, id, kind) {
  const sent = page.opsSent.at(-1);
  assert.equal(sent?.kind, kind, `the page sent ${JSON.stringify(sent)?.slice(0, 200)}`);
  const logged = (await getJson(`/models/${id}/ops`)).items.at(-1).op;
  assert.equal(logged.kind, kind);
  return sent;
}

// A point at fraction t along edge i of the plan editor's first loop, on the page.
async function onEdge(page, i, t) {
  const corners = page.getByTestId('plan-corner');
  const n = await corners.count();
  const [a, b] = [await centre(corners.nth(i)), await centre(corners.nth((i + 1) % n))];
  return { x: a.x + (b.x - a.x) * t, y: a.y + (b.y - a.y) * t };
}

test('steps and offset events edited in the plan editor', async () => {
  const page = await recordingPage('dana');
  await page.goto(env.daemon.url);
  const id = await uploadAndOpen(page, 'extrude-input', HOUSE);
  let v = (await getJson(`/models/${id}`)).version;
  await waitMesh(page, v);
  await page.getByTestId('plan-corner').first().waitFor(WAIT);
  // The house: 10 × 6 m, walls 3 m, 45° roofs on edges 0 and 2, vertical gables on 1 and 3.
  const house = await shellOf(id);
  assertClosed(house, 'the house');
  assertBounds(house, { x0: 0, x1: 10, y0: 0, y1: 6, top: 6 }, 'the house');
  const next = async () => {
    await waitVersion(page, ++v);
    await waitMesh(page, v);
    return getJson(`/models/${id}/plan`);
  };

  // A forced step: a 0.8 m square chimney at 70% of edge 0, 4 m up, with vertical walls. At
  // 4 m the roof edge has moved 1 m in, so the chimney's front stands at y = 0.6 until the
  // back slope (from y = 6 at 3 m) reaches it: the top is 3 + 6 − 0.6 = 8.4 m.
  await page.getByTestId('new-step-kind').selectOption('forced');
  await page.getByTestId('new-step-height').fill('4');
  await page.getByTestId('new-step-width').fill('0.8');
  await page.getByTestId('new-step-depth').fill('0.8');
  await page.getByTestId('new-step-profile').selectOption('gable');
  await page.getByTestId('step-mode').click();
  const before = await readCanvas(page);
  let at = await onEdge(page, 0, 0.7);
  await page.mouse.click(at.x, at.y);
  let plan = await next();
  let op = await lastOp(page, id, 'plan');
  assert.deepEqual(op.plan.steps, plan.steps, 'the stored steps are not the ones sent');
  assert.equal(plan.steps.length, 1);
  const forced = plan.steps[0];
  assert.deepEqual(forced.points, [[-0.4, -0.4], [0.4, -0.4], [0.4, 0.4], [-0.4, 0.4]]);
  assert.equal(forced.edge, 0);
  assert.equal(forced.height, 4);
  assert.equal(forced.profile, 'gable');
  assert.ok(Math.abs(forced.relative - 0.7) < 0.05, `the chimney is at ${forced.relative} of the edge`);
  assert.equal(plan.anchors.length, 1, 'the anchor was lost');
  let shell = await shellOf(id);
  assertClosed(shell, 'with the chimney');
  assertBounds(shell, { x0: 0, x1: 10, y0: 0, y1: 6, top: 8.4 }, 'with the chimney');
  await page.locator('[data-testid="plan-step"][data-kind="forced"]').waitFor({ state: 'attached', ...WAIT });
  const withChimney = await readCanvas(page);
  assert.ok(countChanged(before, withChimney) > 50, 'the chimney did not show');

  // Its height typed in its row: previewed while typing, committed with Enter. At 4.5 m the
  // front stands at y = 1.1: the top is 9 − 1.1 = 7.9 m.
  const shown = Number((await page.locator('#viewport').getAttribute('data-extrude-preview')) ?? 0);
  const height = page.getByTestId('step-row').first().getByTestId('step-height');
  await height.fill('4.5');
  await page.waitForFunction((n) => Number(document.getElementById('viewport').dataset.extrudePreview ?? 0) > n, shown, WAIT);
  assert.equal(page.previewPlans.at(-1).steps[0].height, 4.5);
  assert.ok(countChanged(withChimney, await readCanvas(page)) > 20, 'the preview did not change the view');
  await height.press('Enter');
  plan = await next();
  op = await lastOp(page, id, 'plan');
  assert.equal(op.plan.steps[0].height, 4.5);
  assert.equal(plan.steps[0].height, 4.5);
  assert.deepEqual(plan.steps[0].points, forced.points);
  shell = await shellOf(id);
  assertClosed(shell, 'the chimney at 4.5 m');
  assertBounds(shell, { x0: 0, x1: 10, y0: 0, y1: 6, top: 7.9 }, 'the chimney at 4.5 m');

  // Removed: the house as it was.
  await page.getByTestId('step-row').first().getByTestId('step-remove').click();
  plan = await next();
  assert.equal(plan.steps, undefined);
  assertBounds(await shellOf(id), { x0: 0, x1: 10, y0: 0, y1: 6, top: 6 }, 'without steps');
  assert.equal(await page.getByTestId('plan-step').count(), 0);

  // A natural step: a dormer 2 m wide grown 1.2 m out of edge 0 at 3.5 m, where the roof edge
  // is 0.5 m in: its front reaches y = −0.7 and stands until the back slope meets it at
  // 3 + 6 + 0.7 = 9.7 m.
  await page.getByTestId('new-step-kind').selectOption('natural');
  await page.getByTestId('new-step-height').fill('3.5');
  await page.getByTestId('new-step-width').fill('2');
  await page.getByTestId('new-step-depth').fill('1.2');
  await page.getByTestId('step-mode').click();
  at = await onEdge(page, 0, 0.5);
  await page.mouse.click(at.x, at.y);
  plan = await next();
  op = await lastOp(page, id, 'plan');
  assert.deepEqual(op.plan.steps, plan.steps);
  const dormer = plan.steps[0];
  assert.equal(dormer.points, undefined);
  assert.deepEqual([dormer.edge, dormer.height, dormer.width, dormer.depth, dormer.profile], [0, 3.5, 2, 1.2, 'gable']);
  shell = await shellOf(id);
  assertClosed(shell, 'with the dormer');
  assertBounds(shell, { x0: 0, x1: 10, y0: -0.7, y1: 6, top: 9.7 }, 'with the dormer');
  await page.locator('[data-testid="plan-step"][data-kind="natural"]').waitFor({ state: 'attached', ...WAIT });
  await page.getByTestId('step-row').first().getByTestId('step-remove').click();
  plan = await next();
  assert.equal(plan.steps, undefined);

  // An offset event: added at the eave (3 m), 0.5 m out. Every edge moves out, so the roof
  // starts from 11 × 7 m: the top is 3 + 3.5 = 6.5 m.
  await page.getByTestId('add-offset').click();
  plan = await next();
  op = await lastOp(page, id, 'plan');
  assert.deepEqual(plan.offsets, [{ height: 3, outside: 0.5 }]);
  assert.deepEqual(op.plan.offsets, plan.offsets);
  shell = await shellOf(id);
  assertClosed(shell, 'with the offset');
  assertBounds(shell, { x0: -0.5, x1: 10.5, y0: -0.5, y1: 6.5, top: 6.5 }, 'with the offset');

  // The gable edges (1 and 3) left out of it, one click each: only the eaves overhang.
  await page.getByTestId('offset-row').first().getByTestId('offset-edges').click();
  for (const edge of [1, 3]) {
    at = await onEdge(page, edge, 0.5);
    await page.mouse.click(at.x, at.y);
    plan = await next();
    await lastOp(page, id, 'plan');
  }
  assert.deepEqual(plan.offsets, [{ height: 3, outside: 0.5, edges: [{ loop: 0, edge: 1, disabled: true }, { loop: 0, edge: 3, disabled: true }] }]);
  await page.locator('[data-testid="plan-edge"][data-edge="3"][data-offset="disabled"]').waitFor({ state: 'attached', ...WAIT });
  shell = await shellOf(id);
  assertClosed(shell, 'eaves only');
  assertBounds(shell, { x0: 0, x1: 10, y0: -0.5, y1: 6.5, top: 6.5 }, 'eaves only');

  // Its distance typed: 0.8 m out, previewed, then committed (top 3 + 7.6 / 2 = 6.8 m).
  const eaves = await readCanvas(page);
  const previews = page.previewPlans.length;
  const outside = page.getByTestId('offset-row').first().getByTestId('offset-outside');
  await outside.fill('0.8');
  await page.waitForFunction(() => document.querySelector('[data-testid="plan-status"]')?.dataset.state === 'ok', null, WAIT);
  assert.ok(page.previewPlans.length > previews, 'no preview was asked for');
  assert.equal(page.previewPlans.at(-1).offsets[0].outside, 0.8);
  await outside.press('Enter');
  plan = await next();
  assert.equal(plan.offsets[0].outside, 0.8);
  assert.equal(plan.offsets[0].edges.length, 2);
  shell = await shellOf(id);
  assertClosed(shell, 'a deeper overhang');
  assertBounds(shell, { x0: 0, x1: 10, y0: -0.8, y1: 6.8, top: 6.8 }, 'a deeper overhang');
  assert.ok(countChanged(eaves, await readCanvas(page)) > 20, 'the deeper overhang did not show');

  // Removed: the house as it was.
  await page.getByTestId('offset-row').first().getByTestId('offset-remove').click();
  plan = await next();
  assert.equal(plan.offsets, undefined);
  assertBounds(await shellOf(id), { x0: 0, x1: 10, y0: 0, y1: 6, top: 6 }, 'without offsets');

  // A refused edit: a forced step's corners typed into a bowtie. The preview says why, the
  // plan op is refused, the person is told once, and the plan and the row stay as stored.
  await page.getByTestId('new-step-kind').selectOption('forced');
  await page.getByTestId('step-mode').click();
  at = await onEdge(page, 0, 0.3);
  await page.mouse.click(at.x, at.y);
  const stored = await next();
  await page.evaluate(() => {
    window.problemsTold = [];
    window.archgram.signals.problem.add((p) => window.problemsTold.push(p.detail || p.title));
  });
  const corners = page.getByTestId('step-row').first().getByTestId('step-points');
  const text = await corners.inputValue();
  await corners.fill('0 0, 1 1, 1 0, 0 1');
  await page.waitForFunction(() => document.querySelector('[data-testid="plan-status"]')?.dataset.state === 'failed', null, WAIT);
  await corners.press('Enter');
  await page.getByTestId('error').waitFor({ state: 'visible', ...WAIT });
  await page.waitForFunction((t) => document.querySelector('[data-testid="step-points"]')?.value === t, text, WAIT);
  assert.deepEqual(await getJson(`/models/${id}/plan`), stored);
  assert.equal((await getJson(`/models/${id}`)).version, v);
  const told = await page.evaluate(() => window.problemsTold);
  assert.equal(told.length, 1, `told ${JSON.stringify(told)}`);
  assert.match(told[0], /step|polygon|simple|cross/i);

  // The only logged problems are the browser's notes on the refused preview and op.
  const refused = /Failed to load resource: the server responded with a status of 422\b/;
  assert.deepEqual(page.problems.filter((p) => !refused.test(p)), [], page.problems.join('\n'));
});

// Edge 0 of a 10 × 6 m plan cut in two collinear edges with different roof slopes: where
// they meet, one plane carries on for both. By default (max_volume) the steeper face wins
// (dw/dz 0.5: the ridge at 7 m); when the 45° roof wins the ridge is at 6 m.
const COLLINEAR = {
  profiles: {
    roof: { points: [[0, 0], [0, 3], [1, 4]], tag: 'tiles' },
    steep: { points: [[0, 0], [0, 3], [0.5, 4]] },
  },
  loops: [{ points: [[0, 0], [5, 0], [10, 0], [10, 6], [0, 6]], profiles: ['roof', 'steep', 'roof', 'roof', 'roof'] }],
};

test('priority tags and the rule for ties edited in the profile editor', async () => {
  const page = await recordingPage('eli');
  await page.goto(env.daemon.url);
  const id = await uploadAndOpen(page, 'extrude-input', {
    name: 'collinear.json', mimeType: 'application/json', buffer: Buffer.from(JSON.stringify(COLLINEAR)),
  });
  let v = (await getJson(`/models/${id}`)).version;
  await waitMesh(page, v);
  await page.getByTestId('profile-point').first().waitFor(WAIT);
  const ridge = async (top, what) => {
    const shell = await shellOf(id);
    assertClosed(shell, what);
    assertBounds(shell, { x0: 0, x1: 10, y0: 0, y1: 6, top }, what);
  };
  await ridge(7, 'by volume');
  const next = async () => {
    await waitVersion(page, ++v);
    await waitMesh(page, v);
    return getJson(`/models/${id}/plan`);
  };
  const setTag = async (testid, value) => {
    const input = page.getByTestId(testid);
    await input.fill(value);
    await input.press('Enter');
    return next();
  };

  // The 45° roof tagged 3: a profile op (one building) keeping its face tag; it wins.
  await page.getByTestId('profile-select').selectOption('roof');
  const tall = await readCanvas(page);
  let plan = await setTag('profile-priority', '3');
  let op = await lastOp(page, id, 'profile');
  assert.equal(op.name, 'roof');
  assert.deepEqual(op.profile, { points: [[0, 0], [0, 3], [1, 4]], tag: 'tiles', priority: 3 });
  assert.deepEqual(plan.profiles.roof, op.profile);
  await ridge(6, 'roof tagged 3');
  assert.ok(countChanged(tall, await readCanvas(page)) > 50, 'the lower ridge did not show');

  // The steep profile's upper segment (the one the edges are on when they meet) tagged 5: it
  // wins again. Tagging its wall segment instead changes nothing.
  await page.getByTestId('profile-select').selectOption('steep');
  const segment = async (i) => {
    const at = await centre(page.locator(`[data-testid="profile-segment"][data-index="${i}"]`));
    await page.mouse.click(at.x, at.y); // a vertical line's box has no width: aim at its middle
  };
  await segment(1);
  plan = await setTag('segment-priority', '5');
  op = await lastOp(page, id, 'profile');
  assert.equal(op.name, 'steep');
  assert.deepEqual(plan.profiles.steep, { points: [[0, 0], [0, 3], [0.5, 4]], segment_priority: [null, 5] });
  await ridge(7, 'steep segment 1 tagged 5');
  await page.locator('[data-testid="profile-segment"][data-index="1"][data-priority="5"]').waitFor({ state: 'attached', ...WAIT });
  plan = await setTag('segment-priority', '');
  assert.deepEqual(plan.profiles.steep, { points: [[0, 0], [0, 3], [0.5, 4]] });
  await ridge(6, 'steep segment 1 untagged');
  await segment(0);
  plan = await setTag('segment-priority', '5');
  assert.deepEqual(plan.profiles.steep.segment_priority, [5, null]);
  await ridge(6, 'steep wall segment tagged 5');

  // Untagged roof: equal tags where the edges meet, the rule decides (max_volume: steep);
  // min_volume (a plan op) keeps the gentler 45° face.
  await page.getByTestId('profile-select').selectOption('roof');
  plan = await setTag('profile-priority', '0');
  assert.deepEqual(plan.profiles.roof, { points: [[0, 0], [0, 3], [1, 4]], tag: 'tiles' });
  await ridge(7, 'equal tags, max_volume');
  await page.getByTestId('priority-scheme').selectOption('min_volume');
  plan = await next();
  op = await lastOp(page, id, 'plan');
  assert.equal(op.plan.priority, 'min_volume');
  assert.equal(plan.priority, 'min_volume');
  await ridge(6, 'equal tags, min_volume');

  assert.deepEqual(page.problems, [], page.problems.join('\n'));
});
