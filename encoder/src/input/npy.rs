//! NumPy `.npy` / `.npz` elevation arrays, via `npyz`.
//!
//! Arrays are two-dimensional, any integer or float dtype, C or Fortran
//! order. Like image-ordered DEMs (and GeoTIFF, ESRI grids), row 0 is taken
//! as the northern edge; spacing is 1 and the south-west sample sits at the
//! origin unless the archive says otherwise.
//!
//! `.npz` archives may carry scalar `dx`, `dy`, `xmin`, `ymin` (and `xmax`,
//! `ymax`) entries, as matplotlib's `jacksboro_fault_dem.npz` does. There
//! `(xmin, ymin)` is the position of element `[0, 0]`, and `ymax < ymin`
//! says that rows run southward (matplotlib's own examples place row `r` at
//! `linspace(ymin, ymax, nrows)[r]`). Without `ymax`, `ymin` is taken
//! literally as the southern edge.
//!
//! Without those scalars, 1-D (or np.meshgrid's 2-D) coordinate arrays
//! named `x`/`lon`/`longitude` and `y`/`lat`/`latitude` (`npz_axes`) place
//! the columns and rows, as matplotlib's `topobathy.npz` does; unevenly
//! spaced ones are kept value by value ([`Grid::coordinates`]). Without
//! any, the heights array is the first 2-D array not named as coordinates.

use std::fs::File;
use std::io::{BufReader, Read};
use std::path::Path;

use npyz::npz::NpzArchive;
use npyz::{DType, NpyFile, Order, TypeChar};

use super::grid::Grid;
use super::npz_axes::{self, Axis, X_NAMES, Y_NAMES};
use super::{InputError, check_vertex_count};

/// numpy's own bound on a header's length (`_MAX_HEADER_SIZE` since numpy
/// 1.24, which refuses longer ones for the same reason as below).
const MAX_HEADER_BYTES: u32 = 10_000;

/// How deep a header may nest brackets: its dict holds the shape tuple,
/// and a structured dtype's list of tuples at most.
const MAX_HEADER_DEPTH: usize = 3;

/// Refuses a header that npyz's literal parser would take exponential time
/// on (py_literal backtracks: each level of nesting doubled the time, so a
/// 40-byte file took hours; found by fuzzing) or that numpy would refuse.
/// A header too short to say is left to npyz, which reports it.
fn check_header<R: Read>(mut r: R) -> Result<(), String> {
    let mut preamble = [0u8; 8];
    if r.read_exact(&mut preamble).is_err() || &preamble[..6] != b"\x93NUMPY" {
        return Ok(());
    }
    let len = match preamble[6] {
        1 => {
            let mut b = [0u8; 2];
            if r.read_exact(&mut b).is_err() {
                return Ok(());
            }
            u16::from_le_bytes(b) as u32
        }
        2 | 3 => {
            let mut b = [0u8; 4];
            if r.read_exact(&mut b).is_err() {
                return Ok(());
            }
            u32::from_le_bytes(b)
        }
        _ => return Ok(()),
    };
    if len > MAX_HEADER_BYTES {
        return Err(format!(
            "header of {len} bytes (numpy reads at most {MAX_HEADER_BYTES})"
        ));
    }
    let mut header = Vec::with_capacity(len as usize);
    r.take(len as u64)
        .read_to_end(&mut header)
        .map_err(|e| e.to_string())?;
    let (mut depth, mut deepest) = (0usize, 0usize);
    for b in header {
        match b {
            b'(' | b'[' | b'{' => {
                depth += 1;
                deepest = deepest.max(depth);
            }
            b')' | b']' | b'}' => depth = depth.saturating_sub(1),
            _ => {}
        }
    }
    if deepest > MAX_HEADER_DEPTH {
        return Err(format!(
            "header nests brackets {deepest} deep (at most {MAX_HEADER_DEPTH})"
        ));
    }
    Ok(())
}

pub(super) fn read_npy(path: &Path, file: &str) -> Result<Grid, InputError> {
    let invalid = |m: String| InputError::malformed(file, format!("invalid .npy: {m}"));
    let f = File::open(path).map_err(|e| InputError::io(file, e))?;
    check_header(BufReader::new(&f)).map_err(invalid)?;
    let f = File::open(path).map_err(|e| InputError::io(file, e))?;
    let npy = NpyFile::new(BufReader::new(f))
        .map_err(|e| InputError::malformed(file, format!("invalid .npy: {e}")))?;
    let (rows, cols, values) = read_2d(npy, file, "array")?;
    north_first_grid(file, rows, cols, values, [0.0, 0.0], [1.0, 1.0])
}

fn north_first_grid(
    file: &str,
    rows: usize,
    cols: usize,
    values: Vec<f64>,
    south_west: [f64; 2],
    spacing: [f64; 2],
) -> Result<Grid, InputError> {
    Grid::from_north_first(rows, cols, values, south_west, spacing, None)
        .ok_or_else(|| InputError::malformed(file, "array length does not match its shape"))
}

/// Shape and values (row-major, as f64) of a 2-D array.
fn read_2d<R: Read>(
    npy: NpyFile<R>,
    file: &str,
    name: &str,
) -> Result<(usize, usize, Vec<f64>), InputError> {
    let shape = npy.shape().to_vec();
    let [rows, cols] = shape[..] else {
        return Err(InputError::malformed(
            file,
            format!("{name} must be two-dimensional, its shape is {shape:?}"),
        ));
    };
    check_vertex_count(file, rows.saturating_mul(cols))?;
    let fortran = npy.order() == Order::Fortran;
    let mut values = read_values(npy, file, name)?;
    let (rows, cols) = (rows as usize, cols as usize);
    if values.len() != rows * cols {
        return Err(InputError::malformed(
            file,
            format!(
                "{name} has {} values, expected {rows} x {cols}",
                values.len()
            ),
        ));
    }
    if fortran {
        let mut c_order = vec![0.0; values.len()];
        for c in 0..cols {
            for r in 0..rows {
                c_order[r * cols + c] = values[c * rows + r];
            }
        }
        values = c_order;
    }
    Ok((rows, cols, values))
}

/// Reads any numeric dtype as f64.
fn read_values<R: Read>(npy: NpyFile<R>, file: &str, name: &str) -> Result<Vec<f64>, InputError> {
    let dtype = npy.dtype();
    let DType::Plain(ts) = &dtype else {
        return Err(InputError::unsupported(
            file,
            format!("{name} has a structured dtype"),
        ));
    };
    let shape = npy.shape().to_vec();
    let bytes = shape
        .iter()
        .product::<u64>()
        .saturating_mul(ts.size_field());
    let err = |e: std::io::Error| {
        let why = match e.kind() {
            std::io::ErrorKind::UnexpectedEof => {
                format!("the file ends before its shape {shape:?} of {bytes} bytes")
            }
            _ => e.to_string(),
        };
        InputError::malformed(file, format!("cannot read {name}: {why}"))
    };
    fn widen<T: Copy + Into<f64>>(v: Vec<T>) -> Vec<f64> {
        v.into_iter().map(Into::into).collect()
    }
    Ok(match (ts.type_char(), ts.size_field()) {
        (TypeChar::Float, 4) => widen(npy.into_vec::<f32>().map_err(err)?),
        (TypeChar::Float, 8) => npy.into_vec::<f64>().map_err(err)?,
        (TypeChar::Int, 1) => widen(npy.into_vec::<i8>().map_err(err)?),
        (TypeChar::Int, 2) => widen(npy.into_vec::<i16>().map_err(err)?),
        (TypeChar::Int, 4) => widen(npy.into_vec::<i32>().map_err(err)?),
        (TypeChar::Int, 8) => npy
            .into_vec::<i64>()
            .map_err(err)?
            .into_iter()
            .map(|v| v as f64)
            .collect(),
        (TypeChar::Uint, 1) => widen(npy.into_vec::<u8>().map_err(err)?),
        (TypeChar::Uint, 2) => widen(npy.into_vec::<u16>().map_err(err)?),
        (TypeChar::Uint, 4) => widen(npy.into_vec::<u32>().map_err(err)?),
        (TypeChar::Uint, 8) => npy
            .into_vec::<u64>()
            .map_err(err)?
            .into_iter()
            .map(|v| v as f64)
            .collect(),
        _ => {
            return Err(InputError::unsupported(
                file,
                format!("{name} has dtype '{ts}'"),
            ));
        }
    })
}

/// Names (or parts of names) of arrays that hold heights, which wins
/// where an archive has several two-dimensional arrays.
const HEIGHT_NAMES: &[&str] = &["elev", "height", "dem", "topo", "bathy", "alt", "depth"];

/// Integer or floating-point values (not booleans, strings or records).
fn is_numeric(dtype: &DType) -> bool {
    matches!(dtype, DType::Plain(ts) if matches!(ts.type_char(), TypeChar::Float | TypeChar::Int | TypeChar::Uint))
}

pub(super) fn read_npz(path: &Path, file: &str, wanted: Option<&str>) -> Result<Grid, InputError> {
    let bad = |e: std::io::Error| InputError::malformed(file, format!("invalid .npz: {e}"));
    let mut archive = NpzArchive::open(path).map_err(|e| match e.kind() {
        std::io::ErrorKind::NotFound | std::io::ErrorKind::PermissionDenied => {
            InputError::io(file, e)
        }
        _ => bad(e),
    })?;
    // Archive order (array_names() iterates a hash map).
    let zip = archive.zip_archive();
    let mut names = Vec::new();
    for i in 0..zip.len() {
        let entry = zip
            .by_index(i)
            .map_err(|e| InputError::malformed(file, format!("invalid .npz: {e}")))?;
        if let Some(name) = npyz::npz::array_name_from_file_name(entry.name()) {
            let name = name.to_owned();
            check_header(entry).map_err(|m| {
                InputError::malformed(file, format!("invalid .npz: array '{name}': {m}"))
            })?;
            names.push(name);
        }
    }

    let name = match wanted {
        Some(w) => {
            if !names.iter().any(|n| n == w) {
                return Err(InputError::NpzArrayMissing {
                    file: file.to_owned(),
                    name: w.to_owned(),
                    available: names,
                });
            }
            w.to_owned()
        }
        None => {
            let mut found = None;
            // A 2-D `x` or `lat` beside the heights (np.meshgrid's) holds
            // coordinates, not heights.
            let coordinate = |n: &str| {
                X_NAMES
                    .iter()
                    .chain(&Y_NAMES)
                    .any(|c| n.eq_ignore_ascii_case(c))
            };
            // Numeric two-dimensional arrays only (a boolean mask beside
            // the heights was taken and refused); where there are several,
            // one named as heights are, or else the user says which: the
            // first of them, taken silently, was once a slope raster.
            let mut candidates = Vec::new();
            for n in names.iter().filter(|n| !coordinate(n)) {
                let npy = archive.by_name(n).map_err(bad)?;
                if npy.is_some_and(|a| a.shape().len() == 2 && is_numeric(&a.dtype())) {
                    candidates.push(n.clone());
                }
            }
            let height_like = |n: &str| {
                let n = n.to_ascii_lowercase();
                n == "z" || HEIGHT_NAMES.iter().any(|h| n.contains(h))
            };
            match candidates.as_slice() {
                [one] => found = Some(one.clone()),
                [] => {}
                several => match several.iter().find(|n| height_like(n)) {
                    Some(n) => found = Some(n.clone()),
                    None => {
                        return Err(InputError::malformed(
                            file,
                            format!(
                                "several two-dimensional arrays ({}): say which holds the heights with --npz-array",
                                several.join(", ")
                            ),
                        ));
                    }
                },
            }
            found.ok_or_else(|| {
                InputError::malformed(
                    file,
                    format!(
                        "no two-dimensional array of heights in the archive (arrays: {}; coordinate arrays are named as in x, lon, latitude, ...)",
                        names.join(", ")
                    ),
                )
            })?
        }
    };
    let npy = archive
        .by_name(&name)
        .map_err(bad)?
        .ok_or_else(|| InputError::malformed(file, format!("array '{name}' vanished")))?;
    let (rows, cols, values) = read_2d(npy, file, &format!("array '{name}'"))?;

    let mut scalar = |key: &str| -> Result<Option<f64>, InputError> {
        if !names.iter().any(|n| n == key) || key == name {
            return Ok(None);
        }
        let Some(npy) = archive.by_name(key).map_err(bad)? else {
            return Ok(None);
        };
        if npy.shape().iter().product::<u64>() != 1 {
            return Ok(None);
        }
        Ok(read_values(npy, file, key)?.first().copied())
    };
    let dx = scalar("dx")?;
    let dy = scalar("dy")?;
    let xmin = scalar("xmin")?;
    let ymin = scalar("ymin")?;
    let xmax = scalar("xmax")?;
    let ymax = scalar("ymax")?;
    if [dx, dy, xmin, ymin, xmax, ymax].iter().all(Option::is_none) {
        let x = coordinate_axis(&mut archive, &names, &name, file, rows, cols, true)?;
        let y = coordinate_axis(&mut archive, &names, &name, file, rows, cols, false)?;
        if x.is_some() || y.is_some() {
            return Ok(listed_grid(rows, cols, values, x, y));
        }
    }

    let dx = dx.unwrap_or(1.0);
    let dy = dy.or(dx.into()).unwrap_or(1.0);
    if !(dx.is_finite() && dy.is_finite() && dx != 0.0 && dy != 0.0) {
        return Err(InputError::malformed(
            file,
            format!("invalid spacing dx={dx}, dy={dy}"),
        ));
    }
    let (dx, dy) = (dx.abs(), dy.abs());
    let x0 = xmin.unwrap_or(0.0);
    // Columns run toward xmax, so a reversed x extent mirrors them.
    let dx = if xmax.zip(xmin).is_some_and(|(hi, lo)| hi < lo) {
        -dx
    } else {
        dx
    };
    let y0 = ymin.unwrap_or(0.0);
    let grid = match ymax {
        // Rows run north from ymin: row 0 is the southern edge.
        Some(ymax) if ymax > y0 => Grid {
            rows,
            cols,
            elevations: values,
            origin: [x0, y0],
            spacing: [dx, dy],
            nodata: None,
            coordinates: None,
        },
        // Rows run south from ymin (jacksboro), or no ymax: ymin is the south edge.
        Some(_) => north_first_grid(
            file,
            rows,
            cols,
            values,
            [x0, y0 - rows.saturating_sub(1) as f64 * dy],
            [dx, dy],
        )?,
        None => north_first_grid(file, rows, cols, values, [x0, y0], [dx, dy])?,
    };
    Ok(grid)
}

/// The axis that a coordinate array named as in [`X_NAMES`] (`along_x`) or
/// [`Y_NAMES`] gives the grid, if the archive has one: 1-D with a value per
/// column (row), or 2-D of the grid's shape and the same in every row
/// (column), as `np.meshgrid` writes them.
fn coordinate_axis<R: Read + std::io::Seek>(
    archive: &mut NpzArchive<R>,
    names: &[String],
    raster: &str,
    file: &str,
    rows: usize,
    cols: usize,
    along_x: bool,
) -> Result<Option<Axis>, InputError> {
    let wanted: &[&str] = if along_x { &X_NAMES } else { &Y_NAMES };
    let Some(name) = npz_axes::find(names, wanted, raster) else {
        return Ok(None);
    };
    if rows == 0 || cols == 0 {
        // No sample to place: the grid is refused for having no cell.
        return Ok(None);
    }
    let (count, what) = if along_x {
        (cols, "columns")
    } else {
        (rows, "rows")
    };
    let bad = |e: std::io::Error| InputError::malformed(file, format!("invalid .npz: {e}"));
    let Some(npy) = archive.by_name(name).map_err(bad)? else {
        return Ok(None);
    };
    let label = format!("coordinate array '{name}'");
    let values = match npy.shape() {
        [n] if *n == count as u64 => read_values(npy, file, &label)?,
        &[r, c] if (r, c) == (rows as u64, cols as u64) => {
            let all = read_values(npy, file, &label)?;
            let line: Vec<f64> = if along_x {
                all[..cols].to_vec()
            } else {
                all.iter().step_by(cols).copied().collect()
            };
            let varies = (0..rows * cols).any(|i| {
                let (r, c) = (i / cols, i % cols);
                all[i].to_bits() != if along_x { line[c] } else { line[r] }.to_bits()
            });
            if varies {
                return Err(InputError::unsupported(
                    file,
                    format!(
                        "{label} is not the same in every {}: a curvilinear grid",
                        if along_x { "row" } else { "column" }
                    ),
                ));
            }
            line
        }
        shape => {
            return Err(InputError::malformed(
                file,
                format!(
                    "{label} has shape {shape:?}: a value per {} ({count}) or the grid's \
                     shape ({rows}, {cols}) was expected",
                    &what[..what.len() - 1]
                ),
            ));
        }
    };
    npz_axes::axis(file, name, values, count, what).map(Some)
}

/// The grid of `values` (rows in file order) at the coordinates `x` and `y`
/// list; an axis without a list keeps the unlisted default (unit spacing,
/// row 0 the northern edge, the south-west sample at 0). Rows are stored
/// south to north as [`Grid`] prefers.
fn listed_grid(
    rows: usize,
    cols: usize,
    values: Vec<f64>,
    x: Option<Axis>,
    y: Option<Axis>,
) -> Grid {
    let x = x.unwrap_or(Axis::Regular {
        first: 0.0,
        step: 1.0,
    });
    let y = y.unwrap_or(Axis::Regular {
        first: rows.saturating_sub(1) as f64,
        step: -1.0,
    });
    let (x0, dx) = x.first_and_step();
    let (y0, dy) = y.first_and_step();
    let listed = matches!(x, Axis::Listed(_)) || matches!(y, Axis::Listed(_));
    let mut grid = Grid {
        rows,
        cols,
        elevations: values,
        origin: [x0, y0],
        spacing: [dx, dy],
        nodata: None,
        coordinates: listed.then(|| [x.values(cols), y.values(rows)]),
    };
    if dy < 0.0 {
        grid.reverse_rows_in_place();
        grid.origin[1] = y0 + rows.saturating_sub(1) as f64 * dy;
        grid.spacing[1] = -dy;
    }
    grid
}

#[cfg(test)]
mod tests {
    use super::super::test_util::TempFile;
    use super::super::{ReadOptions, check_mesh, read_mesh};
    use super::*;

    /// A minimal .npy file: version 1.0 header, padded to 64 bytes.
    fn npy_bytes(descr: &str, fortran: bool, shape: &str, data: &[u8]) -> Vec<u8> {
        let mut header = format!(
            "{{'descr': '{descr}', 'fortran_order': {}, 'shape': {shape}, }}",
            if fortran { "True" } else { "False" }
        );
        while (10 + header.len() + 1) % 64 != 0 {
            header.push(' ');
        }
        header.push('\n');
        let mut out = b"\x93NUMPY\x01\x00".to_vec();
        out.extend((header.len() as u16).to_le_bytes());
        out.extend(header.as_bytes());
        out.extend(data);
        out
    }

    fn le<T: Copy, const N: usize>(values: &[T], f: impl Fn(T) -> [u8; N]) -> Vec<u8> {
        values.iter().flat_map(|&v| f(v)).collect()
    }

    #[test]
    fn reads_npy_dtypes_and_orders() {
        // 2 rows x 3 cols, row 0 = north = [1, 2, 3].
        let expect_south_first = vec![4.0, 5.0, 6.0, 1.0, 2.0, 3.0];
        let cases = [
            npy_bytes(
                "<f4",
                false,
                "(2, 3)",
                &le(&[1f32, 2., 3., 4., 5., 6.], f32::to_le_bytes),
            ),
            npy_bytes(
                ">f8",
                false,
                "(2, 3)",
                &le(&[1f64, 2., 3., 4., 5., 6.], f64::to_be_bytes),
            ),
            npy_bytes(
                "<i2",
                false,
                "(2, 3)",
                &le(&[1i16, 2, 3, 4, 5, 6], i16::to_le_bytes),
            ),
            npy_bytes(
                "<u2",
                true,
                "(2, 3)",
                &le(&[1u16, 4, 2, 5, 3, 6], u16::to_le_bytes),
            ),
            npy_bytes(
                "<i8",
                false,
                "(2, 3)",
                &le(&[1i64, 2, 3, 4, 5, 6], i64::to_le_bytes),
            ),
            npy_bytes("|u1", false, "(2, 3)", &[1, 2, 3, 4, 5, 6]),
        ];
        for (i, bytes) in cases.iter().enumerate() {
            let f = TempFile::new("a.npy", bytes);
            let g = read_npy(&f.0, "a.npy").unwrap();
            assert_eq!((g.rows, g.cols), (2, 3), "case {i}");
            assert_eq!(g.elevations, expect_south_first, "case {i}");
            let m = read_mesh(&f.0, &ReadOptions::default()).unwrap();
            assert_eq!(m.positions[0], [0.0, 0.0, 4.0]);
            assert_eq!(m.positions[5], [2.0, 1.0, 3.0]);
            check_mesh(&m).unwrap();
        }
    }

    #[test]
    fn npy_errors() {
        let cases = [
            (npy_bytes("<f4", false, "(6,)", &[0; 24]), "two-dimensional"),
            (
                npy_bytes("<f4", false, "(2, 3)", &[0; 10]),
                "cannot read array",
            ),
            (npy_bytes("<c8", false, "(1, 1)", &[0; 8]), "unsupported"),
            (b"\x93NUMPY\x01".to_vec(), "invalid .npy"),
        ];
        for (bytes, needle) in cases {
            let f = TempFile::new("bad.npy", &bytes);
            let msg = read_npy(&f.0, "bad.npy").unwrap_err().to_string();
            assert!(
                msg.starts_with("bad.npy: ") && msg.contains(needle),
                "{msg}"
            );
        }
    }

    /// Found by fuzzing (`encoder/fuzz`, `read_input`): npyz parses the
    /// header with py_literal, whose parser backtracks, so each level of
    /// nesting doubled the time: 20 open brackets took 5.6 s, 30 would take
    /// hours. Such headers are refused before npyz sees them.
    #[test]
    fn deeply_nested_header_is_refused_at_once() {
        let deep = |depth: usize, tail: &str| {
            let header = format!("{{'descr': {}{tail}\n", "[".repeat(depth));
            let mut bytes = b"\x93NUMPY\x01\x00".to_vec();
            bytes.extend((header.len() as u16).to_le_bytes());
            bytes.extend(header.as_bytes());
            bytes
        };
        for bytes in [deep(30, ""), deep(4, "]]]]")] {
            let f = TempFile::new("deep.npy", &bytes);
            let t = std::time::Instant::now();
            let msg = read_npy(&f.0, "deep.npy").unwrap_err().to_string();
            assert!(t.elapsed().as_secs() < 1);
            assert!(
                msg.starts_with("deep.npy: invalid .npy: header nests brackets"),
                "{msg}"
            );
            // The same inside an archive.
            let f = TempFile::new("deep.npz", &npz(&[("elevation.npy", bytes)]));
            let msg = read_npz(&f.0, "deep.npz", None).unwrap_err().to_string();
            assert!(msg.contains("header nests brackets"), "{msg}");
        }
        // A header longer than numpy itself reads.
        let mut bytes = b"\x93NUMPY\x02\x00".to_vec();
        bytes.extend(20_000u32.to_le_bytes());
        bytes.extend(vec![b' '; 20_000]);
        let f = TempFile::new("long.npy", &bytes);
        let msg = read_npy(&f.0, "long.npy").unwrap_err().to_string();
        assert!(msg.contains("header of 20000 bytes"), "{msg}");
    }

    fn npz(entries: &[(&str, Vec<u8>)]) -> Vec<u8> {
        // Stored (uncompressed) zip written by hand: local headers, central
        // directory, end record. Enough for npyz's zip reader.
        let mut out = Vec::new();
        let mut central = Vec::new();
        for (name, data) in entries {
            let name = format!("{name}.npy");
            let crc = crc32fast::hash(data);
            let offset = out.len() as u32;
            let mut local = Vec::new();
            local.extend(0x04034b50u32.to_le_bytes());
            local.extend([20, 0, 0, 0, 0, 0, 0, 0, 0, 0]);
            local.extend(crc.to_le_bytes());
            local.extend((data.len() as u32).to_le_bytes());
            local.extend((data.len() as u32).to_le_bytes());
            local.extend((name.len() as u16).to_le_bytes());
            local.extend([0, 0]);
            local.extend(name.as_bytes());
            out.extend(&local);
            out.extend(data);
            central.extend(0x02014b50u32.to_le_bytes());
            central.extend([20, 0, 20, 0, 0, 0, 0, 0, 0, 0, 0, 0]);
            central.extend(crc.to_le_bytes());
            central.extend((data.len() as u32).to_le_bytes());
            central.extend((data.len() as u32).to_le_bytes());
            central.extend((name.len() as u16).to_le_bytes());
            central.extend([0; 12]);
            central.extend(offset.to_le_bytes());
            central.extend(name.as_bytes());
        }
        let cd_offset = out.len() as u32;
        out.extend(&central);
        out.extend(0x06054b50u32.to_le_bytes());
        out.extend([0, 0, 0, 0]);
        out.extend((entries.len() as u16).to_le_bytes());
        out.extend((entries.len() as u16).to_le_bytes());
        out.extend((central.len() as u32).to_le_bytes());
        out.extend(cd_offset.to_le_bytes());
        out.extend([0, 0]);
        out
    }

    fn scalar(v: f64) -> Vec<u8> {
        npy_bytes("<f8", false, "()", &v.to_le_bytes())
    }

    /// Found by an audit (2026-12-08): a boolean mask before the heights
    /// was taken and refused, and a slope raster before them was encoded
    /// as if it held heights.
    /// A payload shorter than its shape says (an audit, 2026-12-08) is
    /// named as such, not as "failed to fill whole buffer".
    #[test]
    fn a_short_payload_names_the_shape() {
        let bytes = npy_bytes("<f8", false, "(300, 400)", &[0; 100]);
        let f = TempFile::new("short.npy", &bytes);
        let msg = read_npy(&f.0, "short.npy").unwrap_err().to_string();
        assert!(
            msg.contains("the file ends before its shape [300, 400] of 960000 bytes"),
            "{msg}"
        );
    }

    #[test]
    fn npz_takes_the_heights_among_several_arrays_or_asks() {
        let grid = |v: f64| npy_bytes("<f8", false, "(2, 2)", &le(&[v; 4], f64::to_le_bytes));
        let mask = npy_bytes("|b1", false, "(2, 2)", &[1, 0, 1, 1]);
        for (entries, file) in [
            (vec![("mask", mask), ("elevation", grid(7.0))], "mask.npz"),
            (
                vec![("slope", grid(1.0)), ("elevation", grid(7.0))],
                "slope.npz",
            ),
        ] {
            let f = TempFile::new(file, &npz(&entries));
            let g = read_npz(&f.0, file, None).unwrap();
            assert_eq!(g.elevations, vec![7.0; 4], "{file}");
        }
        let f = TempFile::new("two.npz", &npz(&[("a", grid(1.0)), ("b", grid(2.0))]));
        let msg = read_npz(&f.0, "two.npz", None).unwrap_err().to_string();
        assert!(
            msg.contains("several two-dimensional arrays (a, b): say which holds the heights with --npz-array"),
            "{msg}"
        );
        assert_eq!(
            read_npz(&f.0, "two.npz", Some("b")).unwrap().elevations,
            vec![2.0; 4]
        );
    }

    #[test]
    fn npz_uses_metadata_like_jacksboro() {
        let elevation = npy_bytes(
            "<i2",
            false,
            "(2, 3)",
            &le(&[1i16, 2, 3, 4, 5, 6], i16::to_le_bytes),
        );
        let bytes = npz(&[
            ("dx", scalar(0.5)),
            ("elevation", elevation.clone()),
            ("dy", scalar(0.25)),
            ("xmin", scalar(-84.0)),
            ("ymin", scalar(36.5)),
            ("ymax", scalar(36.0)),
            (
                "other",
                npy_bytes("<f8", false, "(1, 1)", &1f64.to_le_bytes()),
            ),
        ]);
        let f = TempFile::new("dem.npz", &bytes);
        let g = read_npz(&f.0, "dem.npz", None).unwrap();
        assert_eq!(g.spacing, [0.5, 0.25]);
        assert_eq!(g.origin, [-84.0, 36.25]);
        assert_eq!(g.elevations, vec![4.0, 5.0, 6.0, 1.0, 2.0, 3.0]);
        let m = read_mesh(&f.0, &ReadOptions::default()).unwrap();
        assert!(m.positions.contains(&[-84.0, 36.5, 1.0]));
        check_mesh(&m).unwrap();

        // Named array, missing array, no 2-D array.
        let g = read_npz(&f.0, "dem.npz", Some("other")).unwrap();
        assert_eq!((g.rows, g.cols), (1, 1));
        let msg = read_npz(&f.0, "dem.npz", Some("nope"))
            .unwrap_err()
            .to_string();
        assert!(
            msg.contains("no array named 'nope'") && msg.contains("dx, elevation"),
            "{msg}"
        );
        let f2 = TempFile::new("flat.npz", &npz(&[("dx", scalar(1.0))]));
        let msg = read_npz(&f2.0, "flat.npz", None).unwrap_err().to_string();
        assert!(msg.contains("no two-dimensional array"), "{msg}");

        // Without ymax, ymin is the south edge; rows still run north to south.
        let f3 = TempFile::new(
            "plain.npz",
            &npz(&[("elevation", elevation), ("ymin", scalar(10.0))]),
        );
        let g = read_npz(&f3.0, "plain.npz", None).unwrap();
        assert_eq!(g.origin, [0.0, 10.0]);
        assert_eq!(g.spacing, [1.0, 1.0]);

        let mut truncated = bytes.clone();
        truncated.truncate(bytes.len() / 2);
        let f4 = TempFile::new("trunc.npz", &truncated);
        assert!(read_npz(&f4.0, "trunc.npz", None).is_err());
    }

    fn f8(shape: &str, values: &[f64]) -> Vec<u8> {
        npy_bytes("<f8", false, shape, &le(values, f64::to_le_bytes))
    }

    /// Heights of 2 rows × 3 columns, 1 to 6 in file order.
    fn heights() -> Vec<u8> {
        f8("(2, 3)", &[1.0, 2.0, 3.0, 4.0, 5.0, 6.0])
    }

    /// `longitude` and `latitude` arrays (topobathy.npz's layout): evenly
    /// spaced ones set origin and spacing; rows whose latitude falls run
    /// south as in image order, and rows whose latitude rises run north.
    #[test]
    fn npz_coordinate_arrays_place_the_samples() {
        for (lat, south_first) in [([36.5, 36.0], false), ([36.0, 36.5], true)] {
            let bytes = npz(&[
                ("topo", heights()),
                ("longitude", f8("(3,)", &[234.0, 234.25, 234.5])),
                ("latitude", f8("(2,)", &lat)),
            ]);
            let f = TempFile::new("topo.npz", &bytes);
            let g = read_npz(&f.0, "topo.npz", None).unwrap();
            assert_eq!((g.origin, g.spacing), ([234.0, 36.0], [0.25, 0.5]));
            assert_eq!(g.coordinates, None);
            let south_row = if south_first {
                [1.0, 2.0, 3.0]
            } else {
                [4.0, 5.0, 6.0]
            };
            assert_eq!(g.elevations[..3], south_row);
            let m = read_mesh(&f.0, &ReadOptions::default()).unwrap();
            check_mesh(&m).unwrap();
            let z_at_36 = if south_first { 1.0 } else { 4.0 };
            assert!(
                m.positions.contains(&[234.0, 36.0, z_at_36]),
                "{:?}",
                m.positions
            );
        }
    }

    /// Unevenly spaced latitudes (Mercator rows) are kept sample by sample;
    /// 2-D `x` and `y` as np.meshgrid writes them are read like 1-D ones.
    #[test]
    fn npz_uneven_and_meshgrid_coordinates() {
        let bytes = npz(&[
            ("x", f8("(2, 3)", &[0.0, 10.0, 20.0, 0.0, 10.0, 20.0])),
            ("y", f8("(2, 3)", &[5.0, 5.0, 5.0, 1.0, 1.0, 1.0])),
            ("z", heights()),
        ]);
        let f = TempFile::new("grid.npz", &bytes);
        let g = read_npz(&f.0, "grid.npz", None).unwrap();
        assert_eq!((g.origin, g.spacing), ([0.0, 1.0], [10.0, 4.0]));
        let uneven = npz(&[
            ("elevation", heights()),
            ("lat", f8("(2,)", &[48.0, 48.5])),
            ("lon", f8("(3,)", &[0.0, 1.0, 3.0])),
        ]);
        let f = TempFile::new("uneven.npz", &uneven);
        let g = read_npz(&f.0, "uneven.npz", None).unwrap();
        assert_eq!(g.coordinates, Some([vec![0.0, 1.0, 3.0], vec![48.0, 48.5]]));
        let m = read_mesh(&f.0, &ReadOptions::default()).unwrap();
        check_mesh(&m).unwrap();
        assert!(m.positions.contains(&[3.0, 48.5, 6.0]), "{:?}", m.positions);
        // --grid-spacing places the samples on its own regular grid.
        let spaced = ReadOptions {
            grid_spacing: Some((2.0, 2.0)),
            ..ReadOptions::default()
        };
        let m = read_mesh(&f.0, &spaced).unwrap();
        assert!(m.positions.contains(&[4.0, 50.0, 6.0]), "{:?}", m.positions);
    }

    #[test]
    fn npz_bad_coordinate_arrays_are_named() {
        let err = |extra: (&str, Vec<u8>)| {
            let f = TempFile::new("bad.npz", &npz(&[("elevation", heights()), extra]));
            read_npz(&f.0, "bad.npz", None).unwrap_err().to_string()
        };
        let msg = err(("latitude", f8("(3,)", &[1.0, 2.0, 3.0])));
        assert!(msg.contains("'latitude' has shape [3]"), "{msg}");
        let msg = err(("x", f8("(3,)", &[1.0, 3.0, 2.0])));
        assert!(msg.contains("'x' is not monotonic"), "{msg}");
        let msg = err(("x", f8("(2, 3)", &[0.0, 1.0, 2.0, 0.0, 1.0, 2.5])));
        assert!(msg.contains("not the same in every row"), "{msg}");
    }

    /// Found in reviewing the coordinate arrays: a raster without rows or
    /// columns beside coordinate arrays as empty as it (a 1-D `y` of no
    /// value, a 2-D `y` of no column) is refused for having no cell, not a
    /// panic (an index into no values, a `step_by(0)`).
    #[test]
    fn npz_empty_raster_beside_coordinates_fails_cleanly() {
        for (shape, y) in [("(0, 3)", f8("(0,)", &[])), ("(2, 0)", f8("(2, 0)", &[]))] {
            let bytes = npz(&[("z", f8(shape, &[])), ("y", y)]);
            let f = TempFile::new("empty.npz", &bytes);
            let msg = read_mesh(&f.0, &ReadOptions::default())
                .unwrap_err()
                .to_string();
            assert!(msg.contains("no cell"), "{shape}: {msg}");
        }
        assert_eq!(
            npz_axes::axis("f", "y", vec![], 0, "rows").unwrap(),
            Axis::Regular {
                first: 0.0,
                step: 1.0
            }
        );
    }
}
