//! GeoTIFFs written by GDAL (`gdal_translate`, fetched into
//! encoder/data/real/gdal/ by encoder/data/fetch.sh): the Jacksboro DEM
//! stripped and tiled, uncompressed and under DEFLATE, LZW, ZSTD and
//! PackBits with their predictors, as int16, float32 and float64, as a
//! cloud-optimized GeoTIFF with overviews, and with three bands; and
//! GDAL's ESRI grid of it. Each must
//! read as the ESRI grid GDAL converted it from: the same samples at the same
//! positions, the ten nodata samples missing. Without the folder this test
//! says so and passes.

use std::path::Path;

use splitstream_encoder::Mesh;
use splitstream_encoder::input::{ReadOptions, check_mesh, read_mesh};

const FILES: [&str; 8] = [
    "plain.tif",
    "deflate_tiled.tif",
    "lzw_float32.tif",
    "zstd_float64.tif",
    "cog.tif",
    "packbits_epsg4326.tif",
    "three_bands.tif",
    // GDAL's own ESRI grid writer: corners, cellsize to 12 decimals.
    "aaigrid.asc",
];

fn read(dir: &Path, file: &str) -> Mesh {
    read_mesh(&dir.join(file), &ReadOptions::default()).unwrap_or_else(|e| panic!("{e}"))
}

#[test]
fn gdal_geotiffs_read_as_their_source_grid() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("data/real/gdal");
    if !dir.join(".complete").exists() {
        eprintln!(
            "skipped data/real/gdal/: run encoder/data/fetch.sh with gdal_translate installed"
        );
        return;
    }
    let source = read(&dir, "jacksboro.asc");
    check_mesh(&source).unwrap();
    // 344 × 403 samples, ten of them nodata (jacksboro_asc.py).
    assert_eq!(source.positions.len(), 344 * 403 - 10);
    for file in FILES {
        let mesh = read(&dir, file);
        assert_eq!(mesh.triangles, source.triangles, "{file}");
        assert_eq!(mesh.positions.len(), source.positions.len(), "{file}");
        for (i, (p, q)) in mesh.positions.iter().zip(&source.positions).enumerate() {
            // GDAL turns the grid's cell centres into a corner origin and
            // back: x and y within rounding, heights exact.
            let close = (0..2).all(|k| (p[k] - q[k]).abs() < 1e-9) && p[2] == q[2];
            assert!(close, "{file}: vertex {i} at {p:?}, {q:?} in the grid");
        }
    }
}

/// The ESRI grid itself against the .npz it was written from: the same
/// heights at the same places but for the ten samples set to nodata.
#[test]
fn the_gdal_source_grid_is_the_jacksboro_dem() {
    let real = Path::new(env!("CARGO_MANIFEST_DIR")).join("data/real");
    if !real.join("gdal/.complete").exists() {
        eprintln!(
            "skipped data/real/gdal/: run encoder/data/fetch.sh with gdal_translate installed"
        );
        return;
    }
    let npz = read(&real, "jacksboro_fault_dem.npz");
    let asc = read(&real.join("gdal"), "jacksboro.asc");
    let key = |p: &[f64; 3]| [(p[0] * 1e6).round() as i64, (p[1] * 1e6).round() as i64];
    let heights: std::collections::HashMap<_, f64> =
        npz.positions.iter().map(|p| (key(p), p[2])).collect();
    for p in &asc.positions {
        assert_eq!(heights.get(&key(p)), Some(&p[2]), "{p:?}");
    }
    assert_eq!(npz.positions.len(), asc.positions.len() + 10);
}
