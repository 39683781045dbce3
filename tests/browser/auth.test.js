// Accounts in the web client against a real archgramd in Debian's chromium: signing in with
// the printed link or a pasted token, the share dialog, the role on a model shown in the top
// bar, read-only mode for viewers (no edit tools, no drag handles, ops refused without being
// sent), a role changed live, and access taken away. The accounts here are ordinary ones the
// test makes (not the harness's admins), so the server's role checks apply.
import assert from 'node:assert/strict';
import { test } from 'node:test';
import { daemonAndBrowser, openPage } from './browser.js';
import { facadeObj } from './facade.js';
import { versionOf, WAIT, waitJob } from './page.js';

const env = daemonAndBrowser();

const asAccount = (token) => (p, init = {}) => fetch(`${env.daemon.url}api/v1${p}`, {
  ...init, headers: { ...(init.headers || {}), Authorization: `Bearer ${token}` },
});

const hidden = (page, testid) => page.getByTestId(testid).isHidden();

test('sign in with the printed link or a pasted token; a bad token is refused; sign out', async () => {
  const page = await openPage(env.browser, { token: null });
  await page.goto(`${env.daemon.url}#token=${env.daemon.adminToken}`);
  await page.getByTestId('user-name').filter({ hasText: /^admin$/ }).waitFor(WAIT);
  assert.equal(await page.evaluate(() => location.hash), '', 'the token is out of the address bar');
  assert.equal(await page.evaluate(() => localStorage.getItem('archgram.token')), env.daemon.adminToken);
  assert.equal((await page.getByTestId('account-role').textContent()).trim(), 'admin');
  assert.ok(await hidden(page, 'signin'));
  await page.reload();
  await page.getByTestId('user-name').filter({ hasText: /^admin$/ }).waitFor(WAIT);
  await page.getByTestId('model-list').waitFor(WAIT);

  // Signed out, the page asks for a token and lists nothing meanwhile.
  await page.getByTestId('sign-out').click();
  await page.getByTestId('signin').waitFor({ state: 'visible', ...WAIT });
  assert.equal(await page.evaluate(() => localStorage.getItem('archgram.token')), null);
  assert.equal(await page.getByTestId('model-item').count(), 0);
  await page.getByTestId('signin-token').fill('agt_this-is-not-a-token-of-this-server');
  await page.getByTestId('signin-submit').click();
  await page.getByTestId('signin-message').filter({ hasText: 'does not know' }).waitFor(WAIT);
  assert.ok(!(await hidden(page, 'signin')));

  const paula = await env.daemon.makeAccount('paula', 'editor');
  await page.getByTestId('signin-token').fill(paula);
  await page.getByTestId('signin-submit').click();
  await page.getByTestId('signin').waitFor({ state: 'hidden', ...WAIT });
  await page.getByTestId('user-name').filter({ hasText: /^paula$/ }).waitFor(WAIT);
  assert.ok(await hidden(page, 'account-role'), 'an editor account needs no badge');
  assert.ok(!(await hidden(page, 'drop-zone')), 'an editor account may import');
});

test('share a model: the viewer reads only, an editor made live gets the tools, a removed one is shown out', async () => {
  const olgaToken = await env.daemon.makeAccount('olga', 'editor');
  const vicToken = await env.daemon.makeAccount('vic', 'editor');
  const olgaApi = asAccount(olgaToken);
  const vicApi = asAccount(vicToken);

  // Olga's proceduralized facade, made over REST with her token: she owns it.
  const up = await olgaApi('/models?name=shared-facade&format=obj', { method: 'POST', body: facadeObj(4, 2) });
  assert.equal(up.status, 202, await up.clone().text());
  const id = (await waitJob(olgaApi, await up.json())).result.model;
  const proc = await olgaApi(`/models/${id}/proceduralize`, { method: 'POST', headers: { 'Content-Type': 'application/json' }, body: '{}' });
  assert.equal(proc.status, 202, await proc.clone().text());
  await waitJob(olgaApi, await proc.json());
  assert.equal((await vicApi(`/models/${id}`)).status, 404, 'vic cannot see it before it is shared');

  const olga = await openPage(env.browser, { token: olgaToken });
  await olga.goto(`${env.daemon.url}#model=${id}`);
  await olga.getByTestId('model-role').filter({ hasText: 'owner' }).waitFor(WAIT);
  await olga.getByTestId('share').click();
  await olga.getByTestId('share-dialog').waitFor({ state: 'visible', ...WAIT });
  await olga.locator('[data-testid="share-members"] li[data-user="olga"]').waitFor(WAIT);
  await olga.getByTestId('share-user').fill('vic');
  await olga.getByTestId('share-role').selectOption('viewer');
  await olga.getByTestId('share-add').click();
  const vicRow = olga.locator('[data-testid="share-members"] li[data-user="vic"]');
  await vicRow.waitFor(WAIT);
  assert.equal(await vicRow.getByTestId('share-member-role').inputValue(), 'viewer');
  const members = await (await olgaApi(`/models/${id}/members`)).json();
  assert.deepEqual(members.items, [{ user: 'olga', role: 'owner' }, { user: 'vic', role: 'viewer' }]);

  // Vic, a viewer: the role is shown, there are no edit tools and no handles.
  const vic = await openPage(env.browser, { token: vicToken });
  await vic.goto(`${env.daemon.url}#model=${id}`);
  await vic.getByTestId('model-role').filter({ hasText: 'viewer' }).waitFor(WAIT);
  await vic.waitForFunction(() => window.archgram.tree, null, WAIT);
  await vic.getByTestId('read-only').waitFor({ state: 'visible', ...WAIT });
  assert.ok(await vic.locator('#edit .edit-body').isHidden(), 'edit tools for a viewer');
  assert.ok(await hidden(vic, 'proceduralize'));
  assert.ok(await hidden(vic, 'note-input'));
  assert.equal(await vic.getByTestId('model-name').getAttribute('contenteditable'), 'false');
  assert.equal(await vic.getByTestId('grammar-text').evaluate((t) => t.readOnly), true);
  assert.ok(await hidden(vic, 'grammar-apply'));
  assert.equal(await vic.evaluate(() => document.body.hasAttribute('data-read-only')), true, 'tool bars of the extrusion panes');
  const root = await vic.evaluate(() => window.archgram.tree.root);
  await vic.locator(`[data-testid="tree-node"][data-node="${root}"]`).click();
  await vic.getByTestId('picked-component').filter({ hasText: `node ${root}` }).waitFor(WAIT);
  assert.equal(await vic.evaluate(() => window.archgramTools.handles.group.children.length), 0, 'drag handles for a viewer');
  // an op is refused in the page, once, and never sent
  const v = await versionOf(vic);
  const got = await vic.evaluate(() => window.archgram.execute({ kind: 'rename', name: 'by vic' }));
  assert.equal(got, null);
  await vic.getByTestId('error').filter({ hasText: 'Read only' }).waitFor(WAIT);
  assert.equal((await (await olgaApi(`/models/${id}`)).json()).version, v, 'nothing reached the server');

  // Olga makes him an editor: his page follows at once, with tools and handles.
  await vicRow.getByTestId('share-member-role').selectOption('editor');
  await vic.getByTestId('model-role').filter({ hasText: 'editor' }).waitFor(WAIT);
  await vic.locator('#edit .edit-body').waitFor({ state: 'visible', ...WAIT });
  assert.ok(await hidden(vic, 'read-only'));
  assert.equal(await vic.evaluate(() => document.body.hasAttribute('data-read-only')), false);
  await vic.waitForFunction(() => window.archgramTools.handles.group.children.length > 0, null, WAIT);
  assert.equal(await vic.getByTestId('model-name').getAttribute('contenteditable'), 'plaintext-only');
  const renamed = await vic.evaluate(() => window.archgram.execute({ kind: 'rename', name: 'renamed by vic' }));
  assert.equal(renamed, v + 1);
  await olga.getByTestId('model-name').filter({ hasText: 'renamed by vic' }).waitFor(WAIT);
  const log = await (await olgaApi(`/models/${id}/ops?since=${v}`)).json();
  assert.deepEqual(log.items.map((o) => o.author), ['vic']);

  // Olga takes his access away: his page says so and closes the model.
  await vicRow.getByTestId('share-remove').click();
  await vicRow.waitFor({ state: 'detached', ...WAIT });
  await vic.getByTestId('error').filter({ hasText: 'No access' }).waitFor(WAIT);
  await vic.getByTestId('model-name').filter({ hasText: 'No model open' }).waitFor(WAIT);
  assert.equal((await vicApi(`/models/${id}`)).status, 404);
  assert.deepEqual(olga.problems, []);
  assert.deepEqual(vic.problems, []);
});
