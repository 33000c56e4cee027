// Writes the glTF and STL test files of encoder/data/real/ with writers the
// encoder's readers share no code with: glTF-Transform (npm
// @gltf-transform/core) and three.js's STLExporter (npm three). Called by
// fetch.sh:
//
//   node third_party_files.mjs NODE_MODULES_DIR REAL_DIR
//
// NODE_MODULES_DIR holds @gltf-transform/core, three and bunny; REAL_DIR
// holds armadillo.off and refined_elephant.off, and gets:
// * bunny.glb: the npm bunny as exporters write meshes with flat normals:
//   three vertices of its own per triangle, no index buffer, a plain node.
//   Read back it must weld into bunny.ply's mesh.
// * armadillo.gltf + armadillo.bin: CGAL's armadillo, indexed with u32, in
//   a JSON glTF with an external buffer, its mesh under two nodes: a parent
//   translated by (1000, -2000, 500) and a child rotated a quarter turn
//   about z and scaled by 2. Read back it must be the OFF mesh with
//   (x, y, z) -> (1000 - 2y, -2000 + 2x, 500 + 2z).
// * refined_elephant.stl: binary STL of refined_elephant.off (three.js,
//   f32, a copy of each corner per facet); bunny_ascii.stl: ascii STL of
//   the npm bunny. Read back they must weld into the OFF / PLY meshes.
import { readFileSync, renameSync, writeFileSync } from 'node:fs';
import { createRequire } from 'node:module';
import { join } from 'node:path';
import { pathToFileURL } from 'node:url';

const [modules, real] = process.argv.slice(2);
const require = createRequire(join(modules, 'x.js'));
const { Document, NodeIO } = require('@gltf-transform/core');
// three is an ES module; its exporter imports `three` from its own folder,
// which resolves to this same file.
const esm = (path) => import(pathToFileURL(join(modules, path)).href);
const THREE = await esm('three/build/three.module.js');
const { STLExporter } = await esm('three/examples/jsm/exporters/STLExporter.js');
const bunny = require('bunny');

/** Writes `bytes` to REAL_DIR/name through a temporary name. */
function write(name, bytes) {
  writeFileSync(join(real, `${name}.part`), bytes);
  renameSync(join(real, `${name}.part`), join(real, name));
}

function readOff(file) {
  const words = readFileSync(file, 'utf8')
    .split('\n')
    .map((l) => l.replace(/#.*/, ''))
    .join(' ')
    .split(/\s+/)
    .filter((w) => w.length);
  if (words[0] !== 'OFF') throw new Error(`${file}: not an OFF file`);
  const [nv, nf] = [Number(words[1]), Number(words[2])];
  let at = 4;
  const positions = new Float32Array(3 * nv);
  for (let i = 0; i < 3 * nv; i++) positions[i] = Number(words[at++]);
  const indices = [];
  for (let f = 0; f < nf; f++) {
    const n = Number(words[at++]);
    const poly = words.slice(at, at + n).map(Number);
    at += n;
    for (let k = 1; k + 1 < n; k++) indices.push(poly[0], poly[k], poly[k + 1]);
  }
  return { positions, indices: new Uint32Array(indices) };
}

function gltfMesh(doc, buffer, positions, indices) {
  const pos = doc.createAccessor().setType('VEC3').setArray(positions).setBuffer(buffer);
  const prim = doc.createPrimitive().setAttribute('POSITION', pos);
  if (indices) prim.setIndices(doc.createAccessor().setType('SCALAR').setArray(indices).setBuffer(buffer));
  return doc.createMesh().addPrimitive(prim);
}

function stl(positions, indices, binary) {
  const geometry = new THREE.BufferGeometry();
  geometry.setAttribute('position', new THREE.BufferAttribute(positions, 3));
  geometry.setIndex(new THREE.BufferAttribute(indices, 1));
  const out = new STLExporter().parse(new THREE.Mesh(geometry), { binary });
  return binary ? new Uint8Array(out.buffer, out.byteOffset, out.byteLength) : out;
}

const io = new NodeIO();
const bunnyPositions = Float32Array.from(bunny.positions.flat());
const bunnyIndices = Uint32Array.from(bunny.cells.flat());

// bunny.glb: unindexed, one vertex per corner.
{
  const corners = new Float32Array(9 * bunny.cells.length);
  bunny.cells.forEach((cell, t) => cell.forEach((v, k) => corners.set(bunny.positions[v], 9 * t + 3 * k)));
  const doc = new Document();
  const mesh = gltfMesh(doc, doc.createBuffer(), corners, null);
  doc.createScene().addChild(doc.createNode('bunny').setMesh(mesh));
  write('bunny.glb', await io.writeBinary(doc));
}

// armadillo.gltf + armadillo.bin: indexed, under a transformed hierarchy.
{
  const arm = readOff(join(real, 'armadillo.off'));
  const doc = new Document();
  const mesh = gltfMesh(doc, doc.createBuffer().setURI('armadillo.bin'), arm.positions, arm.indices);
  const child = doc
    .createNode('turned')
    .setRotation([0, 0, Math.SQRT1_2, Math.SQRT1_2])
    .setScale([2, 2, 2])
    .setMesh(mesh);
  doc.createScene().addChild(doc.createNode('moved').setTranslation([1000, -2000, 500]).addChild(child));
  const json = await io.writeJSON(doc);
  write('armadillo.bin', json.resources['armadillo.bin']);
  write('armadillo.gltf', JSON.stringify(json.json));
}

// STL, binary and ascii.
{
  const elephant = readOff(join(real, 'refined_elephant.off'));
  write('refined_elephant.stl', stl(elephant.positions, elephant.indices, true));
  write('bunny_ascii.stl', stl(bunnyPositions, bunnyIndices, false));
}
