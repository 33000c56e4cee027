#!/usr/bin/env python3
"""Writes the seed corpus of the read_input fuzz target: one small valid
file per format (a tetrahedron, or a 4 x 3 grid), each prefixed with the
byte that picks its extension (its index in SUPPORTED_EXTENSIONS).

    python3 encoder/fuzz/make_seeds.py encoder/fuzz/corpus/read_input
"""
import base64
import io
import json
import os
import struct
import sys
import zipfile

EXTENSIONS = ["ply", "obj", "off", "gltf", "glb", "stl", "tif", "tiff", "asc", "npy", "npz"]
P = [(0.0, 0.0, 0.0), (1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0)]
T = [(0, 2, 1), (0, 1, 3), (0, 3, 2), (1, 2, 3)]
H = [[1, 2, 3, 4], [2, 3, 5, 8], [1, 1, 2, 3]]  # 3 rows x 4 columns


def ply_ascii():
    lines = ["ply", "format ascii 1.0", "element vertex 4", "property float x", "property float y",
             "property float z", "element face 4", "property list uchar int vertex_indices", "end_header"]
    lines += [" ".join(map(str, p)) for p in P] + ["3 " + " ".join(map(str, t)) for t in T]
    return ("\n".join(lines) + "\n").encode()


def ply_binary():
    head = ("ply\nformat binary_little_endian 1.0\nelement vertex 4\nproperty double x\nproperty double y\n"
            "property double z\nelement face 4\nproperty list uchar uint vertex_indices\nend_header\n").encode()
    body = b"".join(struct.pack("<3d", *p) for p in P) + b"".join(struct.pack("<B3I", 3, *t) for t in T)
    return head + body


def obj():
    return ("".join(f"v {x} {y} {z}\n" for x, y, z in P) + "".join(f"f {a+1} {b+1} {c+1}\n" for a, b, c in T)).encode()


def off():
    return ("OFF\n4 4 0\n" + "".join(f"{x} {y} {z}\n" for x, y, z in P) + "".join(f"3 {a} {b} {c}\n" for a, b, c in T)).encode()


def gltf_parts():
    positions = b"".join(struct.pack("<3f", *p) for p in P)
    indices = b"".join(struct.pack("<3H", *t) for t in T)
    doc = {
        "asset": {"version": "2.0"},
        "buffers": [{"byteLength": len(positions) + len(indices)}],
        "bufferViews": [{"buffer": 0, "byteLength": len(positions)},
                        {"buffer": 0, "byteOffset": len(positions), "byteLength": len(indices)}],
        "accessors": [{"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3",
                       "min": [0, 0, 0], "max": [1, 1, 1]},
                      {"bufferView": 1, "componentType": 5123, "count": 12, "type": "SCALAR"}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]}],
        "nodes": [{"mesh": 0, "translation": [10, 0, 0]}],
        "scenes": [{"nodes": [0]}],
    }
    return doc, positions + indices


def gltf():
    doc, data = gltf_parts()
    doc["buffers"][0]["uri"] = "data:application/octet-stream;base64," + base64.b64encode(data).decode()
    return json.dumps(doc).encode()


def glb():
    doc, data = gltf_parts()
    text = json.dumps(doc).encode()
    text += b" " * (-len(text) % 4)
    data += b"\0" * (-len(data) % 4)
    body = struct.pack("<I4s", len(text), b"JSON") + text + struct.pack("<I4s", len(data), b"BIN\0") + data
    return struct.pack("<4sII", b"glTF", 2, 12 + len(body)) + body


def stl_binary():
    facets = b"".join(struct.pack("<12fH", 0, 0, 0, *P[a], *P[b], *P[c], 0) for a, b, c in T)
    return b"\0" * 80 + struct.pack("<I", len(T)) + facets


def stl_ascii():
    out = "solid t\n"
    for a, b, c in T:
        out += "facet normal 0 0 0\nouter loop\n" + "".join(f"vertex {x} {y} {z}\n" for x, y, z in (P[a], P[b], P[c]))
        out += "endloop\nendfacet\n"
    return (out + "endsolid t\n").encode()


def tiff():
    """A 4 x 3 int16 grayscale baseline TIFF, uncompressed, one strip."""
    rows, cols = len(H), len(H[0])
    pixels = b"".join(struct.pack("<h", v) for row in H for v in row)
    entries = [  # tag, type, count, value
        (256, 3, 1, cols), (257, 3, 1, rows), (258, 3, 1, 16), (259, 3, 1, 1), (262, 3, 1, 1),
        (273, 4, 1, 0), (277, 3, 1, 1), (278, 3, 1, rows), (279, 4, 1, len(pixels)), (339, 3, 1, 2),
    ]
    ifd_offset = 8
    data_offset = ifd_offset + 2 + 12 * len(entries) + 4
    out = struct.pack("<2sHI", b"II", 42, ifd_offset) + struct.pack("<H", len(entries))
    for tag, kind, count, value in entries:
        if tag == 273:
            value = data_offset
        out += struct.pack("<HHI", tag, kind, count) + (struct.pack("<HH", value, 0) if kind == 3 else struct.pack("<I", value))
    return out + struct.pack("<I", 0) + pixels


def asc():
    head = f"ncols {len(H[0])}\nnrows {len(H)}\nxllcorner 0\nyllcorner 0\ncellsize 30\nNODATA_value -9999\n"
    return (head + "".join(" ".join(map(str, row)) + "\n" for row in H)).encode()


def npy():
    header = "{'descr': '<i2', 'fortran_order': False, 'shape': (%d, %d), }" % (len(H), len(H[0]))
    header += " " * (-(10 + len(header) + 1) % 64) + "\n"
    return b"\x93NUMPY\x01\x00" + struct.pack("<H", len(header)) + header.encode() + b"".join(
        struct.pack("<h", v) for row in H for v in row)


def npz():
    out = io.BytesIO()
    with zipfile.ZipFile(out, "w") as z:
        z.writestr("elevation.npy", npy())
    return out.getvalue()


def f8_npy(shape, values):
    header = "{'descr': '<f8', 'fortran_order': False, 'shape': %s, }" % (shape,)
    header += " " * (-(10 + len(header) + 1) % 64) + "\n"
    return b"\x93NUMPY\x01\x00" + struct.pack("<H", len(header)) + header.encode() + b"".join(
        struct.pack("<d", v) for v in values)


def npz_coordinates():
    """The grid with 1-D longitude (even) and latitude (uneven) arrays."""
    out = io.BytesIO()
    with zipfile.ZipFile(out, "w") as z:
        z.writestr("topo.npy", npy())
        z.writestr("longitude.npy", f8_npy((4,), [234.0, 234.5, 235.0, 235.5]))
        z.writestr("latitude.npy", f8_npy((3,), [49.0, 48.6, 48.0]))
    return out.getvalue()


SEEDS = {
    "ply-ascii": ("ply", ply_ascii), "ply-binary": ("ply", ply_binary), "obj": ("obj", obj),
    "off": ("off", off), "gltf": ("gltf", gltf), "glb": ("glb", glb), "stl-binary": ("stl", stl_binary),
    "stl-ascii": ("stl", stl_ascii), "tif": ("tif", tiff), "asc": ("asc", asc), "npy": ("npy", npy),
    "npz": ("npz", npz), "npz-coordinates": ("npz", npz_coordinates),
}

if __name__ == "__main__":
    out = sys.argv[1]
    os.makedirs(out, exist_ok=True)
    for name, (ext, make) in SEEDS.items():
        with open(os.path.join(out, name), "wb") as f:
            f.write(bytes([EXTENSIONS.index(ext)]) + make())
    print(f"{len(SEEDS)} seeds in {out}")
