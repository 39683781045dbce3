// schema/plan.schema.json agrees with the building descriptions the engine reads: every
// fixture validates, and typical mistakes are refused.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import fs from 'node:fs';
import path from 'node:path';
import Ajv2020 from 'ajv/dist/2020.js';
import { REPO } from './harness.js';

const schema = JSON.parse(fs.readFileSync(path.join(REPO, 'schema', 'plan.schema.json'), 'utf8'));
const ajv = new Ajv2020({ allErrors: true, strict: false });
const validate = ajv.compile(schema);
const jsonIn = (dir) => fs.readdirSync(path.join(REPO, 'tests', 'data', dir))
  .filter((f) => f.endsWith('.json')).map((f) => path.join(REPO, 'tests', 'data', dir, f));

test('every building description fixture validates against plan.schema.json', () => {
  const files = [...jsonIn('extrude'), ...jsonIn('extrude_service').filter((f) => f.endsWith('plan.json')),
    path.join(REPO, 'tests', 'data', 'extrude_web', 'house_plan.json')];
  assert.ok(files.length >= 30, `${files.length} fixtures`);
  for (const f of files) {
    const ok = validate(JSON.parse(fs.readFileSync(f, 'utf8')));
    assert.ok(ok, `${path.relative(REPO, f)}: ${ajv.errorsText(validate.errors)}`);
  }
});

test('plan.schema.json refuses typical mistakes', () => {
  const base = { loops: [[[0, 0], [10, 0], [10, 6], [0, 6]]], profiles: { hip: [[0, 0], [0, 3], [1, 4]] } };
  assert.ok(validate(base), ajv.errorsText(validate.errors));
  const bad = [
    { ...base, loop: base.loops },                                   // a misspelt member
    { ...base, offsets: [{ height: 3 }] },                           // neither outside nor inside
    { ...base, offsets: [{ height: 3, inside: { profile: 'hip' } }] }, // an event's gap is required
    { ...base, offsets: [{ height: 3, outside: 1, inside: { gap: [1, 2], colour: 'red' } }] },
    { ...base, priority: 'largest' },
  ];
  for (const doc of bad) assert.equal(validate(doc), false, JSON.stringify(doc));
});
