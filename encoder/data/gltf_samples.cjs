// Writes the glTF test files of encoder/data/real/ with glTF-Transform
// (npm @gltf-transform/core), so the encoder's glTF reader is tested on
// files from a writer it does not share code with. Called by fetch.sh:
//
//   node gltf_samples.cjs BUNNY_PACKAGE_DIR ARMADILLO_OFF OUT_DIR
//
// * bunny.glb: the npm bunny as exporters write meshes with flat normals:
//   three vertices of its own per triangle, no index buffer, a plain node.
//   Read back it must weld into bunny.ply's mesh.
// * armadillo.gltf + armadillo.bin: CGAL's armadillo, indexed with u32, in
//   a JSON glTF with an external buffer, its mesh under two nodes: a parent
//   translated by (1000, -2000, 500) and a child rotated a quarter turn
//   about z and scaled by 2. Read back it must be the OFF mesh with
//   (x, y, z) -> (1000 - 2y, -2000 + 2x, 500 + 2z).
"use strict";
const fs = require("fs");
const path = require("path");
const { Document, NodeIO } = require("@gltf-transform/core");

const [bunnyDir, armadilloOff, outDir] = process.argv.slice(2);

function readOff(file) {
  const words = fs
    .readFileSync(file, "utf8")
    .split("\n")
    .map((l) => l.replace(/#.*/, ""))
    .join(" ")
    .split(/\s+/)
    .filter((w) => w.length);
  if (words[0] !== "OFF") throw new Error(`${file}: not an OFF file`);
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

function primitive(doc, buffer, positions, indices) {
  const pos = doc.createAccessor().setType("VEC3").setArray(positions).setBuffer(buffer);
  const prim = doc.createPrimitive().setAttribute("POSITION", pos);
  if (indices) prim.setIndices(doc.createAccessor().setType("SCALAR").setArray(indices).setBuffer(buffer));
  return doc.createMesh().addPrimitive(prim);
}

async function main() {
  const io = new NodeIO();

  // bunny.glb: unindexed, one vertex per corner.
  const bunny = require(bunnyDir);
  const corners = new Float32Array(9 * bunny.cells.length);
  bunny.cells.forEach((cell, t) =>
    cell.forEach((v, k) => corners.set(bunny.positions[v], 9 * t + 3 * k)),
  );
  let doc = new Document();
  let buffer = doc.createBuffer();
  let mesh = primitive(doc, buffer, corners, null);
  doc.createScene().addChild(doc.createNode("bunny").setMesh(mesh));
  fs.writeFileSync(path.join(outDir, "bunny.glb.part"), await io.writeBinary(doc));

  // armadillo.gltf + armadillo.bin: indexed, under a transformed hierarchy.
  const arm = readOff(armadilloOff);
  doc = new Document();
  buffer = doc.createBuffer().setURI("armadillo.bin");
  mesh = primitive(doc, buffer, arm.positions, arm.indices);
  const child = doc
    .createNode("turned")
    .setRotation([0, 0, Math.SQRT1_2, Math.SQRT1_2])
    .setScale([2, 2, 2])
    .setMesh(mesh);
  const parent = doc.createNode("moved").setTranslation([1000, -2000, 500]).addChild(child);
  doc.createScene().addChild(parent);
  const json = await io.writeJSON(doc);
  fs.writeFileSync(path.join(outDir, "armadillo.bin"), json.resources["armadillo.bin"]);
  fs.writeFileSync(path.join(outDir, "armadillo.gltf.part"), JSON.stringify(json.json));
  fs.renameSync(path.join(outDir, "bunny.glb.part"), path.join(outDir, "bunny.glb"));
  fs.renameSync(path.join(outDir, "armadillo.gltf.part"), path.join(outDir, "armadillo.gltf"));
}

main().catch((e) => {
  console.error(e);
  process.exit(1);
});
