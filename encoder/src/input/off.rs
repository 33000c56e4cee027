//! OFF reader, by hand: the format is a few lines of text and no crate adds
//! value. Accepts the `OFF`/`COFF`/`NOFF`/`CNOFF`/`STOFF` header keywords
//! (extra per-vertex and per-face values such as colours are ignored), `#`
//! comments anywhere, blank lines, the counts on the header line or the next
//! line (or glued to the keyword, `OFF8 6 0`), and polygons (fanned, a
//! concave one cut by ear clipping: `polygon.rs`). Lines after the
//! declared faces are ignored. Every error names its line.

use std::path::Path;

use crate::Mesh;

use super::{InputError, Polygons, ascii_lines, check_vertex_count, push_polygon, text_of};

pub(super) fn read(path: &Path, file: &str) -> Result<Mesh, InputError> {
    let bytes = std::fs::read(path).map_err(|e| InputError::io(file, e))?;
    super::refuse_utf16(&bytes, file)?;
    parse(&text_of(&bytes), file)
}

/// Non-empty lines with comments stripped, with their 1-based numbers.
fn content_lines(text: &str) -> impl Iterator<Item = (usize, &str)> {
    ascii_lines(text)
        .enumerate()
        .map(|(i, l)| (i + 1, l.split('#').next().unwrap_or("").trim_ascii()))
        .filter(|(_, l)| !l.is_empty())
}

fn parse_count(
    file: &str,
    line: usize,
    token: Option<&str>,
    what: &str,
) -> Result<usize, InputError> {
    let token = token.ok_or_else(|| InputError::line(file, line, format!("missing {what}")))?;
    token
        .parse::<usize>()
        .map_err(|_| InputError::line(file, line, format!("invalid {what} '{token}'")))
}

pub(super) fn parse(text: &str, file: &str) -> Result<Mesh, InputError> {
    let mut lines = content_lines(text);
    let (line_no, header) = lines
        .next()
        .ok_or_else(|| InputError::malformed(file, "empty file (expected an 'OFF' header)"))?;
    let mut tokens = header.split_ascii_whitespace();
    let mut keyword = tokens.next().unwrap_or("");
    // `OFF8 6 0`: the counts run into the keyword (many ModelNet files).
    let mut glued = None;
    if let Some(at) = keyword.find(|c: char| c.is_ascii_digit())
        && keyword[..at].ends_with("OFF")
    {
        glued = Some(&keyword[at..]);
        keyword = &keyword[..at];
    }
    let known = [
        "OFF", "COFF", "NOFF", "CNOFF", "STOFF", "STCOFF", "STNOFF", "STCNOFF",
    ];
    if !known.contains(&keyword) {
        if keyword.ends_with("OFF") {
            return Err(InputError::unsupported(
                file,
                format!("OFF variant '{keyword}'"),
            ));
        }
        return Err(InputError::line(
            file,
            line_no,
            format!("expected an 'OFF' header, found '{keyword}'"),
        ));
    }
    let mut rest: Vec<&str> = glued.into_iter().chain(tokens).collect();
    if rest
        .first()
        .is_some_and(|t| t.eq_ignore_ascii_case("BINARY"))
    {
        return Err(InputError::unsupported(file, "binary OFF"));
    }
    let mut counts_line = line_no;
    if rest.is_empty() {
        let (n, l) = lines
            .next()
            .ok_or_else(|| InputError::line(file, line_no, "missing vertex and face counts"))?;
        counts_line = n;
        rest = l.split_ascii_whitespace().collect();
    }
    let mut counts = rest.into_iter();
    let nv = parse_count(file, counts_line, counts.next(), "vertex count")?;
    let nf = parse_count(file, counts_line, counts.next(), "face count")?;
    check_vertex_count(file, nv as u64)?;

    // At most one vertex per 6 bytes ("0 0 0\n") and one face per 8: the
    // counts in the header reserve no more than the text can hold.
    let mut positions = Vec::with_capacity(nv.min(text.len() / 6));
    let mut last_line = counts_line;
    for i in 0..nv {
        let (n, l) = lines.next().ok_or_else(|| {
            InputError::line(
                file,
                last_line,
                format!("file ends after {i} of {nv} vertices"),
            )
        })?;
        last_line = n;
        let mut p = [0.0; 3];
        let mut found = 0;
        for (k, token) in l.split_ascii_whitespace().take(3).enumerate() {
            p[k] = token.parse::<f64>().map_err(|_| {
                InputError::line(file, n, format!("vertex {i}: invalid coordinate '{token}'"))
            })?;
            found += 1;
        }
        if found < 3 {
            return Err(InputError::line(
                file,
                n,
                format!("expected 3 coordinates, found {found}"),
            ));
        }
        positions.push(p);
    }

    let mut triangles = Vec::with_capacity(nf.min(text.len() / 8));
    let mut polygons = Polygons::default();
    for i in 0..nf {
        let (n, l) = lines.next().ok_or_else(|| {
            InputError::line(
                file,
                last_line,
                format!("file ends after {i} of {nf} faces"),
            )
        })?;
        last_line = n;
        let mut tokens = l.split_ascii_whitespace();
        let count = parse_count(file, n, tokens.next(), "face vertex count")?;
        // The line holds at most one index per two bytes: a count beyond
        // that fails below, without reserving memory for it first.
        let mut indices = Vec::with_capacity(count.min(l.len() / 2));
        for _ in 0..count {
            let token = tokens.next().ok_or_else(|| {
                InputError::line(
                    file,
                    n,
                    format!(
                        "face {i}: expected {count} vertex indices, found {}",
                        indices.len()
                    ),
                )
            })?;
            let index = token.parse::<i64>().map_err(|_| {
                InputError::line(file, n, format!("face {i}: invalid vertex index '{token}'"))
            })?;
            indices.push(index);
        }
        push_polygon(&mut triangles, indices, nv, &mut polygons)
            .map_err(|m| InputError::line(file, n, format!("face {i}: {m}")))?;
    }
    // Lines after the declared faces are ignored, as CGAL's reader ignores
    // them: its own sample prim.off declares 7 of the 8 faces it holds.
    let mut mesh = Mesh {
        positions,
        triangles,
    };
    polygons.untangle(&mut mesh);
    Ok(mesh)
}

#[cfg(test)]
mod tests {
    use super::super::test_util::TempFile;
    use super::super::{ReadOptions, read_mesh};
    use super::*;

    /// Found by an audit of real-world files (2026-12-08): `OFF8 6 0`
    /// (ModelNet) was refused and a UTF-8 byte order mark made the keyword
    /// unknown. Faces beyond the header's count stay ignored, as CGAL reads
    /// them (its prim.off declares 7 of its 8 faces).
    #[test]
    fn glued_counts_a_byte_order_mark_and_surplus_faces() {
        let body = "0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n";
        for head in ["OFF4 4 0\n", "\u{feff}OFF\n4 4 0\n"] {
            let text = format!("{head}{body}");
            let f = TempFile::new("head.off", text.as_bytes());
            let m = read_mesh(&f.0, &ReadOptions::default()).unwrap();
            assert_eq!((m.positions.len(), m.triangles.len()), (4, 4), "{head:?}");
        }
        let f = TempFile::new("surplus.off", format!("OFF\n4 3 0\n{body}").as_bytes());
        let m = read_mesh(&f.0, &ReadOptions::default()).unwrap();
        assert_eq!(m.triangles.len(), 3);
    }

    #[test]
    fn reads_comments_counts_on_header_and_polygons() {
        let text = "# a comment\nOFF 5 2 0 # counts here\n\n0 0 0\n1 0 0 # trailing\n1 1 0\n0 1 0 \n2 0.5 0 0.1 0.2 0.3\n\
4 0 1 2 3\n3 1 4 2 255 0 0\n";
        let f = TempFile::new("poly.off", text.as_bytes());
        let m = read_mesh(&f.0, &ReadOptions::default()).unwrap();
        assert_eq!(m.positions.len(), 5);
        assert_eq!(m.positions[4], [2.0, 0.5, 0.0]);
        assert_eq!(m.triangles, vec![[0, 1, 2], [0, 2, 3], [1, 4, 2]]);
    }

    /// Found by fuzzing (`encoder/fuzz`, `read_input`): a face line that
    /// claims 888,888,888 vertices reserved 7 GB before reading them.
    #[test]
    fn huge_polygon_count_fails_without_reserving_it() {
        let text = "OFF\n4 1 0\n0 0 0\n1 0 0\n888.0 0 0\n1 0 0\n888888888 3888888 3 2\n";
        let msg = parse(text, "big.off").unwrap_err().to_string();
        assert!(
            msg.contains("face 0: expected 888888888 vertex indices, found 3"),
            "{msg}"
        );
    }

    #[test]
    fn counts_on_next_line() {
        let m = parse(
            "COFF\n3 1 3\n0 0 0 1 1 1 1\n1 0 0 1 1 1 1\n0 1 0 1 1 1 1\n3 0 1 2\n",
            "t.off",
        )
        .unwrap();
        assert_eq!(m.triangles, vec![[0, 1, 2]]);
    }

    #[test]
    fn errors_name_the_line() {
        let cases = [
            (
                "OFF\n3 1 0\n0 0 0\n1 0\n0 1 0\n3 0 1 2\n",
                "bunny.off: line 4: expected 3 coordinates, found 2",
            ),
            (
                "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 5\n",
                "bunny.off: line 6: face 0: vertex index 5 out of range (the file has 3 vertices)",
            ),
            (
                "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1\n",
                "bunny.off: line 6: face 0: expected 3 vertex indices, found 2",
            ),
            (
                "OFF\n3 2 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n",
                "bunny.off: line 6: file ends after 1 of 2 faces",
            ),
            (
                "OFF\n3 1 0\n0 0 0\n1 x 0\n",
                "bunny.off: line 4: vertex 1: invalid coordinate 'x'",
            ),
            (
                "OFF\nthree 1 0\n",
                "bunny.off: line 2: invalid vertex count 'three'",
            ),
            (
                "PLY\n",
                "bunny.off: line 1: expected an 'OFF' header, found 'PLY'",
            ),
            ("", "bunny.off: empty file (expected an 'OFF' header)"),
            ("OFF BINARY\n", "bunny.off: unsupported: binary OFF"),
            ("4OFF\n", "bunny.off: unsupported: OFF variant '4OFF'"),
        ];
        for (text, expected) in cases {
            assert_eq!(parse(text, "bunny.off").unwrap_err().to_string(), expected);
        }
    }
}
