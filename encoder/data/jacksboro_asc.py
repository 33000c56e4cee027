"""Writes matplotlib's jacksboro_fault_dem.npz as an ESRI ASCII grid, with
ten samples of row 100 (columns 50-59) set to nodata, for fetch.sh's GDAL
files. Standard library only: an .npz is a zip of .npy files.

Usage: python3 jacksboro_asc.py IN.npz OUT.asc
"""

import ast
import struct
import sys
import zipfile


def array(archive, name):
    """(header dict, data bytes) of a version 1.0 .npy member."""
    raw = archive.read(name + ".npy")
    if raw[:6] != b"\x93NUMPY" or raw[6] != 1:
        raise SystemExit(f"{name}.npy: not a version 1.0 .npy file")
    (header_len,) = struct.unpack("<H", raw[8:10])
    header = ast.literal_eval(raw[10 : 10 + header_len].decode("latin1"))
    return header, raw[10 + header_len :]


def scalar(archive, name):
    header, data = array(archive, name)
    if header["descr"] != "<f8":
        raise SystemExit(f"{name}: expected <f8, found {header['descr']}")
    return struct.unpack("<d", data[:8])[0]


def main(source, target):
    archive = zipfile.ZipFile(source)
    header, data = array(archive, "elevation")
    if header["descr"] != "<i2" or header["fortran_order"]:
        raise SystemExit(f"elevation: expected C-ordered <i2, found {header}")
    rows, cols = header["shape"]
    values = struct.unpack(f"<{rows * cols}h", data[: 2 * rows * cols])
    step = scalar(archive, "dx")
    west = scalar(archive, "xmin")
    # ymin is the northern row here (ymax < ymin: rows run south).
    south = scalar(archive, "ymin") - (rows - 1) * step
    with open(target, "w") as out:
        out.write(f"ncols {cols}\nnrows {rows}\n")
        out.write(f"xllcenter {west!r}\nyllcenter {south!r}\n")
        out.write(f"cellsize {step!r}\nNODATA_value -9999\n")
        for r in range(rows):
            row = list(values[r * cols : (r + 1) * cols])
            if r == 100:
                row[50:60] = [-9999] * 10
            out.write(" ".join(map(str, row)) + "\n")


if __name__ == "__main__":
    main(*sys.argv[1:3])
