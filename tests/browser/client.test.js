// The web client against a real archgramd in Debian's chromium: import and draw a model,
// pick a component, import errors, two people editing one model live, a lost connection,
// and the paged model list.
import assert from 'node:assert/strict';
import { readFile, writeFile } from 'node:fs/promises';
import path from 'node:path';
import { test } from 'node:test';
import { ROOT } from './daemon.js';
import { daemonAndBrowser, openPage } from './browser.js';
import { readCanvas } from './pixels.js';

const FIXTURE = path.join(ROOT, 'tests', 'data', 'web', 'two_boxes.obj');
const WAIT = { timeout: 20000 };

const env = daemonAndBrowser();

const newPage = (opts) => openPage(env.browser, opts); // contexts close with the browser

function assertNoProblems(...list) {
  for (const page of list) assert.deepEqual(page.problems, [], 'the page reported errors');
}

// Imports the fixture over REST and returns the new model id.
async function importOverRest(name) {
  const body = await readFile(FIXTURE);
  const res = await fetch(`${env.daemon.url}api/v1/models?name=${encodeURIComponent(name)}&format=obj`, {
    method: 'POST',
    body,
  });
  assert.equal(res.status, 202, await res.clone().text());
  let job = await res.json();
  const deadline = Date.now() + 20000;
  while (!['succeeded', 'failed', 'cancelled'].includes(job.status)) {
    assert.ok(Date.now() < deadline, 'import job did not finish');
    await new Promise((r) => setTimeout(r, 100));
    job = await (await fetch(`${env.daemon.url}api/v1/jobs/${job.id}`)).json();
  }
  assert.equal(job.status, 'succeeded', JSON.stringify(job.error));
  return job.result.model;
}

const textOf = (page, testid) => page.getByTestId(testid).textContent();
const versionOf = async (page) => Number((await textOf(page, 'model-version')).replace(/\D/g, ''));

test('import through the page, draw the model and pick a component', async () => {
  const page = await newPage({ user: 'tester' });
  await page.goto(env.daemon.url);
  await page.getByTestId('upload-input').setInputFiles(FIXTURE);

  await page.locator('[data-testid="job"][data-status="succeeded"]').waitFor(WAIT);
  await page.locator('[data-testid="model-item"]', { hasText: 'two_boxes' }).waitFor(WAIT);
  await page.waitForFunction(() => document.getElementById('viewport').dataset.model, null, WAIT);
  assert.equal((await textOf(page, 'model-name')).trim(), 'two_boxes');
  assert.ok((await versionOf(page)) >= 1);
  const view = await readCanvas(page);
  assert.ok(view.width > 200 && view.height > 200, `canvas is ${view.width}x${view.height}`);
  const pct = (view.fraction * 100).toFixed(2);
  assert.ok(view.fraction > 0.02, `only ${pct}% of the canvas shows the model`);
  assert.ok(view.fraction < 0.9, `${pct}% of the canvas differs from the background`);
  assert.ok(view.inside, 'no pixel well inside the model');
  assert.ok(view.outside, 'no background pixel');

  await view.canvas.click({ position: view.inside });
  const picked = page.getByTestId('picked-component');
  await page.waitForFunction(() => /component \d+/.test(document.querySelector('[data-testid="picked-component"]').textContent), null, WAIT);
  const match = /component (\d+) · group (\S+)/.exec(await picked.textContent());
  assert.ok(match, await picked.textContent());
  assert.ok(['block', 'annex'].includes(match[2]), `group ${match[2]}`);
  // The picked component is drawn highlighted.
  const colourDistance = (a, b) => Math.max(...a.map((v, i) => Math.abs(v - b[i])));
  const before = view.pixel(view.inside);
  const highlighted = (await readCanvas(page)).pixel(view.inside);
  assert.ok(colourDistance(before, highlighted) > 40, `pick did not recolour: ${before} → ${highlighted}`);

  // Clicking empty space (a background pixel) clears the pick.
  await view.canvas.click({ position: view.outside });
  await page.waitForFunction(() => !/component \d+/.test(document.querySelector('[data-testid="picked-component"]').textContent), null, WAIT);
  const restored = (await readCanvas(page)).pixel(view.inside);
  assert.ok(colourDistance(before, restored) <= 2, `colour not restored: ${before} → ${restored}`);
  assertNoProblems(page);
});

test('a failed import is shown to the person', async () => {
  const page = await newPage({ user: 'tester' });
  await page.goto(env.daemon.url);
  const bad = path.join(env.daemon.dir, 'broken.obj');
  await writeFile(bad, 'v 0 0 0\nv 1 0 0\nf 1 2 9\n');
  await page.getByTestId('upload-input').setInputFiles(bad);
  const banner = page.getByTestId('error');
  await banner.waitFor({ state: 'visible', ...WAIT });
  assert.match(await banner.textContent(), /line 3/);
  await page.locator('[data-testid="job"][data-status="failed"]').waitFor(WAIT);
  // the page's own warning about the problem is expected; anything else is not
  assertNoProblems(page);
});

test('two people in one model: presence and a live rename', async () => {
  const id = await importOverRest('Shared hall');
  const alice = await newPage({ user: 'alice' });
  const bob = await newPage({ user: 'bob' });
  await alice.goto(`${env.daemon.url}#model=${id}`);
  await alice.getByTestId('model-name').filter({ hasText: 'Shared hall' }).waitFor(WAIT);
  await bob.goto(`${env.daemon.url}#model=${id}`);
  await bob.getByTestId('model-name').filter({ hasText: 'Shared hall' }).waitFor(WAIT);

  await bob.getByTestId('peers').filter({ hasText: 'alice' }).waitFor(WAIT);
  await alice.getByTestId('peers').filter({ hasText: 'bob' }).waitFor(WAIT);
  const before1 = await versionOf(alice);
  const before2 = await versionOf(bob);
  assert.equal(before1, before2);

  const title = alice.getByTestId('model-name');
  await title.click();
  await title.fill('Hall 7');
  await title.press('Enter');

  await bob.getByTestId('model-name').filter({ hasText: /^Hall 7$/ }).waitFor(WAIT);
  await bob.locator('[data-testid="model-item"]', { hasText: 'Hall 7' }).waitFor(WAIT);
  await alice.waitForFunction((v) => Number(document.querySelector('[data-testid="model-version"]').textContent.replace(/\D/g, '')) > v, before1, WAIT);
  await bob.waitForFunction((v) => Number(document.querySelector('[data-testid="model-version"]').textContent.replace(/\D/g, '')) > v, before2, WAIT);
  assert.equal(await versionOf(alice), await versionOf(bob));
  await bob.getByTestId('history').filter({ hasText: 'alice' }).waitFor(WAIT);

  // A note from bob reaches alice's history; both move on to the same version.
  await bob.getByTestId('note-input').fill('check the annex roof');
  await bob.getByTestId('note-send').click();
  await alice.getByTestId('history').filter({ hasText: 'check the annex roof' }).waitFor(WAIT);
  await alice.waitForFunction((v) => Number(document.querySelector('[data-testid="model-version"]').textContent.replace(/\D/g, '')) === v, before1 + 2, WAIT);
  assert.equal(await versionOf(bob), before1 + 2);

  // The rename is stored: a fresh read of the model has it.
  const model = await (await fetch(`${env.daemon.url}api/v1/models/${id}`)).json();
  assert.equal(model.name, 'Hall 7');
  assert.equal(model.version, before1 + 2);

  // Bob sees what alice picks.
  await alice.waitForFunction(() => document.getElementById('viewport').dataset.model, null, WAIT);
  const view = await readCanvas(alice);
  assert.ok(view.inside, 'no pixel well inside the model');
  await view.canvas.click({ position: view.inside });
  await alice.waitForFunction(() => /component \d+/.test(document.querySelector('[data-testid="picked-component"]').textContent), null, WAIT);
  const component = /component (\d+)/.exec(await textOf(alice, 'picked-component'))[1];
  await bob.getByTestId('peers').filter({ hasText: `component ${component}` }).waitFor(WAIT);
  assertNoProblems(alice, bob);
});

test('a lost connection is shown, and the page resumes and catches up', async () => {
  const id = await importOverRest('Depot');
  const page = await newPage({ user: 'carol' });
  await page.goto(`${env.daemon.url}#model=${id}`);
  await page.getByTestId('model-name').filter({ hasText: 'Depot' }).waitFor(WAIT);
  await page.getByTestId('connection').filter({ hasText: 'live' }).waitFor(WAIT);
  const v0 = await versionOf(page);

  await env.daemon.stopProcess();
  const banner = page.getByTestId('error');
  await banner.filter({ hasText: 'connection lost' }).waitFor({ state: 'visible', ...WAIT });
  await env.daemon.restart();

  // An edit made over REST while the page is away (or just back) reaches it.
  const res = await fetch(`${env.daemon.url}api/v1/models/${id}`, {
    method: 'PATCH',
    headers: { 'Content-Type': 'application/json', 'If-Match': `"${v0}"`, 'X-Archgram-User': 'dave' },
    body: JSON.stringify({ name: 'Depot East' }),
  });
  assert.equal(res.status, 200, await res.clone().text());
  await page.getByTestId('connection').filter({ hasText: 'live' }).waitFor(WAIT);
  await page.getByTestId('model-name').filter({ hasText: 'Depot East' }).waitFor(WAIT);
  assert.equal(await versionOf(page), v0 + 1);
  await page.getByTestId('history').filter({ hasText: 'dave' }).waitFor(WAIT);
  // A failed reconnect attempt logs a websocket error in the console; nothing else may.
  const rest = page.problems.filter((p) => !/WebSocket connection to .* failed|ERR_CONNECTION_REFUSED/.test(p));
  assert.deepEqual(rest, [], 'the page reported errors');
});

test('the model list pages: load more fetches the rest', async () => {
  const listed = async () => (await (await fetch(`${env.daemon.url}api/v1/models?page_size=200`)).json()).items.length;
  // The page shows 50 at a time; make sure there are more than that.
  const have = await listed();
  const names = Array.from({ length: Math.max(0, 53 - have) }, (_, i) => `Block ${i + 1}`);
  for (let i = 0; i < names.length; i += 8) await Promise.all(names.slice(i, i + 8).map(importOverRest));
  const total = await listed();
  assert.ok(total > 50);

  const page = await newPage({ user: 'erin' });
  await page.goto(env.daemon.url);
  const items = page.getByTestId('model-item');
  await page.getByTestId('load-more').waitFor({ state: 'visible', ...WAIT });
  assert.equal(await items.count(), 50);
  await page.getByTestId('load-more').click();
  await page.getByTestId('load-more').waitFor({ state: 'hidden', ...WAIT });
  assert.equal(await items.count(), total);
  // Ids ascend down the list, no model twice.
  const ids = await items.evaluateAll((els) => els.map((e) => Number(e.dataset.id)));
  assert.deepEqual(ids, [...new Set(ids)].sort((a, b) => a - b));
  assertNoProblems(page);
});
