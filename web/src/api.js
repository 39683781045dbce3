// REST client for /api/v1. Every failure becomes an ApiError carrying an RFC 9457 problem
// ({type, title, status, detail, line?, element?}), whether the server sent one or not. Every
// request carries the signed-in person's token (auth.js): the server knows who asks from it
// alone.
const BASE = '/api/v1';

export class ApiError extends Error {
  constructor(problem) {
    super(problem.detail ? `${problem.title}: ${problem.detail}` : problem.title);
    this.name = 'ApiError';
    this.problem = problem;
    this.status = problem.status ?? 0;
  }
}

async function problemFrom(res) {
  const type = res.headers.get('Content-Type') || '';
  let text = '';
  try {
    text = await res.text();
  } catch {
    // body unreadable: fall back to the status line
  }
  if (type.includes('json') && text) {
    try {
      const body = JSON.parse(text);
      if (body && typeof body === 'object' && body.title) return { status: res.status, ...body };
    } catch {
      // not JSON after all
    }
  }
  return {
    type: 'about:blank',
    title: res.statusText || `HTTP ${res.status}`,
    status: res.status,
    detail: text.slice(0, 300) || undefined,
  };
}

function networkProblem(err, what) {
  return { type: 'urn:archgram:problem:network', title: 'Network error', status: 0, detail: `${what}: ${err.message}` };
}

export class Api {
  constructor() {
    this.auth = null; // auth.js: the token, and what to do when the server refuses it
    this.health = null;
  }

  useAuth(auth) {
    this.auth = auth;
  }

  authHeaders() {
    const token = this.auth?.token;
    return token ? { Authorization: `Bearer ${token}` } : {};
  }

  refused(res) {
    if (res.status === 401 && this.auth) this.auth.refused();
  }

  // An image the API serves (href as the server gives it, e.g. a part's versioned thumbnail)
  // as an object URL: an <img src> cannot send the bearer token. Kept per href.
  imageUrl(href) {
    if (!this.images) this.images = new Map();
    if (!this.images.has(href)) {
      const url = (async () => {
        const res = await fetch(href, { headers: this.authHeaders() });
        if (!res.ok) {
          this.refused(res);
          throw new ApiError(await problemFrom(res));
        }
        return URL.createObjectURL(await res.blob());
      })();
      url.catch(() => this.images.delete(href)); // tried again next time
      this.images.set(href, url);
    }
    return this.images.get(href);
  }

  async request(method, path, { body, headers = {}, raw = false } = {}) {
    const init = { method, headers: { Accept: 'application/json', ...this.authHeaders(), ...headers } };
    if (body !== undefined) {
      if (body instanceof Blob || body instanceof ArrayBuffer || typeof body === 'string') {
        init.body = body;
      } else {
        init.body = JSON.stringify(body);
        init.headers['Content-Type'] = 'application/json';
      }
    }
    let res;
    try {
      res = await fetch(BASE + path, init);
    } catch (err) {
      throw new ApiError(networkProblem(err, `${method} ${path}`));
    }
    if (!res.ok) {
      this.refused(res);
      throw new ApiError(await problemFrom(res));
    }
    if (raw) return res;
    if (res.status === 204) return null;
    const text = await res.text();
    try {
      return text ? JSON.parse(text) : null;
    } catch {
      throw new ApiError({ title: 'Bad response', status: res.status, detail: `${method} ${path} did not return JSON` });
    }
  }

  async getHealth() {
    if (!this.health) this.health = await this.request('GET', '/health');
    return this.health;
  }

  // --- the account and sharing ------------------------------------------------------------------
  getMe() {
    return this.request('GET', '/me');
  }

  // {model, public_read, items: [{user, role}]}
  getMembers(id) {
    return this.request('GET', `/models/${id}/members`);
  }

  share(id, user, role) {
    return this.request('PUT', `/models/${id}/members/${encodeURIComponent(user)}`, { body: { role } });
  }

  unshare(id, user) {
    return this.request('DELETE', `/models/${id}/members/${encodeURIComponent(user)}`);
  }

  setPublicRead(id, on) {
    return this.request('PUT', `/models/${id}/public`, { body: { public_read: on } });
  }

  listModels(pageToken = null, pageSize = 50) {
    const q = new URLSearchParams({ page_size: String(pageSize) });
    if (pageToken) q.set('page_token', pageToken);
    return this.request('GET', `/models?${q}`);
  }

  getModel(id) {
    return this.request('GET', `/models/${id}`);
  }

  getOps(id, since = 0) {
    return this.request('GET', `/models/${id}/ops?since=${since}`);
  }

  getJob(id) {
    return this.request('GET', `/jobs/${id}`);
  }

  cancelJob(id) {
    return this.request('DELETE', `/jobs/${id}`);
  }

  // The model's GLB as an ArrayBuffer (through request() so errors arrive as problems).
  async meshBuffer(model) {
    const path = (model.mesh || `${BASE}/models/${model.id}/mesh.glb`).replace(BASE, '');
    const res = await this.request('GET', path, { raw: true, headers: { Accept: 'model/gltf-binary' } });
    return res.arrayBuffer();
  }

  // --- point clouds ---------------------------------------------------------------------------
  // The first `budget` points of a point cloud model's level-of-detail order as GLB POINTS.
  async pointsBuffer(model, budget) {
    const res = await this.request('GET', `/models/${model.id}/points.glb?budget=${budget}`, {
      raw: true,
      headers: { Accept: 'model/gltf-binary' },
    });
    return res.arrayBuffer();
  }

  // At most `budget` of the points a proceduralized cloud's grammar derives, as binary PLY
  // (derivedpoints.js).
  async derivedBuffer(model, budget) {
    const res = await this.request('GET', `/models/${model.id}/derived.ply?budget=${budget}`, { raw: true, headers: { Accept: 'application/x-ply' } });
    return res.arrayBuffer();
  }

  // Starts the segment job against the version the person sees (412 if the model moved on).
  segment(id, version, params = {}) {
    const headers = version != null ? { 'If-Match': `"${version}"` } : {};
    return this.request('POST', `/models/${id}/segment`, { body: params, headers });
  }

  // REST fallbacks for edits when the live connection is down.
  rename(id, version, name) {
    return this.request('PATCH', `/models/${id}`, { body: { name }, headers: { 'If-Match': `"${version}"` } });
  }

  postOp(id, version, cid, op) {
    return this.request('POST', `/models/${id}/ops`, { body: { cid, op }, headers: { 'If-Match': `"${version}"` } });
  }

  // --- proceduralization ----------------------------------------------------------------------
  // Starts the job against the version the person sees (412 if the model moved on).
  proceduralize(id, version, options = {}) {
    const headers = version != null ? { 'If-Match': `"${version}"` } : {};
    return this.request('POST', `/models/${id}/proceduralize`, { body: options, headers });
  }

  getTree(id) {
    return this.request('GET', `/models/${id}/tree`);
  }

  // The grammar text and the model version it belongs to (its ETag).
  async getGrammar(id) {
    const res = await this.request('GET', `/models/${id}/grammar`, { raw: true, headers: { Accept: 'text/plain' } });
    const text = await res.text();
    const version = Number(/\d+/.exec(res.headers.get('ETag') || '')?.[0] ?? NaN);
    return { text, version: Number.isFinite(version) ? version : null };
  }

  // Replaces the grammar; resolves with the model JSON of the new version.
  putGrammar(id, version, text) {
    return this.request('PUT', `/models/${id}/grammar`, {
      body: new Blob([text], { type: 'text/plain; charset=utf-8' }),
      headers: { 'If-Match': `"${version}"` },
    });
  }

  // Uploads a file as the raw request body; XMLHttpRequest because fetch reports no upload
  // progress. Resolves with the job object of the 202 answer.
  uploadModel(file, { name, format, up } = {}, onProgress = () => {}) {
    const q = new URLSearchParams({ name: name ?? file.name, format });
    if (up) q.set('up', up);
    const path = `/models?${q}`;
    return new Promise((resolve, reject) => {
      const xhr = new XMLHttpRequest();
      xhr.open('POST', BASE + path);
      xhr.setRequestHeader('Content-Type', 'application/octet-stream');
      xhr.setRequestHeader('Accept', 'application/json');
      for (const [k, v] of Object.entries(this.authHeaders())) xhr.setRequestHeader(k, v);
      xhr.upload.onprogress = (e) => {
        if (e.lengthComputable) onProgress(e.loaded / e.total);
      };
      xhr.onerror = () => reject(new ApiError(networkProblem(new Error('upload failed'), `POST ${path}`)));
      xhr.onload = () => {
        const headers = new Headers({ 'Content-Type': xhr.getResponseHeader('Content-Type') || '' });
        const res = new Response(xhr.status === 204 ? null : xhr.responseText, {
          status: xhr.status,
          statusText: xhr.statusText,
          headers,
        });
        if (!res.ok) {
          this.refused(res);
          problemFrom(res).then((p) => reject(new ApiError(p)));
          return;
        }
        res.text().then((text) => {
          try {
            resolve(JSON.parse(text));
          } catch {
            reject(new ApiError({ title: 'Bad response', status: xhr.status, detail: 'the upload answer was not JSON' }));
          }
        });
      };
      xhr.send(file);
    });
  }

  // --- extrusions -----------------------------------------------------------------------------
  // GeoJSON footprints or a building description → the extrude job (202).
  uploadExtrusion(file, { name, style } = {}) {
    const q = new URLSearchParams({ name: name ?? file.name });
    if (style) q.set('style', style);
    return this.request('POST', `/extrusions?${q}`, { body: file });
  }

  // The stored description(s) of an extrusion model (a batch: {buildings: [...]}).
  getPlan(id) {
    return this.request('GET', `/models/${id}/plan`);
  }

  // One building description extruded without storing anything: the shell's GLB bytes.
  async previewExtrusion(plan) {
    const res = await this.request('POST', '/extrusions/preview', { body: plan, raw: true, headers: { Accept: 'model/gltf-binary' } });
    return res.arrayBuffer();
  }

  // --- the parts library ----------------------------------------------------------------------
  // A page of parts: q (words), tag, pageToken.
  listParts({ q = '', tag = '', pageToken = null, pageSize = 50 } = {}) {
    const p = new URLSearchParams({ page_size: String(pageSize) });
    if (q) p.set('q', q);
    if (tag) p.set('tag', tag);
    if (pageToken) p.set('page_token', pageToken);
    return this.request('GET', `/parts?${p}`);
  }

  getPart(id) {
    return this.request('GET', `/parts/${id}`);
  }

  // Saves a node (or a selection's common ancestor) of a model at a version as a part.
  savePart(body) {
    return this.request('POST', '/parts', { body });
  }

  deletePart(id, version) {
    return this.request('DELETE', `/parts/${id}`, { headers: { 'If-Match': `"${version}"` } });
  }

  // The common ancestors of selected nodes: {tree, rule: [...]} (server/core/parts/select.h).
  selectionOf(model, version, nodes) {
    const p = new URLSearchParams({ nodes: nodes.join(','), version: String(version) });
    return this.request('GET', `/models/${model}/selection?${p}`);
  }

  // A compose op run without storing it: the GLB bytes of what it would make and how many
  // instances it changes.
  async previewCompose(model, version, op) {
    const res = await this.request('POST', `/models/${model}/compose-preview`, {
      body: { op },
      raw: true,
      headers: { Accept: 'model/gltf-binary', 'If-Match': `"${version}"` },
    });
    return { buffer: await res.arrayBuffer(), instances: Number(res.headers.get('X-Archgram-Instances') ?? NaN) };
  }
}
