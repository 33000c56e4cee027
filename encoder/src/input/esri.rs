//! ESRI ASCII grid (`.asc`) reader, by hand.
//!
//! Header: `ncols`, `nrows`, `xllcorner`|`xllcenter`, `yllcorner`|`yllcenter`,
//! `cellsize` or `dx` + `dy`, optional `NODATA_value` (or `nodata`); keys are
//! case-insensitive and in any order. Then `nrows * ncols` values, rows north
//! to south, laid out over lines in any way. Samples sit at cell centres, so
//! a `*corner` origin is shifted by half a cell.

use std::path::Path;

use super::grid::Grid;
use super::{InputError, check_vertex_count};

pub(super) fn read(path: &Path, file: &str) -> Result<Grid, InputError> {
    let bytes = std::fs::read(path).map_err(|e| InputError::io(file, e))?;
    super::refuse_utf16(&bytes, file)?;
    let text = super::text_of(&bytes);
    parse(&text, file)
}

#[derive(Default)]
struct Header {
    ncols: Option<usize>,
    nrows: Option<usize>,
    /// (value, is_corner)
    x: Option<(f64, bool)>,
    y: Option<(f64, bool)>,
    cellsize: Option<f64>,
    dx: Option<f64>,
    dy: Option<f64>,
    nodata: Option<f64>,
}

pub(super) fn parse(text: &str, file: &str) -> Result<Grid, InputError> {
    let mut tokens = text
        .lines()
        .enumerate()
        .flat_map(|(i, l)| l.split_whitespace().map(move |t| (i + 1, t)))
        .peekable();
    let mut h = Header::default();
    // Header: "key value" pairs until the first numeric token.
    while let Some(&(line, key)) = tokens.peek() {
        if key.parse::<f64>().is_ok() {
            break;
        }
        tokens.next();
        let (_, value) = tokens.next().ok_or_else(|| {
            InputError::line(file, line, format!("header key '{key}' has no value"))
        })?;
        let num = || {
            value.parse::<f64>().map_err(|_| {
                InputError::line(file, line, format!("invalid value '{value}' for '{key}'"))
            })
        };
        let count = || {
            value.parse::<usize>().map_err(|_| {
                InputError::line(file, line, format!("invalid value '{value}' for '{key}'"))
            })
        };
        match key.to_ascii_lowercase().as_str() {
            "ncols" => h.ncols = Some(count()?),
            "nrows" => h.nrows = Some(count()?),
            "xllcorner" => h.x = Some((num()?, true)),
            "xllcenter" | "xllcentre" => h.x = Some((num()?, false)),
            "yllcorner" => h.y = Some((num()?, true)),
            "yllcenter" | "yllcentre" => h.y = Some((num()?, false)),
            "cellsize" => h.cellsize = Some(num()?),
            "dx" | "xdim" => h.dx = Some(num()?),
            "dy" | "ydim" => h.dy = Some(num()?),
            // `nodata` is how some writers (and GDAL's driver, reading)
            // spell it.
            "nodata_value" | "nodata" => h.nodata = Some(num()?),
            "byteorder" => {}
            _ => {
                return Err(InputError::line(
                    file,
                    line,
                    format!("unknown header key '{key}'"),
                ));
            }
        }
    }
    let missing =
        |what: &str| InputError::malformed(file, format!("ESRI grid header lacks '{what}'"));
    let ncols = h.ncols.ok_or_else(|| missing("ncols"))?;
    let nrows = h.nrows.ok_or_else(|| missing("nrows"))?;
    let (x, x_corner) = h.x.ok_or_else(|| missing("xllcorner"))?;
    let (y, y_corner) = h.y.ok_or_else(|| missing("yllcorner"))?;
    let (dx, dy) = match (h.cellsize, h.dx, h.dy) {
        (_, Some(dx), Some(dy)) => (dx, dy),
        (Some(c), _, _) => (c, c),
        _ => return Err(missing("cellsize")),
    };
    if !(dx > 0.0 && dy > 0.0 && dx.is_finite() && dy.is_finite()) {
        return Err(InputError::malformed(
            file,
            format!("cell size must be positive, got {dx} x {dy}"),
        ));
    }
    let total = (ncols as u64).saturating_mul(nrows as u64);
    check_vertex_count(file, total)?;
    let total = total as usize;

    let mut values = Vec::with_capacity(total.min(1 << 26));
    let mut last_line = 0;
    for (line, token) in tokens.by_ref() {
        last_line = line;
        if values.len() == total {
            return Err(InputError::line(
                file,
                line,
                format!("unexpected value '{token}' after the {total} grid values"),
            ));
        }
        let v = token.parse::<f64>().map_err(|_| {
            let (r, c) = (values.len() / ncols.max(1), values.len() % ncols.max(1));
            InputError::line(
                file,
                line,
                format!("invalid value '{token}' at row {r}, column {c}"),
            )
        })?;
        values.push(v);
    }
    if values.len() < total {
        return Err(InputError::malformed(
            file,
            format!(
                "expected {nrows} x {ncols} = {total} values, found {} (file ends at line {last_line})",
                values.len()
            ),
        ));
    }
    let south_west = [
        if x_corner { x + dx / 2.0 } else { x },
        if y_corner { y + dy / 2.0 } else { y },
    ];
    Grid::from_north_first(nrows, ncols, values, south_west, [dx, dy], h.nodata)
        .ok_or_else(|| InputError::malformed(file, "grid size mismatch"))
}

#[cfg(test)]
mod tests {
    use super::super::test_util::TempFile;
    use super::super::{ReadOptions, check_mesh, read_mesh};
    use super::*;

    const SAMPLE: &str = "ncols 3\nNROWS 2\nxllcorner 100\nyllcorner 200\ncellsize 10\nNODATA_value -9999\n\
1 2 3\n4 5\n-9999\n";

    #[test]
    fn parses_header_and_flips_rows() {
        let g = parse(SAMPLE, "t.asc").unwrap();
        assert_eq!((g.rows, g.cols), (2, 3));
        assert_eq!(g.origin, [105.0, 205.0]);
        assert_eq!(g.spacing, [10.0, 10.0]);
        // South row first.
        assert_eq!(g.elevations, vec![4.0, 5.0, -9999.0, 1.0, 2.0, 3.0]);
        assert_eq!(g.nodata, Some(-9999.0));
    }

    /// `nodata` for `NODATA_value` (an audit, 2026-12-08), and a byte
    /// order mark before the header.
    #[test]
    fn nodata_spelled_short_and_a_byte_order_mark() {
        let text = format!("\u{feff}{}", SAMPLE.replace("NODATA_value", "nodata"));
        let f = TempFile::new("short.asc", text.as_bytes());
        let m = read_mesh(&f.0, &ReadOptions::default()).unwrap();
        assert_eq!((m.positions.len(), m.triangles.len()), (5, 3));
    }

    #[test]
    fn reads_to_mesh_with_nodata_dropped() {
        let f = TempFile::new("t.asc", SAMPLE.as_bytes());
        let m = read_mesh(&f.0, &ReadOptions::default()).unwrap();
        assert_eq!(m.positions.len(), 5);
        assert_eq!(m.triangles.len(), 3);
        assert!(m.positions.contains(&[105.0, 215.0, 1.0]));
        assert!(m.positions.contains(&[115.0, 205.0, 5.0]));
        check_mesh(&m).unwrap();
    }

    #[test]
    fn centre_origin_and_dx_dy() {
        let g = parse(
            "ncols 2\nnrows 2\nxllcenter 1\nyllcenter 2\ndx 0.5\ndy 0.25\n1 2 3 4\n",
            "t.asc",
        )
        .unwrap();
        assert_eq!(g.origin, [1.0, 2.0]);
        assert_eq!(g.spacing, [0.5, 0.25]);
    }

    #[test]
    fn errors_name_the_line() {
        let cases = [
            (
                "ncols 2\nnrows 1\nxllcorner 0\nyllcorner 0\ncellsize 1\n1 x\n",
                "t.asc: line 6: invalid value 'x' at row 0, column 1",
            ),
            (
                "ncols 2\nnrows 1\nxllcorner 0\nyllcorner 0\ncellsize 1\n1 2\n3\n",
                "t.asc: line 7: unexpected value '3' after the 2 grid values",
            ),
            (
                "ncols 2\nnrows 2\nxllcorner 0\nyllcorner 0\ncellsize 1\n1 2\n3\n",
                "t.asc: expected 2 x 2 = 4 values, found 3 (file ends at line 7)",
            ),
            (
                "ncols two\n",
                "t.asc: line 1: invalid value 'two' for 'ncols'",
            ),
            (
                "ncols 2\nnrows 2\nxllcorner 0\ncellsize 1\n1 2 3 4\n",
                "t.asc: ESRI grid header lacks 'yllcorner'",
            ),
            (
                "ncols 2\nfoo 1\n",
                "t.asc: line 2: unknown header key 'foo'",
            ),
            (
                "ncols 2\nnrows 2\nxllcorner 0\nyllcorner 0\ncellsize -1\n1 2 3 4\n",
                "t.asc: cell size must be positive, got -1 x -1",
            ),
        ];
        for (text, expected) in cases {
            assert_eq!(parse(text, "t.asc").unwrap_err().to_string(), expected);
        }
    }
}
