// Node test of the wasm-bindgen build (run by .ci/wasm):
//   node sdk-wasm/tests/node/decode_and_simplify.mjs PKG_DIR [--decoder-only]
// PKG_DIR holds `wasm-bindgen --target nodejs` output. Decodes every
// conformance vector of the newest set the way a browser would (96 bytes,
// the head, then each level's byte range; level by level and round by
// round) and checks the state hashes and error classes of manifest.json;
// then simplifies grid tiles. With --decoder-only (a build without the
// `grid` feature) it checks instead that GridSimplifier is absent.
import assert from 'node:assert/strict';
import { readFileSync } from 'node:fs';
import { createRequire } from 'node:module';
import { join, resolve } from 'node:path';

import { newestVectors } from '../vectors.mjs';

const pkgDir = resolve(process.argv[2] ?? process.env.SPLITSTREAM_WASM_PKG ?? '');
const require = createRequire(import.meta.url);
const sdk = require(join(pkgDir, 'splitstream_sdk_wasm.js'));
const { StreamDecoder, GridSimplifier } = sdk;
const decoderOnly = process.argv.includes('--decoder-only');
assert.equal(GridSimplifier === undefined, decoderOnly, 'GridSimplifier is there exactly without --decoder-only');

const { version: set, dir, manifest } = newestVectors();

// Decodes like a browser; `rounds` says which levels go round by round.
// Returns the hashes seen after the seed and each round (round levels only).
function decode(stream, rounds) {
  const head = stream.subarray(0, StreamDecoder.headLength(stream.subarray(0, 96)));
  const d = new StreamDecoder(head);
  const hashes = [];
  try {
    assert.ok(d.workspaceBytes > 0);
    for (let k = d.nextLevel; k !== undefined; k = d.nextLevel) {
      const [start, end] = d.levelRange(k);
      const bytes = stream.subarray(start, end); // an HTTP range request
      if (rounds(k)) {
        d.beginLevel(k, bytes);
        if (k === 0) hashes.push(d.stateHashHex());
        while (d.nextRound()) hashes.push(d.stateHashHex());
      } else {
        d.decodeLevel(k, bytes);
      }
    }
    const hash = d.stateHashHex();
    assert.equal(typeof d.stateHash(), 'bigint');
    assert.equal(d.stateHash(), BigInt('0x' + hash));
    const [nv, nt] = [d.vertexCount, d.triangleCount];
    const q = d.positionsQuantized();
    const p32 = d.positions();
    const p64 = d.positionsF64();
    const idx = d.indices();
    assert.ok(q instanceof Uint32Array && q.length === 3 * nv);
    assert.ok(p32 instanceof Float32Array && p32.length === 3 * nv);
    assert.ok(p64 instanceof Float64Array && p64.length === 3 * nv);
    assert.ok(idx instanceof Uint32Array && idx.length === 3 * nt);
    assert.ok(idx.every((i) => i < nv), 'triangle index beyond the vertices');
    for (let i = 0; i < p64.length; i++) assert.ok(Math.abs(p32[i] - p64[i]) <= 1e-5 * (1 + Math.abs(p64[i])));
    return { hash, hashes, nv, nt, levels: d.levelsDone };
  } finally {
    d.free();
  }
}

let valid = 0, invalid = 0;
for (const v of manifest.vectors) {
  const stream = new Uint8Array(readFileSync(join(dir, v.file)));
  if (v.valid) {
    const all = decode(stream, () => true);
    assert.deepEqual(all.hashes, v.round_hashes, `${v.name}: round hashes`);
    assert.equal(all.hash, v.result.state_hash, v.name);
    assert.equal(all.nv, v.result.vertices, v.name);
    assert.equal(all.nt, v.result.triangles, v.name);
    const byLevel = decode(stream, () => false);
    assert.equal(byLevel.hash, v.result.state_hash, `${v.name} level by level`);
    const mixed = decode(stream, (k) => k % 2 === 1);
    assert.equal(mixed.hash, v.result.state_hash, `${v.name} mixed`);
    valid++;
  } else {
    assert.throws(
      () => decode(stream, () => true),
      (e) => {
        assert.equal(e.name, 'SplitstreamError', `${v.name}: ${e}`);
        assert.equal(e.class, v.error_class, `${v.name}: ${e.message}`);
        assert.ok(e.message.length > 0 && !e.message.includes('\n'));
        return true;
      },
      v.name,
    );
    invalid++;
  }
}
assert.ok(valid >= 5, 'too few valid vectors');

// Misuse is an exception too, with the api-misuse class.
{
  const v = manifest.vectors.find((x) => x.valid && x.result.levels >= 2);
  const stream = new Uint8Array(readFileSync(join(dir, v.file)));
  const d = new StreamDecoder(stream);
  const [s, e] = d.levelRange(1);
  assert.throws(() => d.decodeLevel(1, stream.subarray(s, e)), (err) => err.class === 'api-misuse');
  assert.throws(() => d.levelRange(d.levelCount), (err) => err.class === 'invalid-argument');
  // Screen-space error: close up every level, far away the base level; a
  // field of view of 4 radians is no camera.
  const fov = Math.PI / 3;
  assert.equal(d.levelForScreenError(1080, fov, 0, 2), d.levelWithinError(0));
  assert.equal(d.levelForScreenError(1080, fov, 1e30, 2), 0);
  assert.throws(() => d.levelForScreenError(1080, 4, 10, 2), (err) => err.class === 'invalid-argument');
  assert.throws(() => d.levelWithinError(NaN), (err) => err.class === 'invalid-argument');
  // A memory budget: all levels with room for all, none with one byte.
  assert.equal(d.levelsThatFit, d.levelCount);
  const all = StreamDecoder.withinBudget(stream, d.workspaceBytes + 8);
  assert.equal(all.levelsThatFit, d.levelCount);
  all.free();
  assert.throws(() => StreamDecoder.withinBudget(stream, 1), (err) => err.class === 'capacity-exceeded');
  d.free();
}

// Grid tiles: a tilted plane collapses to two triangles; a hilly tile stays
// within T everywhere, from Float64Array and Float32Array heights alike.
if (!decoderOnly) {
  const n = 65, d = 32;
  const plane = new Float64Array(n * n).map((_, i) => 3 + 0.5 * (i % n) - 0.25 * Math.floor(i / n));
  const g = new GridSimplifier(n, n);
  let st = g.simplify(plane, n, n, new Float64Array([d, d]), new Float64Array([100, 200]), 700,
    new Float64Array(0), new Uint32Array(0));
  assert.equal(st.cells, 4096);
  assert.equal(st.rectangles, 1);
  assert.equal(st.trianglesAfter, 2);
  assert.deepEqual(Array.from(g.indices()).length, 6);
  assert.deepEqual(Array.from(g.positions().subarray(0, 3)), [100, 200, 3]);

  const hills = new Float64Array(n * n).map((_, i) => {
    const x = (i % n) * d, y = Math.floor(i / n) * d;
    return Math.round(40 * Math.sin(x / 170) * Math.cos(y / 230) + 15 * Math.sin(x / 61 + y / 97));
  });
  const res = new Float64Array([0, 64, 0, 0]); // a coarser tile to the east
  st = g.simplify(hills, n, n, new Float64Array([d, d]), new Float64Array([0, 0]), 2000, res, new Uint32Array([1, 1, 1, 1]));
  assert.ok(st.rectangles < st.cells && st.rectangles > 1);
  assert.ok(st.maxErrorRatio <= 1 + 1e-9, `ratio ${st.maxErrorRatio}`);
  assert.ok(st.maxVerticalError <= 64 / 25 + 1e-9);
  const idx = g.indices(), pos = g.positions(), pos32 = g.positionsF32();
  assert.equal(idx.length, 3 * st.trianglesAfter);
  assert.equal(pos.length, 3 * st.verticesAfter);
  assert.ok(pos32 instanceof Float32Array && pos32.length === pos.length);
  assert.ok(idx.every((i) => i < st.verticesAfter));
  const st32 = g.simplifyF32(new Float32Array(hills), n, n, new Float64Array([d, d]), new Float64Array([0, 0]), 2000, res, new Uint32Array(0));
  assert.equal(st32.rectangles, st.rectangles);
  assert.deepEqual(Array.from(g.indices()), Array.from(idx));

  assert.throws(() => g.simplify(plane.subarray(1), n, n, new Float64Array([d, d]), new Float64Array([0, 0]), 700,
    new Float64Array(0), new Uint32Array(0)), (e) => e.name === 'SplitstreamError' && e.class === 'grid-tile');
  assert.throws(() => g.simplify(plane, n, n, new Float64Array([d]), new Float64Array([0, 0]), 700,
    new Float64Array(0), new Uint32Array(0)), (e) => e.class === 'invalid-argument');
  g.free();
  console.log(`grid: ${st.cells} -> ${st.rectangles} facets, ${st.trianglesAfter} triangles, max error ${st.maxVerticalError.toFixed(3)} (${st.maxErrorRatio.toFixed(3)} T)`);
}

console.log(
  `sdk-wasm node test: ${valid} valid and ${invalid} invalid vectors of ${set} as the manifest says; ` +
    (decoderOnly ? 'decoder-only build (no GridSimplifier)' : 'grid tiles ok'),
);
