#!/usr/bin/env python3
"""Sizes of a splitstream stream's levels next to the same meshes as Cesium
quantized-mesh 1.0 tiles, written by the PyPI package quantized-mesh-encoder.

    python3 -m venv /tmp/qm && /tmp/qm/bin/pip install quantized-mesh-encoder==0.5.0
    /tmp/qm/bin/python encoder/benches/quantized_mesh.py STREAM.sps [--splitstream BIN]

Every level k of the stream is decoded (`splitstream decode --level k`) and
that mesh written as one quantized-mesh tile, plain and gzip -9 (terrain
servers send tiles gzip-encoded), its triangles and vertices first put in
the spatially coherent order a tiler writes. A quantized-mesh client showing the same
levels coarse to fine downloads each level's tile whole, where a splitstream
client downloads each level's refinement once: the table sets the sums of
tiles beside the stream's prefixes.

quantized-mesh stores u, v and height as 15-bit values over the tile's
bounds, about one bit finer per axis than a 14-bit stream. x and y are taken
as longitude and latitude when they look like degrees; any other x/y
(generated terrain) is mapped into a one-degree square first, which changes
only the tile header's geodetic fields, not the quantized data.
"""

import argparse
import gzip
import io
import json
import os
import subprocess
import sys
import tempfile

import numpy as np
import quantized_mesh_encoder


def read_ply(path):
    """Positions (n, 3) f64 and triangles (m, 3) u32 from `splitstream
    decode`'s binary little-endian PLY (doubles; uchar count + u32 indices)."""
    with open(path, "rb") as f:
        data = f.read()
    end = data.index(b"end_header\n") + len(b"end_header\n")
    header = data[:end].decode("ascii").split("\n")
    vertices = int(next(l for l in header if l.startswith("element vertex")).split()[2])
    faces = int(next(l for l in header if l.startswith("element face")).split()[2])
    positions = np.frombuffer(data, dtype="<f8", count=3 * vertices, offset=end).reshape(vertices, 3)
    face_dtype = np.dtype([("n", "u1"), ("v", "<u4", (3,))])
    face = np.frombuffer(data, dtype=face_dtype, count=faces, offset=end + 24 * vertices)
    assert (face["n"] == 3).all()
    return positions, face["v"].copy()


def morton(x, y):
    """Interleaves the bits of two arrays of 16-bit integers."""
    def spread(v):
        v = v.astype(np.uint64) & 0xFFFF
        v = (v | (v << 8)) & 0x00FF00FF
        v = (v | (v << 4)) & 0x0F0F0F0F
        v = (v | (v << 2)) & 0x33333333
        return (v | (v << 1)) & 0x55555555
    return spread(x) | (spread(y) << np.uint64(1))


def coherent(positions, triangles):
    """The mesh in the order a terrain tiler writes: triangles along a
    Z-order curve of their centroids, vertices numbered by first use, so
    quantized-mesh's delta-coded vertices and high-water-mark indices see
    neighbours next to each other (a decoder's vertex order, the splits'
    order, would be unfair to it)."""
    lo, hi = positions.min(axis=0), positions.max(axis=0)
    span = np.maximum(hi - lo, 1e-300)
    centroid = positions[triangles].mean(axis=1)
    cell = ((centroid[:, :2] - lo[:2]) / span[:2] * 65535).astype(np.uint64)
    triangles = triangles[np.argsort(morton(cell[:, 0], cell[:, 1]), kind="stable")]
    first_use = np.full(len(positions), -1, dtype=np.int64)
    order = []
    for v in triangles.ravel():
        if first_use[v] < 0:
            first_use[v] = len(order)
            order.append(v)
    return positions[np.array(order)], first_use[triangles].astype(np.uint32)


def tile_bytes(positions, triangles):
    positions, triangles = coherent(positions, triangles)
    lo, hi = positions.min(axis=0), positions.max(axis=0)
    geographic = lo[0] >= -180 and hi[0] <= 180 and lo[1] >= -90 and hi[1] <= 90
    p = positions.copy()
    if not geographic:
        span = max(hi[0] - lo[0], hi[1] - lo[1]) or 1.0
        p[:, 0] = (p[:, 0] - lo[0]) / span
        p[:, 1] = (p[:, 1] - lo[1]) / span
    out = io.BytesIO()
    quantized_mesh_encoder.encode(out, p.astype(np.float64), triangles.astype(np.uint32).ravel())
    raw = out.getvalue()
    return len(raw), len(gzip.compress(raw, compresslevel=9, mtime=0))


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("stream")
    parser.add_argument("--splitstream", default="target/release/splitstream")
    args = parser.parse_args()
    info = json.loads(
        subprocess.run([args.splitstream, "info", args.stream, "--json"], check=True, capture_output=True).stdout
    )
    levels = info["levels"]
    print(f"{args.stream}: {info['vertices']} vertices, {info['bytes']} bytes, {len(levels)} levels")
    print("| level | vertices | splitstream prefix (bytes) | quantized-mesh tile / gzip -9 (bytes) | "
          "sum of tiles 0..k / gzip | stream prefix ÷ gzip sum |")
    print("|---:|---:|---:|---:|---:|---:|")
    sums = [0, 0]
    with tempfile.TemporaryDirectory() as tmp:
        for level in levels:
            k = level["level"]
            ply = os.path.join(tmp, f"level{k}.ply")
            subprocess.run(
                [args.splitstream, "decode", args.stream, "-o", ply, "--level", str(k)],
                check=True, capture_output=True,
            )
            positions, triangles = read_ply(ply)
            raw, packed = tile_bytes(positions, triangles)
            sums[0] += raw
            sums[1] += packed
            prefix = level["offset"] + level["length"]
            print(f"| {k} | {len(positions):,} | {prefix:,} | {raw:,} / {packed:,} | "
                  f"{sums[0]:,} / {sums[1]:,} | {prefix / sums[1]:.2f} |")
    n = info["vertices"]
    print(f"bits per vertex of the finest level: splitstream {8 * info['bytes'] / n:.2f}, "
          f"quantized-mesh tile {8 * raw / n:.2f} (gzip {8 * packed / n:.2f})")


if __name__ == "__main__":
    sys.exit(main())
