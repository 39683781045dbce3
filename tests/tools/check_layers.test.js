// tools/check_layers.py on small synthetic trees: a clean tree passes, and each kind of
// planted violation (an include across or up the layers, a symbol from a layer or a system
// library the layer may not use) fails naming the file and line or the archive member and
// symbol. The allowlist lets a named violation pass, and an entry matching nothing fails.
import assert from 'node:assert/strict';
import { spawnSync } from 'node:child_process';
import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';
import { test } from 'node:test';
import { fileURLToPath } from 'node:url';

const REPO = path.resolve(path.dirname(fileURLToPath(import.meta.url)), '..', '..');
const CHECKER = path.join(REPO, 'tools', 'check_layers.py');
const CC = process.env.CC || 'cc';

// A minimal tree that follows the matrix: each layer calls the one below, net calls app and
// the status function of core/status.h.
const CLEAN = {
  'server/core/status.h': 'int ag_status_http(int s);\n',
  'server/core/status.c': '#include "status.h"\nint ag_status_http(int s) { return s ? 500 : 200; }\n',
  'server/core/mesh.h': 'double ag_mesh_area(double a);\n',
  'server/core/mesh.c': '#include <math.h>\n#include "mesh.h"\n#include "status.h"\ndouble ag_mesh_area(double a) { return sqrt(a) + ag_status_http(0); }\n',
  'server/io/glb.h': '#include "../core/mesh.h"\nint ag_glb_write(void);\n',
  'server/io/glb.c': '#include "glb.h"\n#include <jansson.h>\nint ag_glb_write(void) { json_t *j = json_object(); json_decref(j); return (int)ag_mesh_area(4); }\n',
  'server/store/db.h': 'int ag_db_open(void);\n',
  'server/store/db.c': '#include "db.h"\n#include "../io/glb.h"\n#include <sqlite3.h>\nint ag_db_open(void) { return ag_glb_write() + (int)sqlite3_libversion_number(); }\n',
  'server/app/app.h': 'int ag_app_start(void);\n',
  'server/app/app.c': '#include "app.h"\n#include "../store/db.h"\n#include <pthread.h>\nint ag_app_start(void) { return ag_db_open() + (int)(pthread_self() != 0); }\n',
  'server/net/http.c': '#include "../app/app.h"\n#include "../core/status.h"\n#include <microhttpd.h>\nint ag_http_start(void) { return ag_app_start() + ag_status_http(1) + (int)MHD_is_feature_supported(MHD_FEATURE_IPv6); }\n',
  'server/main.c': '#include "store/db.h"\n#include "io/glb.h"\nint main(void) { return ag_db_open(); }\n',
};

function compile(root, rel) {
  const o = path.join(root, 'build', rel.replace(/\.c$/, '.o'));
  fs.mkdirSync(path.dirname(o), { recursive: true });
  const r = spawnSync(CC, ['-c', '-w', '-I/usr/include/suitesparse', path.join(root, rel), '-o', o], { encoding: 'utf8' });
  assert.equal(r.status, 0, `${rel}: ${r.stderr}`);
}

function writeFiles(root, files) {
  for (const [rel, text] of Object.entries(files)) {
    fs.mkdirSync(path.dirname(path.join(root, rel)), { recursive: true });
    fs.writeFileSync(path.join(root, rel), text);
  }
}

// The clean tree is compiled once; each test copies it and compiles only what it plants.
let cleanTree;
process.on('exit', () => { if (cleanTree) fs.rmSync(cleanTree, { recursive: true, force: true }); });

function makeTree(overrides = {}) {
  if (!cleanTree) {
    cleanTree = fs.mkdtempSync(path.join(os.tmpdir(), 'archgram-layers-clean-'));
    writeFiles(cleanTree, CLEAN);
    for (const rel of Object.keys(CLEAN).filter((f) => f.endsWith('.c'))) compile(cleanTree, rel);
  }
  const root = fs.mkdtempSync(path.join(os.tmpdir(), 'archgram-layers-'));
  fs.cpSync(cleanTree, root, { recursive: true });
  writeFiles(root, overrides);
  for (const rel of Object.keys(overrides).filter((f) => f.endsWith('.c'))) compile(root, rel);
  const files = { ...CLEAN, ...overrides };
  // one archive per layer, as the Makefile builds them
  const lib = path.join(root, 'build', 'lib');
  fs.mkdirSync(lib, { recursive: true });
  for (const layer of ['core', 'io', 'store', 'app', 'net']) {
    const objs = Object.keys(files)
      .filter((f) => f.startsWith(`server/${layer}/`) && f.endsWith('.c'))
      .map((rel) => path.join(root, 'build', rel.replace(/\.c$/, '.o')));
    const r = spawnSync('ar', ['rcs', path.join(lib, `libag_${layer}.a`), ...objs], { encoding: 'utf8' });
    assert.equal(r.status, 0, r.stderr);
  }
  return root;
}

function check(root, allow = '') {
  const allowFile = path.join(root, 'layers.allow');
  fs.writeFileSync(allowFile, allow);
  const r = spawnSync('python3', [CHECKER, '--root', root, '--lib', path.join(root, 'build', 'lib'), '--allow', allowFile], { encoding: 'utf8', timeout: 60000 });
  fs.rmSync(root, { recursive: true, force: true });
  return r;
}

test('a tree that follows the matrix passes', () => {
  const r = check(makeTree());
  assert.equal(r.status, 0, r.stderr);
  assert.match(r.stdout, /check-layers: ok/);
});

test('core including a store header fails naming file and line', () => {
  const r = check(makeTree({
    'server/core/bad.c': '/* planted */\n#include "../store/db.h"\nint ag_bad(void) { return 0; }\n',
  }));
  assert.equal(r.status, 1, r.stdout + r.stderr);
  assert.match(r.stderr, /^server\/core\/bad\.c:2: includes server\/store\/db\.h \(store, up the layers\): core may use nothing but itself$/m);
});

test('net including store and io headers (skipping app) fails; core/status.h is allowed', () => {
  const r = check(makeTree({
    'server/net/live.c': '#include "../core/status.h"\n#include "../store/db.h"\n#include "../io/glb.h"\nint ag_live(void) { return ag_status_http(0); }\n',
  }));
  assert.equal(r.status, 1);
  assert.match(r.stderr, /^server\/net\/live\.c:2: includes server\/store\/db\.h \(store\): net may use app, core\/status\.h$/m);
  assert.match(r.stderr, /^server\/net\/live\.c:3: includes server\/io\/glb\.h \(io\): net may use app, core\/status\.h$/m);
  assert.doesNotMatch(r.stderr, /live\.c:1:/);
  // io/glb.h includes core/mesh.h: only direct includes count, and the symbols are clean
  assert.doesNotMatch(r.stderr, /libag_net/);
});

test('a symbol from a layer the archive may not use fails naming member and symbol, even without the include', () => {
  const r = check(makeTree({
    'server/net/api.c': 'int ag_db_open(void);\ndouble ag_mesh_area(double);\nint ag_api(void) { return ag_db_open() + (int)ag_mesh_area(1); }\n',
    'server/core/up.c': 'int ag_glb_write(void);\nint ag_up(void) { return ag_glb_write(); }\n',
  }));
  assert.equal(r.status, 1);
  assert.match(r.stderr, /build\/lib\/libag_net\.a\(api\.o\): ag_db_open is defined in store \(db\.o\): net may use app, core\/status\.h/);
  assert.match(r.stderr, /build\/lib\/libag_net\.a\(api\.o\): ag_mesh_area is defined in core \(mesh\.o\): net may use app, core\/status\.h/);
  assert.match(r.stderr, /build\/lib\/libag_core\.a\(up\.o\): ag_glb_write is defined in io \(glb\.o, up the layers\)/);
});

test('a system library the layer may not use fails: by header and by symbol', () => {
  const r = check(makeTree({
    'server/core/json.c': '#include <jansson.h>\nint ag_json(void) { return json_object() != 0; }\n',
    'server/core/db2.c': 'int sqlite3_libversion_number(void);\nint ag_v(void) { return sqlite3_libversion_number(); }\n',
    'server/io/threads.c': '#include <pthread.h>\nint ag_t(void) { return pthread_self() != 0; }\n',
    'server/core/thr.c': '#include <threads.h>\nint ag_thr(void) { return 0; }\n',
  }));
  assert.equal(r.status, 1);
  assert.match(r.stderr, /^server\/core\/json\.c:1: includes <jansson\.h> \(libjansson\): core may use libc, libm, libcholmod, libspqr, libsuitesparseconfig$/m);
  assert.match(r.stderr, /libag_core\.a\(json\.o\): json_object is defined by no library core may use \(.*\); it is in libjansson/);
  assert.match(r.stderr, /libag_core\.a\(db2\.o\): sqlite3_libversion_number is defined by no library core may use .*; it is in libsqlite3/);
  assert.match(r.stderr, /^server\/io\/threads\.c:1: includes <pthread\.h> \(libpthread\): io may use/m);
  assert.match(r.stderr, /^server\/core\/thr\.c:1: includes <threads\.h>: core does no threads/m);
});

test('the allowlist lets a named violation pass; a stale entry fails', () => {
  const planted = {
    'server/net/live.c': '#include "../store/db.h"\nint ag_live(void) { return ag_db_open(); }\n',
  };
  const allow = '# known\nserver/net/live.c -> server/store/db.h\nlibag_net.a(live.o) -> ag_db_open\n';
  const ok = check(makeTree(planted), allow);
  assert.equal(ok.status, 0, ok.stderr);
  assert.match(ok.stdout, /2 known violations allowed/);
  const partial = check(makeTree(planted), 'server/net/live.c -> server/store/db.h\n');
  assert.equal(partial.status, 1);
  assert.match(partial.stderr, /libag_net\.a\(live\.o\): ag_db_open is defined in store/);
  const stale = check(makeTree(), allow);
  assert.equal(stale.status, 1);
  assert.match(stale.stderr, /layers\.allow:2: 'server\/net\/live\.c -> server\/store\/db\.h' matches no violation any more/);
  assert.match(stale.stderr, /layers\.allow:3: 'libag_net\.a\(live\.o\) -> ag_db_open' matches no violation/);
});

test('two sources of one name in a layer fail (ar would keep one)', () => {
  const r = check(makeTree({
    'server/core/a/dup.c': 'int ag_dup_a(void) { return 1; }\n',
    'server/core/b/dup.c': 'int ag_dup_b(void) { return 2; }\n',
  }));
  assert.equal(r.status, 1);
  assert.match(r.stderr, /dup\.c: same file name as server\/core\/[ab]\/dup\.c/);
});

test('a missing archive is an error, not a pass', () => {
  const root = makeTree();
  fs.rmSync(path.join(root, 'build', 'lib', 'libag_app.a'));
  const r = check(root);
  assert.equal(r.status, 2);
  assert.match(r.stderr, /libag_app\.a is missing/);
});
