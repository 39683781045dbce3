// The parts library in the web client against a real archgramd in Debian's chromium: a person
// clicks a window's piece in building A and walks up to the window with the arrow keys,
// selects a whole window with a selection window, saves the selection as a part from the
// library panel (name, tags, description), finds it by search and tag, opens building B,
// composes the part into B's window slots (scope rule) with a preview in the view before it
// commits, then drops it from the library onto a window, and undoes. The served trees check
// what was made: every slot of B holds the part's pieces, its frame bars keep their width.
import assert from 'node:assert/strict';
import { test } from 'node:test';
import { windowWallObj } from '../integration/harness.js';
import { daemonAndBrowser, openPage } from './browser.js';
import { WAIT, versionOf, waitJob as waitJobOver, waitMesh, waitVersion } from './page.js';

const env = daemonAndBrowser();
const api = async (p, init) => fetch(`${env.daemon.url}api/v1${p}`, init);

const waitJob = (job) => waitJobOver(api, job);

async function proceduralized(opt, name) {
  const { obj, slots } = windowWallObj(opt);
  const res = await api(`/models?name=${name}&format=obj&up=z`, { method: 'POST', body: obj });
  assert.equal(res.status, 202, await res.clone().text());
  const id = (await waitJob(await res.json())).result.model;
  const proc = await api(`/models/${id}/proceduralize`, { method: 'POST', headers: { 'Content-Type': 'application/json' }, body: '{}' });
  assert.equal(proc.status, 202, await proc.clone().text());
  await waitJob(await proc.json());
  return { id, slots };
}

const treeOf = async (id) => (await api(`/models/${id}/tree`)).json();
const grammarOf = async (id) => (await api(`/models/${id}/grammar`)).text();
const near = (a, b) => a.every((x, i) => Math.abs(x - b[i]) < 1e-6);
const inSlot = (n, s) => n.box.every((x, i) => (i < 3 ? x >= s[i] - 1e-6 : x <= s[i] + 1e-6));
const pieces = (t, s) => t.nodes.filter((n) => n.kind === 'component' && inSlot(n, s));
const waitTree = (page, v) => page.waitForFunction((want) => window.archgram.tree?.version === want, v, WAIT);
const selected = (page) => page.evaluate(() => window.archgram.selected.nodeIds());

// Where a world box (archgram axes) is drawn: its centre and its screen rectangle, in page pixels.
async function onScreen(page, box) {
  const r = await page.evaluate((b) => {
    const vp = window.archgramTools.viewport;
    const pts = [];
    for (let k = 0; k < 8; k++) {
      const x = k & 1 ? b[3] : b[0];
      const y = k & 2 ? b[4] : b[1];
      const z = k & 4 ? b[5] : b[2];
      // archgram (x, y, z) is three.js (x, z, -y); the camera's position is a THREE.Vector3
      pts.push(vp.toScreen(new vp.camera.position.constructor(x, z, -y)));
    }
    const xs = pts.map((p) => p.x);
    const ys = pts.map((p) => p.y);
    return { x0: Math.min(...xs), x1: Math.max(...xs), y0: Math.min(...ys), y1: Math.max(...ys) };
  }, box);
  const c = await page.locator('#viewport canvas').boundingBox();
  return { x0: c.x + r.x0, x1: c.x + r.x1, y0: c.y + r.y0, y1: c.y + r.y1, cx: c.x + (r.x0 + r.x1) / 2, cy: c.y + (r.y0 + r.y1) / 2 };
}

test('save a selection as a part, find it, compose it into another building with a preview, undo', async () => {
  // windows standing proud of their walls, so the view shows them
  const A = await proceduralized({ cols: 3, rows: 2, ww: 1.2, wh: 1.8, frame: 0.08, mullions: 1, front: -0.2 }, 'a');
  const B = await proceduralized({ cols: 4, rows: 2, ww: 1.6, wh: 2.0, frame: 0.12, mullions: 2, front: -0.2 }, 'b');
  const tA = await treeOf(A.id);
  const slot = A.slots[1];
  const windowNode = tA.nodes.find((n) => n.kind === 'component' && near(n.box, slot)).id;

  const page = await openPage(env.browser, { user: 'carla', viewport: { width: 1400, height: 900 } });
  await page.goto(`${env.daemon.url}#model=${A.id}`);
  await waitMesh(page, tA.version);
  await waitTree(page, tA.version);

  // click then walk: the window in the view (its casing holds its pieces), then the tree
  const p = await onScreen(page, slot);
  await page.mouse.click(p.cx, p.cy);
  await page.waitForFunction(() => window.archgram.selected.single() !== null, null, WAIT);
  assert.deepEqual(await selected(page), [windowNode]);
  await page.getByTestId('library-selection').filter({ hasText: `node ${windowNode}` }).waitFor(WAIT);
  const inWindow = new Set(pieces(tA, slot).map((n) => n.id));
  const under = (id) => { // a node below the window (split nodes skipped by the walk)
    for (let n = tA.nodes[id]; n && n.parent !== null; n = tA.nodes[n.parent]) if (n.parent === windowNode) return true;
    return false;
  };
  await page.keyboard.press('ArrowDown'); // its first child
  const c1 = (await selected(page))[0];
  assert.ok(c1 !== windowNode && under(c1), `child ${c1}`);
  assert.ok(inWindow.has(c1) || tA.nodes[c1].kind === 'pattern', `child ${c1} is a piece or a pattern of pieces`);
  await page.keyboard.press('ArrowRight'); // the next sibling
  const c2 = (await selected(page))[0];
  assert.ok(c2 !== c1 && under(c2), `sibling ${c2}`);
  await page.keyboard.press('ArrowLeft');
  assert.deepEqual(await selected(page), [c1]);
  await page.keyboard.press('ArrowUp');
  assert.deepEqual(await selected(page), [windowNode]);
  await page.keyboard.press('ArrowUp'); // the pattern of the windows, not a split node
  assert.equal(tA.nodes[(await selected(page))[0]].kind, 'pattern');
  await page.keyboard.press('ArrowDown');
  assert.equal(tA.nodes[(await selected(page))[0]].kind, 'component');

  // select by window: a rectangle around the window takes its pieces, nothing else
  const w = await onScreen(page, slot);
  await page.getByTestId('window-select').click();
  await page.mouse.move(w.x0 - 4, w.y0 - 4);
  await page.mouse.down();
  await page.mouse.move(w.cx, w.cy, { steps: 3 });
  await page.mouse.move(w.x1 + 4, w.y1 + 4, { steps: 3 });
  await page.mouse.up();
  await page.getByTestId('window-select').click();
  const inside = (await selected(page)).sort((a, b) => a - b);
  assert.deepEqual(inside, pieces(tA, slot).map((n) => n.id).sort((a, b) => a - b));
  // several nodes: their common ancestor (the window) is what a save takes
  await page.locator(`[data-testid="ancestor-tree"][data-node="${windowNode}"]`).waitFor(WAIT);

  // save the selection as a part
  await page.getByTestId('part-name').fill('sash window');
  await page.getByTestId('part-tags').fill('window, timber');
  await page.getByTestId('part-description').fill('one mullion');
  await page.getByTestId('save-part').click();
  await page.locator('[data-testid="library-part"][data-name="sash window"]').waitFor(WAIT);
  await page.getByTestId('part-title').filter({ hasText: 'sash window' }).waitFor(WAIT);
  const parts = await (await api('/parts?q=sash')).json();
  assert.equal(parts.items.length, 1);
  const part = await (await api(`/parts/${parts.items[0].id}`)).json();
  assert.equal(part.versions[0].source.node, windowNode);
  assert.deepEqual(part.tags, ['window', 'timber']);
  // a thumbnail loads in the list
  await page.waitForFunction((id) => {
    const img = document.querySelector(`[data-testid="library-part"][data-part="${id}"] img`);
    return img && img.complete && img.naturalWidth === 128;
  }, part.id, WAIT);

  // find it: words and tags
  const count = () => page.getByTestId('library-list').getAttribute('data-count').then(Number);
  await page.getByTestId('library-search').fill('mull');
  await page.waitForFunction(() => document.querySelector('[data-testid="library-list"]').dataset.count === '1', null, WAIT);
  await page.getByTestId('library-search').fill('chimney');
  await page.waitForFunction(() => document.querySelector('[data-testid="library-list"]').dataset.count === '0', null, WAIT);
  await page.getByTestId('library-search').fill('');
  await page.getByTestId('library-tag').selectOption('timber');
  await page.waitForFunction(() => document.querySelector('[data-testid="library-list"]').dataset.count === '1', null, WAIT);
  assert.equal(await count(), 1);

  // building B: compose into every window slot, previewed first
  const tB = await treeOf(B.id);
  const g0 = await grammarOf(B.id);
  await page.goto(`${env.daemon.url}#model=${B.id}`);
  await waitMesh(page, tB.version);
  await waitTree(page, tB.version);
  const target = tB.nodes.find((n) => n.kind === 'component' && near(n.box, B.slots[2])).id;
  const t2 = await onScreen(page, B.slots[2]);
  await page.mouse.click(t2.cx, t2.cy);
  await page.waitForFunction((want) => window.archgram.selected.single() === want, target, WAIT);
  await page.locator(`[data-testid="library-part"][data-part="${part.id}"]`).click();
  await page.getByTestId('compose-here').click();
  await page.getByTestId('compose-form').waitFor(WAIT);
  await page.getByTestId('compose-scope').selectOption('rule');
  await page.locator('[data-testid="compose-status"][data-state="ok"]').waitFor(WAIT);
  assert.equal(await page.locator('#viewport').getAttribute('data-compose-preview'), String(B.slots.length));
  assert.equal(await versionOf(page), tB.version); // nothing stored yet
  await page.getByTestId('compose-commit').click();
  await waitVersion(page, tB.version + 1);
  await waitMesh(page, tB.version + 1);
  const t1 = await treeOf(B.id);
  for (const s of B.slots) {
    const ps = pieces(t1, s);
    assert.equal(ps.length, 7, `slot ${s}`);
    assert.equal(ps.filter((n) => Math.abs(n.box[3] - n.box[0] - 0.08) < 1e-6).length, 2, `jambs of ${s}`);
  }
  const ops = (await (await api(`/models/${B.id}/ops?since=${tB.version}`)).json()).items;
  assert.equal(ops[0].op.kind, 'compose');
  assert.equal(ops[0].op.report.instances, B.slots.length);

  // drop it from the library onto one window of B: a composition of that node, previewed
  await waitTree(page, t1.version);
  const one = pieces(t1, B.slots[5]).sort((a, b) => (b.box[3] - b.box[0]) * (b.box[5] - b.box[2]) - (a.box[3] - a.box[0]) * (a.box[5] - a.box[2]))[0];
  const drop = await onScreen(page, one.box);
  const canvas = page.locator('#viewport canvas');
  const cb = await canvas.boundingBox();
  await page.locator(`[data-testid="library-part"][data-part="${part.id}"]`).dragTo(canvas, { targetPosition: { x: drop.cx - cb.x, y: drop.cy - cb.y } });
  await page.getByTestId('compose-form').waitFor(WAIT);
  await page.locator('[data-testid="compose-status"][data-state="ok"]').waitFor(WAIT);
  const dropped = await page.evaluate(() => window.archgram.library.draft);
  assert.equal(dropped.part, part.id);
  assert.ok(pieces(t1, B.slots[5]).some((n) => n.id === dropped.target), `dropped on ${dropped.target}`);
  await page.getByTestId('compose-cancel').click();
  await page.getByTestId('compose-form').waitFor({ state: 'hidden', ...WAIT });
  assert.equal(await page.locator('#viewport').getAttribute('data-compose-preview'), null);

  // undo: B's grammar as it was, byte for byte
  await page.keyboard.press('Control+z');
  await waitVersion(page, tB.version + 2);
  assert.equal(await grammarOf(B.id), g0);
  assert.deepEqual(page.problems, []);
});
