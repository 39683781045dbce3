// Structure-preserving editing in the web client against a real archgramd in Debian's
// chromium, two people in one room: alice selects a node (bob sees it in her colour), drags a
// face handle (bob's view changes while she drags, from the server's previews), releases (one
// op, both at the same version), undoes with Ctrl+Z (the tree is the original again), redoes,
// bob restores the first version from the history, and alice splits a node with the
// split-plane tool (more nodes). Then one person joins, copies/pastes and removes windows
// picked in the view.
import assert from 'node:assert/strict';
import { test } from 'node:test';
import { daemonAndBrowser, openPage } from './browser.js';
import { facadeObj } from './facade.js';
import { versionOf, WAIT, waitJob as waitJobOver, waitMesh, waitVersion } from './page.js';
import { countChanged, countWhere, hueOf, readCanvas } from './pixels.js';

const COLS = 6;
const ROWS = 2;

const env = daemonAndBrowser();

const api = async (p, init) => fetch(`${env.daemon.url}api/v1${p}`, init);

const waitJob = (job) => waitJobOver(api, job);

// Imports the facade and proceduralizes it over REST, as a pipeline would.
async function proceduralizedFacade() {
  const res = await api('/models?name=facade&format=obj', { method: 'POST', body: facadeObj(COLS, ROWS) });
  assert.equal(res.status, 202, await res.clone().text());
  const id = (await waitJob(await res.json())).result.model;
  const model = await (await api(`/models/${id}`)).json();
  const proc = await api(`/models/${id}/proceduralize`, {
    method: 'POST',
    headers: { 'If-Match': `"${model.version}"`, 'Content-Type': 'application/json', 'X-Archgram-User': 'pipeline' },
    body: '{}',
  });
  assert.equal(proc.status, 202, await proc.clone().text());
  await waitJob(await proc.json());
  return id;
}

const treeOf = async (id) => {
  const r = await api(`/models/${id}/tree`);
  assert.equal(r.status, 200, await r.clone().text());
  return r.json();
};
// The tree without the version it was read at.
const shape = (t) => JSON.stringify({ root: t.root, nodes: t.nodes, labels: t.labels, rules: t.rules });
const waitTree = (page, v) => page.waitForFunction((want) => window.archgram.tree?.version === want, v, WAIT);
const settle = (page) => page.evaluate(() => new Promise((r) => requestAnimationFrame(() => requestAnimationFrame(r))));

// A handle's position on the page.
async function handleAt(page, face) {
  const p = await page.evaluate((f) => window.archgramTools.handles.screen(f), face);
  assert.ok(p, `no ${face} handle`);
  const box = await page.locator('#viewport canvas').boundingBox();
  return { x: box.x + p.x, y: box.y + p.y };
}

function hueNear(hex, tolerance = 12) {
  const want = hueOf([1, 3, 5].map((i) => parseInt(hex.slice(i, i + 2), 16)));
  return (p) => {
    const { h, s } = hueOf(p);
    const d = Math.min(Math.abs(h - want.h), 360 - Math.abs(h - want.h));
    return s > 0.2 && d < tolerance;
  };
}

test('select, drag a handle live, undo, redo, restore, split — seen by a second person', async (t) => {
  const id = await proceduralizedFacade();
  const t0 = await treeOf(id);
  const v1 = t0.version;
  const rootBox = t0.nodes.find((n) => n.id === t0.root).box;

  const alice = await openPage(env.browser, { user: 'alice' });
  const bob = await openPage(env.browser, { user: 'bob' });
  for (const page of [alice, bob]) {
    await page.goto(`${env.daemon.url}#model=${id}`);
    await waitMesh(page, v1);
    await waitTree(page, v1);
  }
  await bob.getByTestId('peers').filter({ hasText: 'alice' }).waitFor(WAIT);
  await alice.getByTestId('peers').filter({ hasText: 'bob' }).waitFor(WAIT);
  const calm = await readCanvas(bob);

  // Alice selects the root in the tree: bob sees the whole facade in her colour.
  await alice.locator(`[data-testid="tree-node"][data-node="${t0.root}"]`).click();
  await alice.getByTestId('picked-component').filter({ hasText: `node ${t0.root}` }).waitFor(WAIT);
  const aliceColour = await bob.locator('[data-testid="peers"] li[data-peer]', { hasText: 'alice' }).getAttribute('data-colour');
  assert.match(aliceColour, /^#[0-9a-f]{6}$/i);
  const inHerColour = hueNear(aliceColour);
  await bob.getByTestId('peers').filter({ hasText: /\d+ components|component \d/ }).waitFor(WAIT);
  await settle(bob);
  const seen = await readCanvas(bob);
  const area = seen.width * seen.height;
  const before = countWhere(calm, inHerColour);
  const after = countWhere(seen, inHerColour);
  assert.ok(after > before + 0.01 * area, `alice's colour on bob's view: ${before} → ${after} pixels`);

  // Alice drags the x+ handle outwards by half the facade's width on screen, holding it.
  const grip = await handleAt(alice, 'x+');
  const other = await handleAt(alice, 'x-');
  const dx = (grip.x - other.x) * 0.5;
  const dy = (grip.y - other.y) * 0.5;
  await alice.mouse.move(grip.x, grip.y);
  await alice.mouse.down();
  for (let i = 1; i <= 12; i++) {
    await alice.mouse.move(grip.x + (dx * i) / 12, grip.y + (dy * i) / 12);
    await alice.waitForTimeout(40);
  }
  assert.equal(await alice.locator('#viewport').getAttribute('data-dragging'), 'x+');
  // Bob's view follows the server's re-solved preview while alice still holds the handle.
  await bob.locator('#viewport[data-preview]').waitFor({ state: 'attached', ...WAIT });
  assert.equal(await bob.locator('#viewport').getAttribute('data-preview-by'), 'alice');
  await settle(bob);
  const dragging = await readCanvas(bob);
  const moved = countChanged(seen, dragging);
  assert.ok(moved > 0.005 * area, `bob's view changed by ${moved} pixels during the drag`);
  assert.equal(await versionOf(bob), v1, 'a preview made a version');
  const sent = await alice.evaluate(() => window.archgramTools.handles.sent);
  assert.ok(sent >= 1 && sent <= 30, `${sent} previews for ~0.5 s of dragging`);
  const received = await bob.evaluate(() => window.archgramTools.preview.received);
  t.diagnostic(`drag: ${sent} previews sent, ${received} received by bob, ${moved} of ${area} pixels changed on bob's view`);

  // Release: one op; both end at the same version, the facade wider.
  await alice.mouse.up();
  const v2 = v1 + 1;
  for (const page of [alice, bob]) {
    await waitVersion(page, v2);
    await waitMesh(page, v2);
    await waitTree(page, v2);
  }
  const t1 = await treeOf(id);
  assert.equal(t1.version, v2);
  const wide = t1.nodes.find((n) => n.id === t1.root).box;
  const ratio = (wide[3] - wide[0]) / (rootBox[3] - rootBox[0]);
  assert.ok(ratio > 1.15, `the facade is ${ratio.toFixed(2)}× as wide after the drag`);
  t.diagnostic(`release: root ${(rootBox[3] - rootBox[0]).toFixed(2)} → ${(wide[3] - wide[0]).toFixed(2)} m wide, ${t0.nodes.length} → ${t1.nodes.length} nodes`);
  for (const page of [alice, bob]) {
    await page.getByTestId('history').locator('li.op', { hasText: 'resize' }).filter({ hasText: 'alice' }).first().waitFor(WAIT);
  }
  assert.equal(await bob.locator('#viewport').getAttribute('data-preview'), null, 'bob still shows a preview');

  // Ctrl+Z on alice's page: an undo op, and the tree is the original again.
  await alice.locator('#viewport canvas').click({ position: { x: 5, y: 5 } }); // focus the page, pick nothing
  await alice.keyboard.press('Control+z');
  const v3 = v2 + 1;
  for (const page of [alice, bob]) {
    await waitVersion(page, v3);
    await waitTree(page, v3);
  }
  const t2 = await treeOf(id);
  assert.equal(shape(t2), shape(t0), 'undo did not restore the original tree');
  await bob.getByTestId('history').locator('li.op', { hasText: 'undo' }).first().waitFor(WAIT);

  // Ctrl+Shift+Z: redo, the wide facade again.
  await alice.keyboard.press('Control+Shift+z');
  const v4 = v3 + 1;
  for (const page of [alice, bob]) await waitTree(page, v4);
  assert.equal(shape(await treeOf(id)), shape(t1), 'redo did not bring the resized tree back');

  // Bob restores the first version from the history: the original again, as his edit.
  await bob.locator(`li.op[data-version="${v1}"] [data-testid="restore"]`).click();
  const v5 = v4 + 1;
  for (const page of [alice, bob]) await waitTree(page, v5);
  const t2b = await treeOf(id);
  assert.equal(shape(t2b), shape(t0), 'restoring v1 did not give the original tree');
  await alice.getByTestId('history').locator(`li.op[data-version="${v5}"]`, { hasText: 'bob' }).filter({ hasText: `back to v${v1}` }).waitFor(WAIT);

  // The split-plane tool on the root, along x at the middle: more nodes.
  await alice.locator(`[data-testid="tree-node"][data-node="${t2.root}"]`).click();
  await alice.getByTestId('split-tool').click();
  await alice.getByTestId('split-axis').selectOption('x');
  assert.match(await alice.getByTestId('split-at-text').textContent(), /^\d+\.\d\d m$/);
  await alice.getByTestId('split').click();
  const v6 = v5 + 1;
  for (const page of [alice, bob]) {
    await waitVersion(page, v6);
    await waitTree(page, v6);
  }
  const t3 = await treeOf(id);
  assert.ok(t3.nodes.length > t2.nodes.length, `split: ${t2.nodes.length} → ${t3.nodes.length} nodes`);
  t.diagnostic(`split: ${t2.nodes.length} → ${t3.nodes.length} nodes`);
  await bob.getByTestId('history').locator('li.op', { hasText: 'split' }).first().waitFor(WAIT);

  assert.deepEqual(alice.problems, [], 'alice\'s page reported errors');
  assert.deepEqual(bob.problems, [], 'bob\'s page reported errors');
});

// Where a node's front (−y) face centre is drawn on the page.
async function nodeOnPage(page, id) {
  const p = await page.evaluate((nid) => {
    const { viewport } = window.archgramTools;
    const b = window.archgram.tree.node(nid).box;
    const v = viewport.camera.position.clone().set((b[0] + b[3]) / 2, (b[2] + b[5]) / 2, -b[1]).project(viewport.camera);
    const el = viewport.renderer.domElement;
    return { x: ((v.x + 1) / 2) * el.clientWidth, y: ((1 - v.y) / 2) * el.clientHeight };
  }, id);
  const box = await page.locator('#viewport canvas').boundingBox();
  return { x: box.x + p.x, y: box.y + p.y };
}

test('join, copy/paste and remove windows picked in the view', async () => {
  const id = await proceduralizedFacade();
  const t0 = await treeOf(id);
  const page = await openPage(env.browser, { user: 'carol' });
  await page.goto(`${env.daemon.url}#model=${id}`);
  await waitMesh(page, t0.version);
  await waitTree(page, t0.version);
  const visible = (t) => t.nodes.filter((n) => typeof n.component === 'number');
  // The windows: visible nodes whose label is not the wall's (the wall is the largest box).
  const area = (n) => (n.box[3] - n.box[0]) * (n.box[5] - n.box[2]);
  const windowsOf = (t) => {
    const vis = visible(t);
    const wall = vis.reduce((a, b) => (area(b) > area(a) ? b : a));
    return vis.filter((n) => n.label !== wall.label).sort((a, b) => a.box[2] - b.box[2] || a.box[0] - b.box[0]);
  };
  const w0 = windowsOf(t0);
  assert.equal(w0.length, COLS * ROWS);
  const selected = () => page.evaluate(() => {
    const s = window.archgram.selection;
    return s ? (s.nodes || [s.node]) : [];
  });

  // Click one window, Shift+click its neighbour: both selected; Join.
  let at = await nodeOnPage(page, w0[0].id);
  await page.mouse.click(at.x, at.y);
  await page.waitForFunction((n) => window.archgram.selection?.node === n, w0[0].id, WAIT);
  at = await nodeOnPage(page, w0[1].id);
  await page.keyboard.down('Shift');
  await page.mouse.click(at.x, at.y);
  await page.keyboard.up('Shift');
  assert.deepEqual(await selected(), [w0[0].id, w0[1].id]);
  assert.equal(await page.locator('[data-testid="tree-node"].selected').count(), 2);
  await page.getByTestId('join').click();
  let v = t0.version + 1;
  await waitTree(page, v);
  const t1 = await treeOf(id);
  assert.notEqual(shape(t1), shape(t0), 'join changed nothing');
  await page.getByTestId('history').locator('li.op', { hasText: 'join' }).waitFor(WAIT);

  // Copy a window (Ctrl+C), pick another, paste it in its place (replace, derive).
  const w1 = windowsOf(t1);
  const last = w1[w1.length - 1];
  at = await nodeOnPage(page, w1[w1.length - 2].id);
  await page.mouse.click(at.x, at.y);
  await page.waitForFunction((n) => window.archgram.selection?.node === n, w1[w1.length - 2].id, WAIT);
  await page.keyboard.press('Control+c');
  await page.getByTestId('clipboard').filter({ hasText: String(w1[w1.length - 2].id) }).waitFor(WAIT);
  at = await nodeOnPage(page, last.id);
  await page.mouse.click(at.x, at.y);
  await page.waitForFunction((n) => window.archgram.selection?.node === n, last.id, WAIT);
  await page.getByTestId('paste-placement').selectOption('replace');
  await page.getByTestId('paste-fit').selectOption('derive');
  await page.getByTestId('paste').click();
  v += 1;
  await waitTree(page, v);
  await page.getByTestId('history').locator('li.op', { hasText: 'paste' }).filter({ hasText: 'replace, derive' }).waitFor(WAIT);
  const t2 = await treeOf(id);

  // Remove one window: one visible node fewer.
  const w2 = windowsOf(t2);
  at = await nodeOnPage(page, w2[w2.length - 1].id);
  await page.mouse.click(at.x, at.y);
  await page.waitForFunction((n) => window.archgram.selection?.node === n, w2[w2.length - 1].id, WAIT);
  await page.getByTestId('remove').click();
  v += 1;
  await waitTree(page, v);
  const t3 = await treeOf(id);
  assert.equal(visible(t3).length, visible(t2).length - 1, 'remove did not take one visible node away');
  assert.deepEqual(page.problems, [], 'the page reported errors');
});

test('copy a window in one model and paste it into another (style transfer)', async () => {
  const a = await proceduralizedFacade();
  const b = await proceduralizedFacade();
  const ta = await treeOf(a);
  const tb0 = await treeOf(b);
  const page = await openPage(env.browser, { user: 'dan' });
  await page.goto(`${env.daemon.url}#model=${a}`);
  await waitMesh(page, ta.version);
  await waitTree(page, ta.version);
  const visible = (t) => t.nodes.filter((n) => typeof n.component === 'number');
  const area = (n) => (n.box[3] - n.box[0]) * (n.box[5] - n.box[2]);
  const wallOf = (t) => visible(t).reduce((x, y) => (area(y) > area(x) ? y : x));
  const win = visible(ta).find((n) => n.label !== wallOf(ta).label);

  // Copy a window of A (picked in the view), switch to B in the same page, select B's wall.
  let at = await nodeOnPage(page, win.id);
  await page.mouse.click(at.x, at.y);
  await page.waitForFunction((n) => window.archgram.selection?.node === n, win.id, WAIT);
  await page.keyboard.press('Control+c');
  await page.getByTestId('clipboard').filter({ hasText: String(win.id) }).waitFor(WAIT);
  await page.evaluate((id) => { location.hash = `#model=${id}`; }, b);
  await waitMesh(page, tb0.version);
  await waitTree(page, tb0.version);
  const wall = wallOf(tb0);
  await page.locator(`[data-testid="tree-node"][data-node="${wall.id}"]`).click();
  await page.waitForFunction((n) => window.archgram.selection?.node === n, wall.id, WAIT);
  await page.getByTestId('paste-placement').selectOption('insert');
  await page.getByTestId('paste-fit').selectOption('fill');
  await page.getByTestId('paste').click();
  await waitTree(page, tb0.version + 1);
  const tb1 = await treeOf(b);
  assert.ok(visible(tb1).length > visible(tb0).length, `${visible(tb0).length} → ${visible(tb1).length} visible nodes`);
  // A is untouched
  assert.equal((await treeOf(a)).version, ta.version);
  assert.deepEqual(page.problems, [], 'the page reported errors');
});

