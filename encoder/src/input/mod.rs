//! The encoder's input layer: reading meshes and elevation grids from files,
//! checking that a mesh is something the encoder can stream, optionally
//! repairing it, and generating synthetic terrain for benchmarks.
//!
//! One file per job: a reader per format (`ply`, `obj`, `off`, `gltf`,
//! `stl`, `esri`, `npy`, `geotiff`), `grid` for raster triangulation, `check` and `repair`
//! for mesh validity, `terrain` for the synthetic DEM.

mod check;
mod csr;
mod error;
mod esri;
mod geotiff;
mod gltf;
mod grid;
mod npy;
mod npz_axes;
mod obj;
mod off;
mod ply;
mod ply_ascii;
mod polygon;
mod read_grid;
mod repair;
mod shapes;
mod stl;
mod terrain;

use std::path::Path;

use crate::Mesh;

pub use check::{MeshError, MeshStats, check_mesh};
pub use error::{GRID_EXTENSIONS, InputError, SUPPORTED_EXTENSIONS};
pub use grid::{Grid, grid_to_mesh};
pub(crate) use polygon::Polygons;
pub use read_grid::read_grid;
pub use repair::{RepairReport, repair_mesh};
pub use shapes::icosphere;
pub use terrain::fractal_terrain;

/// How to interpret an input file.
#[derive(Clone, Debug, PartialEq)]
pub struct ReadOptions {
    /// `.npz` only: the array holding the elevations; by default the first
    /// two-dimensional array in the archive.
    pub npz_array: Option<String>,
    /// Grid formats only: sample spacing `(dx, dy)` replacing whatever the
    /// file says (or the unit spacing used when it says nothing).
    pub grid_spacing: Option<(f64, f64)>,
    /// Every format: factor applied to z, e.g. to exaggerate relief or to
    /// bring elevations in metres to the units of geographic x/y.
    pub z_scale: f64,
}

impl Default for ReadOptions {
    /// Hand-written because `z_scale` must default to 1, not 0.
    fn default() -> Self {
        ReadOptions {
            npz_array: None,
            grid_spacing: None,
            z_scale: 1.0,
        }
    }
}

/// Reads a mesh or an elevation grid, choosing the format by extension
/// (case-insensitive): `.ply`, `.obj`, `.off`, `.gltf`/`.glb` (glTF 2.0, the
/// default scene, welded by position), `.stl` (binary or ascii, welded by
/// position), `.tif`/`.tiff` (GeoTIFF),
/// `.asc` (ESRI ASCII grid), `.npy`, `.npz`. Grids become meshes through
/// [`grid_to_mesh`]. The mesh is not checked: call [`check_mesh`].
pub fn read_mesh(path: &Path, options: &ReadOptions) -> Result<Mesh, InputError> {
    let file = path.display().to_string();
    let extension = path
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default();
    let mut mesh = match extension.as_str() {
        "ply" => ply::read(path, &file)?,
        "obj" => obj::read(path, &file)?,
        "off" => off::read(path, &file)?,
        "gltf" | "glb" => gltf::read(path, &file)?,
        "stl" => stl::read(path, &file)?,
        "tif" | "tiff" => grid_mesh(&file, apply_spacing(geotiff::read(path, &file)?, options))?,
        "asc" => grid_mesh(&file, apply_spacing(esri::read(path, &file)?, options))?,
        "npy" => grid_mesh(&file, apply_spacing(npy::read_npy(path, &file)?, options))?,
        "npz" => grid_mesh(
            &file,
            apply_spacing(
                npy::read_npz(path, &file, options.npz_array.as_deref())?,
                options,
            ),
        )?,
        _ => {
            return Err(InputError::UnknownExtension {
                file,
                extension,
                supported: SUPPORTED_EXTENSIONS,
            });
        }
    };
    if options.z_scale != 1.0 {
        for p in &mut mesh.positions {
            p[2] *= options.z_scale;
        }
    }
    Ok(mesh)
}

/// [`grid_to_mesh`], or an error that says why a grid gives no triangle
/// (a single row or column, or missing samples in every cell), where the
/// mesh check would only say that the mesh is empty.
fn grid_mesh(file: &str, grid: Grid) -> Result<Mesh, InputError> {
    let mesh = grid_to_mesh(&grid);
    if !mesh.triangles.is_empty() {
        return Ok(mesh);
    }
    let (rows, cols) = (grid.rows, grid.cols);
    let message = if rows < 2 || cols < 2 {
        format!("a grid of {rows} x {cols} samples has no cell to triangulate")
    } else {
        let missing = match (0..rows * cols).filter(|&i| !grid.is_valid(i)).count() {
            1 => "1 sample is missing".to_string(),
            n => format!("{n} samples are missing"),
        };
        format!(
            "no cell of the {rows} x {cols} grid has heights at its four corners \
             ({missing}: NaN, infinite or nodata)"
        )
    };
    Err(InputError::malformed(file, message))
}

/// `options.grid_spacing`, where given, places the samples on that regular
/// grid instead of where the file put them (listed coordinates included).
fn apply_spacing(mut grid: Grid, options: &ReadOptions) -> Grid {
    if let Some((dx, dy)) = options.grid_spacing {
        grid.spacing = [dx, dy];
        grid.coordinates = None;
    }
    grid
}

/// A text file's contents as `str`: borrowed where the bytes are UTF-8
/// (`from_utf8` checks them several times faster than the lossy
/// conversion walks them), converted lossily where they are not (a Latin-1
/// comment, say). The text formats (OBJ, OFF) are ASCII in what we read.
pub(crate) fn text_of(bytes: &[u8]) -> std::borrow::Cow<'_, str> {
    // A UTF-8 byte order mark (Windows editors write one) is not text: kept,
    // it glued itself to the first word, and an OBJ lost its first vertex.
    let bytes = bytes.strip_prefix(UTF8_BOM).unwrap_or(bytes);
    match std::str::from_utf8(bytes) {
        Ok(text) => std::borrow::Cow::Borrowed(text),
        Err(_) => String::from_utf8_lossy(bytes),
    }
}

/// Refuses a text file saved as UTF-16 (its byte order mark first): read
/// as bytes it held no statement, and the check said only that the mesh
/// was empty.
pub(crate) fn refuse_utf16(bytes: &[u8], file: &str) -> Result<(), InputError> {
    if bytes.starts_with(b"\xFF\xFE") || bytes.starts_with(b"\xFE\xFF") {
        return Err(InputError::unsupported(
            file,
            "a UTF-16 text file (save it as UTF-8 or ASCII)",
        ));
    }
    Ok(())
}

/// The UTF-8 byte order mark, which a text file may begin with.
pub(crate) const UTF8_BOM: &[u8] = b"\xEF\xBB\xBF";

/// `text.lines()` (`\n` ends a line, a `\r` before it is dropped) by a
/// plain byte scan: the general searcher `lines` uses took about a fifth
/// of the OBJ reader's instructions on its short lines.
pub(crate) fn ascii_lines(text: &str) -> impl Iterator<Item = &str> + '_ {
    let mut rest = text;
    std::iter::from_fn(move || {
        if rest.is_empty() {
            return None;
        }
        let (line, next) = match rest.bytes().position(|b| b == b'\n') {
            Some(end) => (&rest[..end], &rest[end + 1..]),
            None => (rest, ""),
        };
        rest = next;
        Some(line.strip_suffix('\r').unwrap_or(line))
    })
}

/// Appends one polygon as triangles (its fan, which keeps its winding;
/// `polygons.untangle` later cuts a concave one again), shared by the PLY
/// and OFF readers. `indices` are as read (possibly negative); returns a
/// message naming the bad index.
pub(crate) fn push_polygon<I>(
    triangles: &mut Vec<[u32; 3]>,
    indices: I,
    vertex_count: usize,
    polygons: &mut Polygons,
) -> Result<(), String>
where
    I: IntoIterator<Item = i64>,
{
    let scratch = &mut polygons.corners;
    scratch.clear();
    for i in indices {
        if i < 0 || i as u64 >= vertex_count as u64 {
            return Err(format!(
                "vertex index {i} out of range (the file has {vertex_count} vertices)"
            ));
        }
        scratch.push(i as u32);
    }
    if scratch.len() < 3 {
        return Err(format!(
            "polygon with {} vertices (at least 3 needed)",
            scratch.len()
        ));
    }
    merge_repeated_corners(scratch, |&v| v);
    polygons.fan_into(triangles);
    Ok(())
}

/// Merges a polygon's corners that repeat the one before them, the last
/// and the first included (`4 a b c c`: a triangle some exporters write as
/// a quad, whose fan had a degenerate triangle), unless fewer than three
/// corners would remain: a polygon that degenerate is left for the input
/// check to name.
pub(crate) fn merge_repeated_corners<T, K: PartialEq>(corners: &mut Vec<T>, key: impl Fn(&T) -> K) {
    let distinct = |c: &[T]| {
        let n = c.len();
        (0..n)
            .filter(|&i| key(&c[i]) != key(&c[(i + n - 1) % n]))
            .count()
    };
    if corners.len() < 3 || distinct(corners) == corners.len() || distinct(corners) < 3 {
        return;
    }
    let n = corners.len();
    let keep: Vec<bool> = (0..n)
        .map(|i| key(&corners[i]) != key(&corners[(i + n - 1) % n]))
        .collect();
    let mut i = 0;
    corners.retain(|_| {
        i += 1;
        keep[i - 1]
    });
}

/// Fails with [`InputError::TooLarge`] when `count` vertices cannot be
/// addressed by `u32` triangle indices.
pub(crate) fn check_vertex_count(file: &str, count: u64) -> Result<(), InputError> {
    if count > u32::MAX as u64 + 1 {
        Err(InputError::TooLarge {
            file: file.to_owned(),
            vertices: count,
        })
    } else {
        Ok(())
    }
}

#[cfg(test)]
pub(crate) mod test_util {
    use std::path::PathBuf;
    use std::sync::atomic::{AtomicUsize, Ordering};

    /// A file in the temp dir that is deleted on drop; the name is unique per
    /// process and call so tests can run in parallel.
    pub struct TempFile(pub PathBuf);

    impl TempFile {
        pub fn new(name: &str, contents: &[u8]) -> TempFile {
            static COUNTER: AtomicUsize = AtomicUsize::new(0);
            let n = COUNTER.fetch_add(1, Ordering::Relaxed);
            let path = std::env::temp_dir().join(format!(
                "splitstream-input-{}-{n}-{name}",
                std::process::id()
            ));
            std::fs::write(&path, contents).expect("write temp file");
            TempFile(path)
        }
    }

    impl Drop for TempFile {
        fn drop(&mut self) {
            let _ = std::fs::remove_file(&self.0);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::test_util::TempFile;
    use super::*;

    #[test]
    fn unknown_extension_lists_supported_ones() {
        let f = TempFile::new("mesh.fbx", b"Kaydara FBX Binary");
        let err = read_mesh(&f.0, &ReadOptions::default()).unwrap_err();
        assert!(matches!(err, InputError::UnknownExtension { .. }));
        let msg = err.to_string();
        assert!(msg.contains("'.fbx'") && msg.contains(".npz"), "{msg}");
        let err = read_mesh(Path::new("noext"), &ReadOptions::default()).unwrap_err();
        assert!(err.to_string().contains("no file extension"));
    }

    /// `read_grid` lists the grid formats only: a mesh file given where a
    /// grid is wanted is told so, not offered its own extension.
    #[test]
    fn a_mesh_where_a_grid_is_wanted_lists_the_grid_formats() {
        let f = TempFile::new("tri.off", b"OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n");
        let err = read_grid(&f.0, &ReadOptions::default()).unwrap_err();
        let msg = err.to_string();
        assert!(msg.contains("unsupported extension '.off'"), "{msg}");
        assert!(
            msg.ends_with("supported: .tif, .tiff, .asc, .npy, .npz"),
            "{msg}"
        );
    }

    /// A grid that gives no triangle says why, not only that the mesh is
    /// empty.
    #[test]
    fn grids_without_a_whole_cell_say_why() {
        let f = TempFile::new(
            "row.asc",
            b"ncols 5\nnrows 1\nxllcorner 0\nyllcorner 0\ncellsize 1\n1 2 3 4 5\n",
        );
        let err = read_mesh(&f.0, &ReadOptions::default())
            .unwrap_err()
            .to_string();
        assert!(
            err.ends_with("a grid of 1 x 5 samples has no cell to triangulate"),
            "{err}"
        );
        let f = TempFile::new(
            "holes.asc",
            b"ncols 2\nnrows 2\nxllcorner 0\nyllcorner 0\ncellsize 1\nNODATA_value -9\n1 -9\n2 3\n",
        );
        let err = read_mesh(&f.0, &ReadOptions::default())
            .unwrap_err()
            .to_string();
        assert!(
            err.ends_with("no cell of the 2 x 2 grid has heights at its four corners (1 sample is missing: NaN, infinite or nodata)"),
            "{err}"
        );
    }

    #[test]
    fn missing_file_is_io_error() {
        let err = read_mesh(Path::new("/nonexistent/x.ply"), &ReadOptions::default()).unwrap_err();
        assert!(matches!(err, InputError::Io { .. }), "{err}");
        assert!(err.to_string().starts_with("/nonexistent/x.ply: "));
    }

    #[test]
    fn empty_and_garbage_files_fail_cleanly() {
        for ext in SUPPORTED_EXTENSIONS {
            for (i, contents) in [&b""[..], b"\x00\x01garbage\xff\xfe\nmore garbage 1 2 3\n"]
                .iter()
                .enumerate()
            {
                let f = TempFile::new(&format!("garbage{i}.{ext}"), contents);
                let result = read_mesh(&f.0, &ReadOptions::default());
                // OBJ without vertices or faces is an empty mesh, not an error.
                if let Ok(mesh) = result {
                    assert!(check_mesh(&mesh).is_err(), "{ext} {i}");
                } else if let Err(e) = result {
                    let msg = e.to_string();
                    assert!(!msg.contains('\n'), "{msg}");
                    assert!(msg.contains("garbage"), "{msg}");
                }
            }
        }
    }

    #[test]
    fn z_scale_and_spacing_options() {
        let f = TempFile::new(
            "g.asc",
            b"ncols 2\nnrows 2\nxllcenter 0\nyllcenter 0\ncellsize 1\n1 2\n3 4\n",
        );
        let options = ReadOptions {
            z_scale: 2.0,
            grid_spacing: Some((10.0, 20.0)),
            ..ReadOptions::default()
        };
        let m = read_mesh(&f.0, &options).unwrap();
        assert_eq!(
            m.positions,
            vec![
                [0.0, 0.0, 6.0],
                [10.0, 0.0, 8.0],
                [0.0, 20.0, 2.0],
                [10.0, 20.0, 4.0]
            ]
        );
    }

    #[test]
    fn fan_triangulation() {
        let mut tris = Vec::new();
        let mut scratch = Polygons::default();
        push_polygon(&mut tris, [0, 1, 2, 3, 4], 5, &mut scratch).unwrap();
        assert_eq!(tris, vec![[0, 1, 2], [0, 2, 3], [0, 3, 4]]);
        // A corner repeated at once is merged (`4 a b c c`, a triangle as
        // a quad), unless too few corners would be left.
        push_polygon(&mut tris, [0, 1, 2, 2], 5, &mut scratch).unwrap();
        push_polygon(&mut tris, [3, 3, 1, 2, 3], 5, &mut scratch).unwrap();
        push_polygon(&mut tris, [4, 4, 1, 4], 5, &mut scratch).unwrap();
        assert_eq!(tris[3..], [[0, 1, 2], [1, 2, 3], [4, 4, 1], [4, 1, 4]]);
        tris.truncate(3);
        assert!(
            push_polygon(&mut tris, [0, 5, 1], 5, &mut scratch)
                .unwrap_err()
                .contains("index 5")
        );
        assert!(push_polygon(&mut tris, [0, -1, 1], 5, &mut scratch).is_err());
        assert!(
            push_polygon(&mut tris, [0, 1], 5, &mut scratch)
                .unwrap_err()
                .contains("2 vertices")
        );
    }
}
