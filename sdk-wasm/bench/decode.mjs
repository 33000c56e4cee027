// Node benchmark of the wasm decoder (sdk-wasm's StreamDecoder):
//   node sdk-wasm/bench/decode.mjs PKG_DIR FILE.sps [RUNS]
// PKG_DIR holds `wasm-bindgen --target nodejs` output (.ci/wasm writes it to
// target/wasm-pkg). Decodes the whole stream RUNS times (default 7), level by
// level as a browser does once each level's bytes have arrived, and prints
// the median and best wall times and vertex splits per second (the splits
// are the vertices beyond the seed mesh, SPEC §6.3). Node runs the same wasm
// a browser would; the time covers decoding only, not fetching.
import { readFileSync } from 'node:fs';
import { createRequire } from 'node:module';
import { join, resolve } from 'node:path';
import { performance } from 'node:perf_hooks';

const [pkgArg, file, runsArg] = process.argv.slice(2);
if (!pkgArg || !file) {
  console.error('usage: node sdk-wasm/bench/decode.mjs PKG_DIR FILE.sps [RUNS]');
  process.exit(2);
}
const require = createRequire(import.meta.url);
const { StreamDecoder } = require(join(resolve(pkgArg), 'splitstream_sdk_wasm.js'));
const stream = new Uint8Array(readFileSync(file));
const runs = Math.max(1, Number(runsArg ?? 7));

const head = stream.subarray(0, StreamDecoder.headLength(stream.subarray(0, 96)));

function levelBytes(d, k) {
  const [start, end] = d.levelRange(k);
  return stream.subarray(Number(start), Number(end));
}

// The seed's vertex count, from a decoder that has read level 0's seed
// alone (`beginLevel` decodes it before any round), outside the timings:
// level headers have more than one layout (SPEC §5.1.1), so the SDK reads
// it rather than this script.
function seedVertices() {
  const d = new StreamDecoder(head);
  try {
    d.beginLevel(0, levelBytes(d, 0));
    return d.vertexCount;
  } finally {
    d.free();
  }
}

function decodeOnce() {
  const d = new StreamDecoder(head);
  try {
    const started = performance.now();
    for (let k = d.nextLevel; k !== undefined; k = d.nextLevel) d.decodeLevel(k, levelBytes(d, k));
    const ms = performance.now() - started;
    return { ms, vertices: d.vertexCount, hash: d.stateHashHex() };
  } finally {
    d.free();
  }
}

const results = [];
for (let i = 0; i < runs; i++) results.push(decodeOnce());
const times = results.map((r) => r.ms).sort((a, b) => a - b);
const median = times[Math.floor(times.length / 2)];
const { vertices, hash } = results[0];
const splits = vertices - seedVertices();
console.log(
  `${file}: wasm (node ${process.version}) median ${median.toFixed(1)} ms of ${runs} runs ` +
    `(best ${times[0].toFixed(1)}), ${(splits / median / 1e3).toFixed(2)} M splits/s, ` +
    `${splits} splits, hash ${hash}`,
);
