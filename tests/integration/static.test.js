// --web DIR: the static client at / and its files; nothing outside DIR is served.
import assert from 'node:assert/strict';
import fs from 'node:fs';
import path from 'node:path';
import { after, before, describe, it } from 'node:test';
import { http, rawRequest, removeDir, startDaemon, tempDir } from './harness.js';

describe('static client', () => {
  const dir = tempDir();
  const web = path.join(dir, 'web');
  let d;
  before(async () => {
    fs.mkdirSync(path.join(web, 'sub'), { recursive: true });
    fs.writeFileSync(path.join(web, 'index.html'), '<!doctype html><title>archgram test page</title>\n');
    fs.writeFileSync(path.join(web, 'app.js'), 'export const marker = "archgram-test-js";\n');
    fs.writeFileSync(path.join(web, 'sub', 'style.css'), 'body { color: #123456 }\n');
    fs.writeFileSync(path.join(dir, 'secret.txt'), 'archgram-secret-outside-web\n');
    d = await startDaemon({ dir, args: ['--web', web] });
  });
  after(async () => {
    if (d) { try { await d.stop(); } finally { await d.kill(); removeDir(dir); } }
  });

  it('/ serves index.html, files get their content types', async () => {
    let r = await http(d, 'GET', '/');
    assert.equal(r.status, 200);
    assert.match(r.headers.get('content-type'), /^text\/html/);
    assert.match(r.text, /archgram test page/);
    r = await http(d, 'GET', '/app.js');
    assert.equal(r.status, 200);
    assert.match(r.headers.get('content-type'), /javascript/);
    assert.match(r.text, /archgram-test-js/);
    r = await http(d, 'GET', '/sub/style.css');
    assert.equal(r.status, 200);
    assert.match(r.headers.get('content-type'), /^text\/css/);
    r = await http(d, 'GET', '/no-such-file.js');
    assert.equal(r.status, 404);
  });

  it('paths that climb out of the web directory are refused', async () => {
    for (const p of ['/../secret.txt', '/%2e%2e/secret.txt', '/..%2fsecret.txt', '/sub/../../secret.txt',
      '/%2e%2e%2fsecret.txt', '/sub/%2e%2e/%2e%2e/secret.txt']) {
      const r = await rawRequest(d.port, `GET ${p} HTTP/1.1\r\nHost: 127.0.0.1\r\nConnection: close\r\n\r\n`);
      assert.ok(r.status >= 400 && r.status < 500, `GET ${p} → ${r.status}`);
      assert.doesNotMatch(r.text, /archgram-secret-outside-web/, `GET ${p} leaked a file outside --web`);
    }
  });
});
