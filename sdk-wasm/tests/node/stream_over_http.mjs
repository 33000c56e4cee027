// Node test of the viewer's loader (sdk-wasm/examples/viewer/stream.mjs)
// over real HTTP (the viewer's serve.mjs), run by .ci/wasm:
//   node sdk-wasm/tests/node/stream_over_http.mjs PKG_DIR
// Every valid conformance vector of the newest set is fetched with range
// requests and refined to its last level: each round's state hash must be
// the manifest's, each level is requested once, and no byte of the stream
// is fetched twice but the first 96 (header, then head). A view that needs
// only the coarse levels fetches only those; a server that ignores ranges
// costs one download; a corrupt stream throws the decoder's error class.
import assert from 'node:assert/strict';
import { readFileSync } from 'node:fs';
import { createRequire } from 'node:module';
import { join, resolve } from 'node:path';

import { ProgressiveMesh } from '../../examples/viewer/stream.mjs';
import { serve } from '../../examples/viewer/serve.mjs';
import { newestVectors } from '../vectors.mjs';

const pkgDir = resolve(process.argv[2] ?? process.env.SPLITSTREAM_WASM_PKG ?? '');
const { StreamDecoder } = createRequire(import.meta.url)(join(pkgDir, 'splitstream_sdk_wasm.js'));

const { dir, manifest } = newestVectors();

const { server, url, log } = await serve({ '/v/': dir });
try {
  let checked = 0;
  for (const v of manifest.vectors.filter((x) => x.valid)) {
    log.length = 0;
    const size = readFileSync(join(dir, v.file)).length;
    const mesh = await ProgressiveMesh.open(`${url}/v/${v.file}`, StreamDecoder);
    try {
      const hashes = [];
      for await (const step of mesh.refine(Infinity)) {
        assert.ok(step.round >= 1 || (step.level === 0 && hashes.length === 0), `${v.name}: ${JSON.stringify(step)}`);
        hashes.push(mesh.decoder.stateHashHex());
      }
      assert.deepEqual(hashes, v.round_hashes, `${v.name}: round hashes`);
      assert.equal(mesh.decoder.stateHashHex(), v.result.state_hash, v.name);
      assert.equal(mesh.decoder.levelsDone, v.result.levels, v.name);
      // Ranges only, each level once: the stream's bytes up to the last
      // level's end, plus the 96 header bytes fetched twice.
      assert.ok(log.every((e) => e.status === 206 && e.range !== null), `${v.name}: ${JSON.stringify(log)}`);
      assert.equal(log.length, 2 + v.result.levels, v.name);
      const [, end] = mesh.decoder.levelRange(v.result.levels - 1);
      assert.equal(mesh.bytesFetched, end + 96, v.name);
      assert.ok(end <= size);
      // Refining again fetches and yields nothing.
      for await (const _ of mesh.refine(Infinity)) assert.fail('refined twice');
      assert.equal(log.length, 2 + v.result.levels);
    } finally {
      mesh.free();
    }
    checked++;
  }
  assert.ok(checked >= 5, 'too few valid vectors');

  // A far view needs the base level only: nothing past it is fetched.
  const multi = manifest.vectors.find((x) => x.valid && x.result.levels >= 4);
  {
    log.length = 0;
    const mesh = await ProgressiveMesh.open(`${url}/v/${multi.file}`, StreamDecoder);
    const far = mesh.levelFor({ viewportHeight: 1080, fovY: Math.PI / 4, distance: 1e12 });
    assert.equal(far, 0);
    const steps = [];
    for await (const s of mesh.refine(far)) steps.push(s);
    assert.deepEqual(steps[0], { level: 0, round: 0 });
    assert.ok(steps.every((s) => s.level === 0));
    assert.equal(log.length, 3);
    // Coming closer fetches the next levels, in order, from where it was.
    const near = mesh.levelFor({ viewportHeight: 1080, fovY: Math.PI / 4, distance: 0 });
    assert.equal(near, multi.result.levels - 1);
    for await (const _ of mesh.refine(near));
    assert.equal(mesh.decoder.stateHashHex(), multi.result.state_hash);
    assert.equal(log.length, 2 + multi.result.levels);
    mesh.free();
  }

  // A memory budget for the first two levels: refining stops there.
  {
    const stream = readFileSync(join(dir, multi.file));
    const fits = (bytes) => {
      try {
        const d = StreamDecoder.withinBudget(stream, bytes);
        const n = d.levelsThatFit;
        d.free();
        return n;
      } catch (e) {
        assert.equal(e.class, 'capacity-exceeded'); // not even level 0 fits
        return 0;
      }
    };
    // The smallest budget that holds two levels.
    let [lo, hi] = [0, 2 ** 31];
    while (hi - lo > 1) {
      const mid = Math.floor((lo + hi) / 2);
      if (fits(mid) >= 2) hi = mid;
      else lo = mid;
    }
    assert.equal(fits(hi), 2);
    const mesh = await ProgressiveMesh.open(`${url}/v/${multi.file}`, StreamDecoder, { maxBytes: hi });
    assert.equal(mesh.levelCount, 2);
    for await (const _ of mesh.refine(Infinity));
    assert.equal(mesh.decoder.levelsDone, 2);
    mesh.free();
  }

  // A server that ignores Range: one full download, then slices of it.
  {
    let requests = 0;
    const plainFetch = async (u) => {
      requests++;
      return fetch(u); // no Range header: status 200, the whole file
    };
    const mesh = await ProgressiveMesh.open(`${url}/v/${multi.file}`, StreamDecoder, { fetch: plainFetch });
    for await (const _ of mesh.refine(Infinity));
    assert.equal(mesh.decoder.stateHashHex(), multi.result.state_hash);
    assert.equal(requests, 1);
    assert.equal(mesh.bytesFetched, readFileSync(join(dir, multi.file)).length);
    mesh.free();
  }

  // A corrupt stream: the decoder's error, with its conformance class.
  {
    const bad = manifest.vectors.find((x) => !x.valid && x.error_class === 'checksum-mismatch');
    await assert.rejects(
      (async () => {
        const mesh = await ProgressiveMesh.open(`${url}/v/${bad.file}`, StreamDecoder);
        try {
          for await (const _ of mesh.refine(Infinity));
        } finally {
          mesh.free();
        }
      })(),
      (e) => e.name === 'SplitstreamError' && e.class === 'checksum-mismatch',
    );
    await assert.rejects(ProgressiveMesh.open(`${url}/v/missing.sps`, StreamDecoder), /HTTP 404/);
  }

  // The server: suffix ranges, bad ranges, paths outside the mount.
  {
    const file = `${url}/v/${multi.file}`;
    const size = readFileSync(join(dir, multi.file)).length;
    let r = await fetch(file, { headers: { Range: 'bytes=-10' } });
    assert.equal(r.status, 206);
    assert.equal(r.headers.get('content-range'), `bytes ${size - 10}-${size - 1}/${size}`);
    assert.equal((await r.arrayBuffer()).byteLength, 10);
    r = await fetch(file, { headers: { Range: `bytes=${size}-` } });
    assert.equal(r.status, 416);
    r = await fetch(`${url}/v/..%2F..%2F..%2FCargo.toml`);
    assert.ok(r.status === 403 || r.status === 404, `escaped the mount: ${r.status}`);
  }
  console.log(`stream_over_http: ${checked} vectors refined over HTTP range requests`);
} finally {
  server.close();
}
