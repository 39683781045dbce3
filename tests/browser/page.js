// What the browser tests wait for on a page: the model version in the toolbar, the mesh of a
// version on screen, an uploaded file's model opened; and a job over REST.
import assert from 'node:assert/strict';

export const WAIT = { timeout: 30000 };

// Follows a job over REST (api(path) fetches below /api/v1) until it ends; it must succeed.
export const versionOf = async (page) => Number((await page.getByTestId('model-version').textContent()).replace(/\D/g, ''));

export const waitVersion = (page, v) =>
  page.waitForFunction((want) => Number(document.querySelector('[data-testid="model-version"]').textContent.replace(/\D/g, '')) === want, v, WAIT);

// The viewport shows the mesh of version v.
export const waitMesh = (page, v) => page.locator(`#viewport[data-version="${v}"]`).waitFor({ state: 'attached', ...WAIT });

export const centre = async (locator) => {
  const b = await locator.boundingBox();
  return { x: b.x + b.width / 2, y: b.y + b.height / 2 };
};

// Gives a file (a path, or {name, mimeType, buffer}) to a file input, waits for its job to
// succeed and its model to open; resolves with the model's id.
export async function uploadAndOpen(page, testid, file) {
  await page.getByTestId(testid).setInputFiles(file);
  await page.locator('[data-testid="job"][data-status="succeeded"]').waitFor(WAIT);
  await page.waitForFunction(() => /^#model=\d+$/.test(location.hash), null, WAIT);
  return Number((await page.evaluate(() => location.hash)).replace(/\D/g, ''));
}

// Polls a job through api (path under /api/v1 → fetch Response) until it ends; it must succeed.
export async function waitJob(api, job) {
  const deadline = Date.now() + 60000;
  while (!['succeeded', 'failed', 'cancelled'].includes(job.status)) {
    assert.ok(Date.now() < deadline, `job ${job.id} did not finish`);
    await new Promise((r) => setTimeout(r, 100));
    job = await (await api(`/jobs/${job.id}`)).json();
  }
  assert.equal(job.status, 'succeeded', JSON.stringify(job.error));
  return job;
}
