// Sizes of a splitstream stream's levels next to the same meshes encoded
// one by one with Draco (npm draco3d, the wasm build of Google's encoder),
// the usual alternative to a progressive stream: a chain of discrete LODs.
//
//   npm install --prefix /tmp/draco draco3d@1.5.9
//   NODE_PATH=/tmp/draco/node_modules node encoder/benches/draco_levels.mjs \
//       STREAM.sps [--splitstream BIN] [--bits 14] [--metres]
//
// Every level k is decoded (`splitstream decode --level k`, binary PLY) and
// encoded with Draco's edgebreaker at speed 0 (compression level 10) and
// speed 5 (its default), positions quantized to --bits (Draco's one step for
// all axes over the largest extent). A client showing levels 0..k from
// Draco downloads each level's file whole; a splitstream client downloads
// the stream's prefix up to level k. `--metres`: x and y are longitude and
// latitude in degrees (a stream encoded with --geographic), converted to
// metres about the centre first, since Draco's one step for all axes would
// otherwise be sized by the heights and flatten x and y.
import { execFileSync } from 'node:child_process';
import { mkdtempSync, readFileSync, rmSync } from 'node:fs';
import { createRequire } from 'node:module';
import { tmpdir } from 'node:os';
import { join } from 'node:path';

const require = createRequire(join(process.env.NODE_PATH ?? '.', 'x.js'));
const draco3d = require('draco3d');

const args = process.argv.slice(2);
const option = (name, fallback) => {
  const at = args.indexOf(name);
  return at < 0 ? fallback : args.splice(at, 2)[1];
};
const bin = option('--splitstream', 'target/release/splitstream');
const bits = Number(option('--bits', '14'));
const metresAt = args.indexOf('--metres');
const metres = metresAt >= 0 && args.splice(metresAt, 1).length > 0;
const stream = args[0];
if (!stream) {
  console.error('usage: draco_levels.mjs STREAM.sps [--splitstream BIN] [--bits 14] [--metres]');
  process.exit(2);
}

/** Positions (f32, as Draco takes them) and u32 triangles of a
 *  `splitstream decode` PLY: doubles, then uchar 3 + three u32 per face. */
function readPly(path) {
  const data = readFileSync(path);
  const end = data.indexOf('end_header\n') + 'end_header\n'.length;
  const header = data.subarray(0, end).toString('ascii');
  const vertices = Number(/element vertex (\d+)/.exec(header)[1]);
  const faces = Number(/element face (\d+)/.exec(header)[1]);
  const f64 = new Float64Array(3 * vertices);
  for (let i = 0; i < 3 * vertices; i++) f64[i] = data.readDoubleLE(end + 8 * i);
  if (metres) {
    // About the centre, on a sphere: metres per degree of longitude and
    // latitude there.
    const mid = (k) => {
      let [lo, hi] = [Infinity, -Infinity];
      for (let i = k; i < f64.length; i += 3) [lo, hi] = [Math.min(lo, f64[i]), Math.max(hi, f64[i])];
      return (lo + hi) / 2;
    };
    const [x0, y0] = [mid(0), mid(1)];
    const sx = 111320 * Math.cos((y0 * Math.PI) / 180);
    for (let i = 0; i < f64.length; i += 3) {
      f64[i] = (f64[i] - x0) * sx;
      f64[i + 1] = (f64[i + 1] - y0) * 110540;
    }
  }
  const positions = Float32Array.from(f64);
  const triangles = new Uint32Array(3 * faces);
  let at = end + 24 * vertices;
  for (let f = 0; f < faces; f++, at += 13) {
    for (let k = 0; k < 3; k++) triangles[3 * f + k] = data.readUInt32LE(at + 1 + 4 * k);
  }
  return { positions, triangles, vertices, faces };
}

function dracoBytes(module, mesh, speed) {
  const encoder = new module.Encoder();
  const builder = new module.MeshBuilder();
  const draco = new module.Mesh();
  builder.AddFacesToMesh(draco, mesh.faces, mesh.triangles);
  builder.AddFloatAttributeToMesh(draco, module.POSITION, mesh.vertices, 3, mesh.positions);
  encoder.SetSpeedOptions(speed, speed);
  encoder.SetAttributeQuantization(module.POSITION, bits);
  encoder.SetEncodingMethod(module.MESH_EDGEBREAKER_ENCODING);
  const out = new module.DracoInt8Array();
  const length = encoder.EncodeMeshToDracoBuffer(draco, out);
  if (length <= 0) throw new Error('Draco failed to encode');
  for (const o of [out, draco, builder, encoder]) module.destroy(o);
  return length;
}

const module = await draco3d.createEncoderModule({});
const info = JSON.parse(execFileSync(bin, ['info', stream, '--json']).toString());
const tmp = mkdtempSync(join(tmpdir(), 'draco-levels-'));
try {
  console.log(`${stream}: ${info.vertices} vertices, ${info.bytes} bytes, ${info.levels.length} levels, Draco ${bits}-bit positions`);
  console.log('| level | vertices | splitstream prefix (bytes) | Draco speed 0 / 5 (bytes) | sum of Draco files 0..k, speed 0 | stream prefix ÷ that sum |');
  console.log('|---:|---:|---:|---:|---:|---:|');
  let sum = 0;
  let last;
  for (const level of info.levels) {
    const ply = join(tmp, `level${level.level}.ply`);
    execFileSync(bin, ['decode', stream, '-o', ply, '--level', String(level.level)]);
    const mesh = readPly(ply);
    const [best, fast] = [dracoBytes(module, mesh, 0), dracoBytes(module, mesh, 5)];
    sum += best;
    last = best;
    const prefix = level.offset + level.length;
    console.log(`| ${level.level} | ${mesh.vertices.toLocaleString('en')} | ${prefix.toLocaleString('en')} | ` +
      `${best.toLocaleString('en')} / ${fast.toLocaleString('en')} | ${sum.toLocaleString('en')} | ${(prefix / sum).toFixed(2)} |`);
  }
  const n = info.vertices;
  console.log(`bits per vertex of the finest level: splitstream ${(8 * info.bytes / n).toFixed(2)}, ` +
    `Draco speed 0 ${(8 * last / n).toFixed(2)}; all levels from Draco ${(8 * sum / n).toFixed(2)}`);
} finally {
  rmSync(tmp, { recursive: true, force: true });
}
