//! Wavefront OBJ reader: positions (`v`) and faces (`f`) only.
//!
//! Vertex ids are the file's: the i-th `v` statement is vertex i, whether
//! or not a face uses it (an unused one is then reported by the input
//! check, as for the other formats), so `encode --permutation` maps decoded
//! vertices to the file's own numbering and attributes can follow. The
//! `tobj` crate, used before, renumbers vertices in the order faces first
//! use them and drops unused ones; it offers no way back to the file's
//! numbering, hence this reader. It takes what the OBJ format says of
//! these two statements: 1-based indices, negative ones relative to the
//! vertices read so far, `v/vt/vn` forms (only `v` is kept), polygons
//! fanned into triangles from their first vertex (a concave one cut by ear
//! clipping instead, `polygon.rs`), `#` comments anywhere on a line, `\`
//! line continuations;
//! every other statement (`vt`, `vn`, `o`, `g`, `usemtl`, `l`, …) is
//! skipped. Coordinates stay f64.

use std::borrow::Cow;
use std::path::Path;

use crate::Mesh;

use super::{InputError, ascii_lines, check_vertex_count, text_of};

pub(super) fn read(path: &Path, file: &str) -> Result<Mesh, InputError> {
    let bytes = std::fs::read(path).map_err(|e| InputError::io(file, e))?;
    super::refuse_utf16(&bytes, file)?;
    parse(&text_of(&bytes), file)
}

/// The statements of `text`, each with the line it starts on (1-based),
/// continuation lines (`\` at a line's end) joined. A statement of one
/// line, nearly all of them, is borrowed from `text`, not copied.
fn statements(text: &str) -> impl Iterator<Item = (usize, Cow<'_, str>)> + '_ {
    let mut lines = ascii_lines(text).enumerate();
    std::iter::from_fn(move || {
        let (i, first) = lines.next()?;
        if !first.trim_ascii_end().ends_with('\\') {
            return Some((i + 1, Cow::Borrowed(first)));
        }
        let mut statement = first.to_string();
        while statement.trim_ascii_end().ends_with('\\') {
            let cut = statement.trim_ascii_end().len() - 1;
            statement.truncate(cut);
            match lines.next() {
                Some((_, more)) => {
                    statement.push(' ');
                    statement.push_str(more);
                }
                None => break,
            }
        }
        Some((i + 1, Cow::Owned(statement)))
    })
}

pub(super) fn parse(text: &str, file: &str) -> Result<Mesh, InputError> {
    let mut mesh = Mesh::default();
    // Each face corner as the file wrote it: a positive index may name a
    // vertex defined further down, so they are resolved at the end.
    let mut corners: Vec<(i64, usize)> = Vec::new();
    let mut polygon: Vec<(i64, usize)> = Vec::new();
    let mut polygons = super::Polygons::default();
    let mut skipped = 0usize;
    for (line, statement) in statements(text) {
        // OBJ is ASCII: its separators are ASCII blanks; `#` starts a
        // comment anywhere on a line (`f 1 2 3 # a quad` was refused).
        let body = statement.split('#').next().unwrap_or_default();
        let mut words = body.split_ascii_whitespace();
        match words.next() {
            Some("v") => {
                let mut xyz = [0.0f64; 3];
                for (axis, x) in xyz.iter_mut().enumerate() {
                    let word = words.next().ok_or_else(|| {
                        InputError::line(file, line, format!("vertex with {axis} coordinates"))
                    })?;
                    *x = word.parse().map_err(|_| {
                        InputError::line(file, line, format!("'{word}' is not a coordinate"))
                    })?;
                }
                // A w or vertex colours may follow: not positions.
                mesh.positions.push(xyz);
                check_vertex_count(file, mesh.positions.len() as u64)?;
            }
            Some("f") => {
                polygon.clear();
                for word in words {
                    let v = word.split_once('/').map_or(word, |(v, _)| v);
                    let index: i64 = v.parse().map_err(|_| {
                        InputError::line(file, line, format!("'{word}' is not a vertex index"))
                    })?;
                    // Negative: relative to the vertices read so far.
                    let index = match index {
                        0 => {
                            return Err(InputError::line(file, line, "vertex index 0"));
                        }
                        i if i < 0 => mesh.positions.len() as i64 + i + 1,
                        i => i,
                    };
                    if index < 1 {
                        return Err(InputError::line(
                            file,
                            line,
                            format!("'{word}' points before the first vertex"),
                        ));
                    }
                    polygon.push((index, line));
                }
                if polygon.len() < 3 {
                    return Err(InputError::line(
                        file,
                        line,
                        format!("face with {} vertices", polygon.len()),
                    ));
                }
                // A corner repeated at once (`f 1 2 3 3`, a triangle
                // written as a quad) is one corner.
                super::merge_repeated_corners(&mut polygon, |c| c.0);
                polygons.note(corners.len() / 3, polygon.len());
                for i in 1..polygon.len() - 1 {
                    corners.extend([polygon[0], polygon[i], polygon[i + 1]]);
                }
            }
            Some("l" | "p") => skipped += 1,
            _ => {}
        }
    }
    if corners.is_empty() && skipped > 0 {
        return Err(InputError::malformed(
            file,
            format!("no faces ('f'): {skipped} line or point statements ('l', 'p') skipped"),
        ));
    }
    let n = mesh.positions.len() as i64;
    let resolve = |(index, line): (i64, usize)| {
        if index > n {
            Err(InputError::line(
                file,
                line,
                format!("vertex {index} of a file with {n} vertices"),
            ))
        } else {
            Ok((index - 1) as u32)
        }
    };
    mesh.triangles = corners
        .chunks_exact(3)
        .map(|t| Ok([resolve(t[0])?, resolve(t[1])?, resolve(t[2])?]))
        .collect::<Result<_, InputError>>()?;
    polygons.untangle(&mut mesh);
    Ok(mesh)
}

#[cfg(test)]
mod tests {
    use super::super::test_util::TempFile;
    use super::super::{ReadOptions, check_mesh, read_mesh};
    use super::*;

    #[test]
    fn groups_share_vertices_and_polygons_are_triangulated() {
        let text = "# square in two groups\nmtllib none.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 2 0.5 0.25\n\
vt 0 0\nvn 0 0 1\no first\ng a\nusemtl red\nf 1/1/1 2/1/1 3/1/1 4/1/1\ng b\nf -4//1 -1//1 -3//1\nl 1 2\n";
        let f = TempFile::new("sq.obj", text.as_bytes());
        let m = read_mesh(&f.0, &ReadOptions::default()).unwrap();
        assert_eq!(m.positions.len(), 5);
        assert_eq!(m.triangles.len(), 3);
        let stats = check_mesh(&m).unwrap();
        assert_eq!(stats.components, 1);
        // Geographic precision survives (tobj built with f64 positions).
        let m = parse(
            "v 12345678.123456 -0.1 1e-9\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
            "p.obj",
        )
        .unwrap();
        assert_eq!(m.positions[0], [12345678.123456, -0.1, 1e-9]);
    }

    /// Found by an audit of real-world files (2026-12-08): a UTF-8 byte
    /// order mark hid the first `v` (every index then named the next
    /// vertex), a comment after a face's indices was refused, and a
    /// triangle written as a quad with its last corner repeated had a
    /// degenerate fan triangle.
    #[test]
    fn byte_order_mark_comments_and_repeated_corners() {
        let text = "\u{feff}v 0 0 0\nv 1 0 0\nv 1 1 0 # a comment\nv 0 1 0\nv 9 9 9\n\
                    f 1 2 3 # a triangle\nf 1 3 4 4\n";
        let f = TempFile::new("bom.obj", text.as_bytes());
        let m = read_mesh(&f.0, &ReadOptions::default()).unwrap();
        assert_eq!(m.positions[0], [0.0, 0.0, 0.0]);
        assert_eq!(m.positions.len(), 5);
        assert_eq!(m.triangles, vec![[0, 1, 2], [0, 2, 3]]);
    }

    /// The audit's L-shaped hexagon (2026-12-08): its fan from the first
    /// corner turned a triangle over; it is cut into upright triangles.
    #[test]
    fn a_concave_face_is_cut_without_a_fold() {
        let text = "v 2 1 0\nv 1 1 0\nv 1 2 0\nv 0 2 0\nv 0 0 0\nv 2 0 0\nf 1 2 3 4 5 6\n";
        let f = TempFile::new("ell.obj", text.as_bytes());
        let m = read_mesh(&f.0, &ReadOptions::default()).unwrap();
        assert_eq!(m.triangles.len(), 4);
        for t in &m.triangles {
            let [a, b, c] = t.map(|v| m.positions[v as usize]);
            let area = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
            assert!(area > 0.0, "{t:?} in {:?}", m.triangles);
        }
    }

    /// Files with nothing to read said only that the mesh was empty (an
    /// audit, 2026-12-08).
    #[test]
    fn lines_only_and_utf16_files_say_why_nothing_was_read() {
        let f = TempFile::new("lines.obj", b"v 0 0 0\nv 1 0 0\nv 0 1 0\nl 1 2 3\np 1\n");
        let err = read_mesh(&f.0, &ReadOptions::default())
            .unwrap_err()
            .to_string();
        assert!(
            err.contains("no faces ('f'): 2 line or point statements"),
            "{err}"
        );
        let utf16: Vec<u8> = "\u{feff}v 0 0 0\n"
            .encode_utf16()
            .flat_map(u16::to_le_bytes)
            .collect();
        let f = TempFile::new("utf16.obj", &utf16);
        let err = read_mesh(&f.0, &ReadOptions::default())
            .unwrap_err()
            .to_string();
        assert!(err.contains("a UTF-16 text file"), "{err}");
    }

    #[test]
    fn bad_indices_fail() {
        for (text, message) in [
            (
                "v 0 0 0\nf 1 2 3\n",
                "bad.obj: line 2: vertex 2 of a file with 1 vertices",
            ),
            (
                "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 x\n",
                "bad.obj: line 4: 'x' is not a vertex index",
            ),
            ("v 0 0\n", "bad.obj: line 1: vertex with 2 coordinates"),
            ("v 0 0 z\n", "bad.obj: line 1: 'z' is not a coordinate"),
            (
                "v 0 0 0\nv 1 0 0\nf 1 2\n",
                "bad.obj: line 3: face with 2 vertices",
            ),
            ("v 0 0 0\nf 0 1 1\n", "bad.obj: line 2: vertex index 0"),
            (
                "v 0 0 0\nf -2 1 1\n",
                "bad.obj: line 2: '-2' points before the first vertex",
            ),
        ] {
            let msg = parse(text, "bad.obj").unwrap_err().to_string();
            assert_eq!(msg, message);
        }
    }

    /// Vertex ids are the file's `v` order, whatever order the faces use
    /// them in, so a permutation written by `encode` indexes the file's
    /// vertices; an unused vertex stays and the check names it.
    #[test]
    fn vertices_keep_the_files_order() {
        let text = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nv 9 9 9\n\
f 4 2 3\nf 4 3 1\nf 4 1 2\nf 1 3 2\n";
        let m = parse(text, "t.obj").unwrap();
        assert_eq!(m.positions[3], [0.0, 0.0, 1.0]);
        assert_eq!(m.positions.len(), 5);
        assert_eq!(m.triangles[0], [3, 1, 2]);
        let err = check_mesh(&m).unwrap_err().to_string();
        assert!(err.contains("vertex 4 (9, 9, 9) is not used"), "{err}");
    }

    /// Forward references, negative indices, `v/vt/vn` forms, polygons,
    /// continuation lines, a w and vertex colours.
    #[test]
    fn the_formats_index_forms_all_read() {
        let text = "f 1 2 3\nv 0 0 0 1\nv 1 0 0 0.5 0.5 0.5\nv 1 1 0\nv 0 1 \\\n  0\n\
f -4/1/1 -2//1 -1/2\nf 1/1 2/2 3/3 4/4 \\\n\n";
        let m = parse(text, "t.obj").unwrap();
        assert_eq!(m.positions.len(), 4);
        assert_eq!(m.positions[3], [0.0, 1.0, 0.0]);
        assert_eq!(
            m.triangles,
            vec![[0, 1, 2], [0, 2, 3], [0, 1, 2], [0, 2, 3]]
        );
    }
}
