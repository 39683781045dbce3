// Proceduralization in the web client against a real archgramd in Debian's chromium: the
// Proceduralize button and its job, label colours, the split-tree panel selecting geometry
// and geometry selecting tree nodes, grammar edits (a syntax error, a fix, someone else's
// change), and a second page in the room following along live.
import assert from 'node:assert/strict';
import { writeFile } from 'node:fs/promises';
import path from 'node:path';
import { test } from 'node:test';
import { daemonAndBrowser, openPage } from './browser.js';
import { facadeObj } from './facade.js';
import { versionOf, WAIT, waitMesh, waitVersion } from './page.js';
import { countChanged, countWhere, hueOf, readCanvas, spotWhere } from './pixels.js';

const STAGES = ['segment', 'label', 'tree', 'rules', 'patterns', 'export', 'verify'];
const COLS = 6;
const ROWS = 4;

const env = daemonAndBrowser();

const api = async (p, init) => fetch(`${env.daemon.url}api/v1${p}`, init);
const textOf = (page, testid) => page.getByTestId(testid).textContent();
const selectedNode = (page) => page.evaluate(() => document.querySelector('[data-testid="tree-node"].selected')?.dataset.node ?? null);

// The highlight colour (yellow) under any lighting: green and red well above blue.
const yellow = ([r, g, b]) => r - b > 90 && g - b > 60;

test('proceduralize a facade, explore its split tree and edit its grammar', async () => {
  const file = path.join(env.daemon.dir, 'facade.obj');
  await writeFile(file, facadeObj(COLS, ROWS));

  const alice = await openPage(env.browser, { user: 'alice' });
  await alice.goto(env.daemon.url);
  await alice.getByTestId('upload-input').setInputFiles(file);
  await alice.locator('[data-testid="job"][data-status="succeeded"]').waitFor(WAIT);
  await alice.waitForFunction(() => /^#model=\d+$/.test(location.hash), null, WAIT);
  const id = Number((await alice.evaluate(() => location.hash)).replace(/\D/g, ''));
  await alice.waitForFunction(() => document.getElementById('viewport').dataset.model, null, WAIT);
  const v0 = await versionOf(alice);

  // Bob is in the room before anything happens; nothing procedural to show yet.
  const bob = await openPage(env.browser, { user: 'bob' });
  await bob.goto(`${env.daemon.url}#model=${id}`);
  await bob.getByTestId('peers').filter({ hasText: 'alice' }).waitFor(WAIT);
  await alice.getByTestId('peers').filter({ hasText: 'bob' }).waitFor(WAIT);
  assert.equal(await bob.getByTestId('tree-node').count(), 0);
  assert.ok(await bob.locator('#grammar').isHidden(), 'a grammar drawer for a model without grammar');
  const plain = await readCanvas(alice);

  // Proceduralize: the job runs through its stages and the page reloads mesh, tree, grammar.
  await alice.getByTestId('proceduralize').click();
  await alice.locator('[data-testid="proc-job"][data-status="succeeded"]').waitFor(WAIT);
  const stages = await alice.locator('[data-testid="proc-job"] .stage').evaluateAll((els) => els.map((e) => [e.textContent, e.className]));
  assert.deepEqual(stages.map((s) => s[0]), STAGES);
  assert.ok(stages.every((s) => /\bdone\b/.test(s[1])), JSON.stringify(stages));
  const v1 = v0 + 1;
  await waitVersion(alice, v1);
  await waitMesh(alice, v1);

  // The tree panel shows the pattern node with the grid's counts.
  const pattern = alice.locator('[data-testid="tree-node"][data-kind="pattern"]');
  await pattern.first().waitFor(WAIT);
  assert.equal(await pattern.count(), 1);
  const title = await pattern.locator('.kind').textContent();
  const counts = /(\d+)×(\d+)×(\d+)/.exec(title);
  assert.ok(counts, `pattern row: ${title}`);
  const n = counts.slice(1).map(Number);
  assert.deepEqual(n.filter((c) => c > 1).sort((a, b) => a - b), [ROWS, COLS].sort((a, b) => a - b), title);
  const tree = await (await api(`/models/${id}/tree`)).json();
  assert.equal(tree.version, v1);
  const patternId = Number(await pattern.getAttribute('data-node'));
  const patternNode = tree.nodes.find((x) => x.id === patternId);
  assert.equal(patternNode.kind, 'pattern');
  assert.equal(patternNode.children.length, COLS * ROWS);

  // Components are drawn in their labels' colours: each label's hue is on screen.
  const coloured = await readCanvas(alice);
  for (const l of tree.labels) {
    const rgb = [1, 3, 5].map((i) => parseInt(l.color.slice(i, i + 2), 16));
    const want = hueOf(rgb).h;
    const near = countWhere(coloured, (p) => {
      const { h, s } = hueOf(p);
      return s > 0.25 && Math.min(Math.abs(h - want), 360 - Math.abs(h - want)) < 15;
    });
    assert.ok(near > 200, `label ${l.label} (${l.color}): ${near} pixels of its hue`);
  }
  assert.ok(countChanged(plain, coloured) > 0.01 * plain.width * plain.height, 'the colours did not change');

  // Selecting the pattern node highlights all its windows.
  assert.equal(countWhere(coloured, yellow), 0, 'highlighted pixels before any selection');
  await pattern.click();
  await alice.getByTestId('picked-component').filter({ hasText: `node ${patternId}` }).waitFor(WAIT);
  const lit = await readCanvas(alice);
  const area = lit.width * lit.height;
  const changed = countChanged(coloured, lit);
  const yellowPx = countWhere(lit, yellow);
  assert.ok(changed > 0.005 * area, `selecting the pattern changed ${changed} pixels`);
  assert.ok(yellowPx > 0.005 * area, `${yellowPx} highlighted pixels`);
  const details = alice.getByTestId('node-details');
  assert.match(await details.locator('[data-field="pattern"]').textContent(), new RegExp(n.join(' × ')));
  assert.match(await details.locator('[data-field="size"]').textContent(), /^\d+\.\d\d × \d+\.\d\d × \d+\.\d\d m$/);
  assert.equal(await details.locator('[data-field="rule"]').textContent(), patternNode.rule);
  assert.equal(await selectedNode(alice), String(patternId));

  // Clicking one window selects it, and the tree reveals its node (a cell of the pattern).
  const spot = spotWhere(lit, yellow, 3);
  assert.ok(spot, 'no spot inside a highlighted window');
  await lit.canvas.click({ position: spot });
  await alice.waitForFunction(() => /^component \d+ · group \S+ · node \d+$/.test(document.querySelector('[data-testid="picked-component"]').textContent), null, WAIT);
  const [, component, , node] = /component (\d+) · group (\S+) · node (\d+)/.exec(await textOf(alice, 'picked-component')).map(String);
  const windowNode = tree.nodes.find((x) => x.id === Number(node));
  assert.equal(windowNode.component, Number(component));
  assert.ok(patternNode.children.includes(windowNode.id) || tree.nodes.some((c) => patternNode.children.includes(c.id) && c.children.includes(windowNode.id)), `node ${node} is not in the pattern`);
  assert.equal(await selectedNode(alice), node);
  assert.ok(await alice.locator(`[data-testid="tree-node"][data-node="${node}"]`).isVisible());
  assert.equal(await details.locator('[data-field="component"]').textContent(), component);
  assert.equal(await details.locator('[data-field="label"]').textContent(), windowNode.label);
  const one = await readCanvas(alice);
  const oneYellow = countWhere(one, yellow);
  assert.ok(oneYellow > 0 && oneYellow < yellowPx / 4, `one window lit: ${oneYellow} of ${yellowPx} pixels`);

  // Bob saw the proceduralize op arrive: his tree panel filled and his history names it.
  await bob.locator('[data-testid="tree-node"][data-kind="pattern"]').waitFor(WAIT);
  await bob.getByTestId('history').filter({ hasText: 'proceduralize' }).waitFor(WAIT);
  await waitVersion(bob, v1);
  await waitMesh(bob, v1);
  await bob.getByTestId('peers').filter({ hasText: `component ${component}` }).waitFor(WAIT);

  // A syntax error in the grammar: the banner names the line, the editor marks it.
  const text = alice.getByTestId('grammar-text');
  const original = await text.inputValue();
  assert.equal(original, await (await api(`/models/${id}/grammar`)).text());
  const lines = original.split('\n');
  const at = lines.findIndex((l) => /^rule /.test(l)) + 1; // inside the first rule
  assert.ok(at > 0, original);
  const broken = [...lines.slice(0, at), '  @@@', ...lines.slice(at)];
  await text.fill(broken.join('\n'));
  await alice.getByTestId('grammar-apply').click();
  const banner = alice.getByTestId('error');
  await banner.waitFor({ state: 'visible', ...WAIT });
  assert.match(await banner.textContent(), new RegExp(`line ${at + 1}\\b`));
  assert.equal(await alice.getByTestId('grammar-error-line').textContent(), String(at + 1));
  const caretLine = await text.evaluate((t) => t.value.slice(0, t.selectionStart).split('\n').length);
  assert.equal(caretLine, at + 1);
  assert.equal(await versionOf(alice), v1, 'a refused grammar made a version');

  // Fixed (the bad line becomes a comment) and applied: a new version, re-derived.
  broken[at] = '  # checked by alice';
  await text.fill(broken.join('\n'));
  await alice.getByTestId('grammar-apply').click();
  const v2 = v1 + 1;
  await waitVersion(alice, v2);
  await waitMesh(alice, v2);
  await alice.getByTestId('grammar-status').filter({ hasText: `v${v2}` }).waitFor(WAIT);
  assert.equal(await text.inputValue(), broken.join('\n'));
  await bob.getByTestId('grammar-text').evaluate((t, want) => new Promise((resolve) => {
    const check = () => (t.value === want ? resolve() : setTimeout(check, 50));
    check();
  }), broken.join('\n'));
  await bob.getByTestId('history').filter({ hasText: 'grammar edited' }).waitFor(WAIT);
  await alice.locator('[data-testid="tree-node"][data-kind="pattern"]').waitFor(WAIT);

  // Someone else changes the grammar under alice's edit: Apply is refused, reload offered.
  await text.fill(`${broken.join('\n')}\n# alice again\n`);
  const put = await api(`/models/${id}/grammar`, {
    method: 'PUT',
    headers: { 'If-Match': `"${v2}"`, 'X-Archgram-User': 'dave' },
    body: `${original}# dave\n`,
  });
  assert.equal(put.status, 200, await put.clone().text());
  await waitVersion(alice, v2 + 1);
  await alice.getByTestId('grammar-status').filter({ hasText: 'Someone else' }).waitFor(WAIT);
  await alice.getByTestId('grammar-apply').click();
  await banner.filter({ hasText: 'Someone else changed' }).waitFor(WAIT);
  assert.equal(await versionOf(alice), v2 + 1);
  await alice.getByTestId('error-action').click(); // the banner offers the reload
  assert.equal(await text.inputValue(), `${original}# dave\n`);
  await alice.getByTestId('grammar-status').filter({ hasText: `v${v2 + 1}` }).waitFor(WAIT);

  // Only the expected problems were logged: the browser's notes on the two refused edits.
  const refused = /Failed to load resource: the server responded with a status of (422|412)\b/;
  assert.deepEqual(alice.problems.filter((p) => !refused.test(p)), [], 'alice\'s page reported errors');
  assert.equal(alice.problems.length, 2, alice.problems.join('\n'));
  assert.deepEqual(bob.problems, [], 'bob\'s page reported errors');
});
