// GET /api/v1/health and the OpenAPI document, checked against what the routes answer.
import assert from 'node:assert/strict';
import fs from 'node:fs';
import { after, before, describe, it } from 'node:test';
import { http, removeDir, startDaemon } from './harness.js';

describe('health and openapi', () => {
  let d;
  before(async () => { d = await startDaemon(); });
  after(async () => {
    if (d) { try { await d.stop(); } finally { await d.kill(); removeDir(d.dir); } }
  });

  it('health reports the version, the database and the websocket port', async () => {
    const r = await http(d, 'GET', '/api/v1/health');
    assert.equal(r.status, 200, r.text);
    assert.match(r.headers.get('content-type'), /^application\/json\b/);
    assert.equal(r.json.status, 'ok');
    assert.equal(r.json.version, '0.1.0');
    assert.equal(typeof r.json.db, 'object');
    assert.equal(fs.realpathSync(r.json.db.path), fs.realpathSync(d.db));
    assert.ok(Number.isInteger(r.json.db.schema_version) && r.json.db.schema_version >= 1,
      `schema_version: ${r.json.db.schema_version}`);
    assert.equal(r.json.ws_port, d.wsPort);
  });

  let doc;
  const norm = (p) => p.replace(/\{[^}]*\}/g, '{}');
  // Full paths: a server URL like "/api/v1" prefixes the documented paths.
  const fullPaths = () => {
    const prefix = (doc.servers?.[0]?.url ?? '').replace(/^https?:\/\/[^/]+/, '').replace(/\/$/, '');
    return Object.keys(doc.paths).map((p) => (p.startsWith('/api/') ? p : prefix + p));
  };

  it('openapi.json is an OpenAPI 3.1 document listing the API', async () => {
    const r = await http(d, 'GET', '/api/v1/openapi.json');
    assert.equal(r.status, 200, r.text.slice(0, 300));
    assert.match(r.headers.get('content-type'), /json/);
    assert.ok(r.json, 'openapi.json does not parse as JSON');
    doc = r.json;
    assert.match(doc.openapi, /^3\.1\.\d+$/);
    assert.equal(typeof doc.info?.title, 'string');
    assert.equal(doc.info?.version, '0.1.0');
    const paths = new Set(fullPaths().map(norm));
    for (const p of ['/api/v1/health', '/api/v1/openapi.json', '/api/v1/models', '/api/v1/models/{}',
      '/api/v1/models/{}/mesh.glb', '/api/v1/models/{}/ops', '/api/v1/jobs/{}']) {
      assert.ok(paths.has(p), `openapi.json lacks ${p}; has ${[...paths].join(', ')}`);
    }
    const ops = { '/api/v1/models': ['get', 'post'], '/api/v1/models/{}': ['get', 'patch', 'delete'],
      '/api/v1/jobs/{}': ['get', 'delete'], '/api/v1/models/{}/ops': ['get', 'post'] };
    const prefix = (p) => fullPaths()[Object.keys(doc.paths).indexOf(p)];
    for (const [p, methods] of Object.entries(ops)) {
      const key = Object.keys(doc.paths).find((k) => norm(prefix(k)) === p);
      for (const m of methods) {
        assert.ok(doc.paths[key][m], `openapi.json: ${p} has no ${m}`);
        assert.ok(doc.paths[key][m].responses, `openapi.json: ${m} ${p} has no responses`);
      }
    }
  });

  it('each documented path answers other methods with 405 and an Allow of the documented ones', async () => {
    assert.ok(doc, 'needs the previous test');
    const keys = Object.keys(doc.paths);
    const full = fullPaths();
    const verbs = ['get', 'put', 'post', 'delete', 'patch'];
    let checked = 0;
    for (let i = 0; i < keys.length; i++) {
      if (!full[i].startsWith('/api/v1/')) continue;
      const documented = verbs.filter((m) => doc.paths[keys[i]][m]);
      const probe = verbs.find((m) => !documented.includes(m));
      if (!probe) continue;
      const url = full[i].replace(/\{[^}]*\}/g, '1');
      const r = await http(d, probe.toUpperCase(), url, probe === 'get' ? {} : { body: {} });
      assert.equal(r.status, 405, `${probe.toUpperCase()} ${url} → ${r.status} ${r.text}`);
      const allow = (r.headers.get('allow') ?? '').split(',').map((s) => s.trim().toLowerCase())
        .filter((s) => s && s !== 'head' && s !== 'options');
      assert.deepEqual(allow.sort(), [...documented].sort(), `Allow for ${url}`);
      checked++;
    }
    assert.ok(checked >= 5, `only ${checked} paths checked`);
  });
});
