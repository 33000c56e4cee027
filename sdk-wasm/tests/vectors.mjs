// The newest conformance vector set, for the sdk-wasm tests:
// conformance/vectors/<major.minor>/ with its manifest.json.
import assert from 'node:assert/strict';
import { existsSync, readFileSync, readdirSync } from 'node:fs';
import { dirname, join, resolve } from 'node:path';
import { fileURLToPath } from 'node:url';

/** The repository's root folder. */
export const root = resolve(dirname(fileURLToPath(import.meta.url)), '../..');

/** `{ version, dir, manifest }` of the highest major.minor set. */
export function newestVectors() {
  const vectorsRoot = join(root, 'conformance/vectors');
  const number = (v) => v.split('.').map(Number);
  const sets = readdirSync(vectorsRoot)
    .filter((d) => existsSync(join(vectorsRoot, d, 'manifest.json')))
    .sort((a, b) => number(a)[0] - number(b)[0] || number(a)[1] - number(b)[1]);
  assert.ok(sets.length > 0, 'no conformance vector set');
  const version = sets[sets.length - 1];
  const dir = join(vectorsRoot, version);
  const manifest = JSON.parse(readFileSync(join(dir, 'manifest.json'), 'utf8'));
  return { version, dir, manifest };
}
