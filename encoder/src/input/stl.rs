//! STL reader (binary and ascii) on top of `stl_io`.
//!
//! STL stores each triangle with three coordinates of its own; `stl_io`
//! welds corners whose f32 coordinates are bit-identical into one vertex,
//! which is how STL meshes share vertices at all. Input vertex ids (as
//! `--permutation` reports them) number the distinct positions in the order
//! the facets first use them.
//!
//! A binary file is recognised by its size (84 + 50 bytes per facet, the
//! facet count at byte 80), before `stl_io` looks at it: `stl_io` takes
//! any file whose first line starts with `solid ` for ascii, and some
//! exporters begin a binary header with those very bytes.

use std::io::Cursor;
use std::path::Path;

use crate::Mesh;

use super::{InputError, check_vertex_count};

pub(super) fn read(path: &Path, file: &str) -> Result<Mesh, InputError> {
    let bytes = std::fs::read(path).map_err(|e| InputError::io(file, e))?;
    parse(bytes, file)
}

pub(super) fn parse(mut bytes: Vec<u8>, file: &str) -> Result<Mesh, InputError> {
    if is_binary(&bytes) && bytes.starts_with(b"solid") {
        // Steer `stl_io` to its binary reader; the header is free text.
        bytes[0] = b' ';
    }
    let stl = stl_io::read_stl(&mut Cursor::new(bytes))
        .map_err(|e| InputError::malformed(file, format!("invalid STL: {e}")))?;
    check_vertex_count(file, stl.vertices.len() as u64)?;
    let mut mesh = Mesh {
        positions: Vec::with_capacity(stl.vertices.len()),
        triangles: Vec::with_capacity(stl.faces.len()),
    };
    for (i, v) in stl.vertices.iter().enumerate() {
        let p = [v[0] as f64, v[1] as f64, v[2] as f64];
        if p.iter().any(|c| !c.is_finite()) {
            return Err(InputError::element(
                file,
                format!("vertex {i}"),
                "coordinate is not a finite number",
            ));
        }
        mesh.positions.push(p);
    }
    mesh.triangles
        .extend(stl.faces.iter().map(|f| f.vertices.map(|v| v as u32)));
    if mesh.triangles.is_empty() {
        return Err(InputError::malformed(file, "no facets"));
    }
    Ok(mesh)
}

/// Whether the size is exactly that of a binary STL with the facet count
/// its header gives.
fn is_binary(bytes: &[u8]) -> bool {
    let Some(count) = bytes.get(80..84) else {
        return false;
    };
    let count = u32::from_le_bytes([count[0], count[1], count[2], count[3]]) as u64;
    84 + 50 * count == bytes.len() as u64
}

#[cfg(test)]
mod tests {
    use super::super::test_util::TempFile;
    use super::super::{ReadOptions, check_mesh, read_mesh};
    use super::*;

    /// A closed tetrahedron, counter-clockwise seen from outside.
    const TETRA: [[[f32; 3]; 3]; 4] = [
        [[0., 0., 0.], [0., 1., 0.], [1., 0., 0.]],
        [[0., 0., 0.], [1., 0., 0.], [0., 0., 1.]],
        [[0., 0., 0.], [0., 0., 1.], [0., 1., 0.]],
        [[1., 0., 0.], [0., 1., 0.], [0., 0., 1.]],
    ];

    fn binary(header: &[u8], facets: &[[[f32; 3]; 3]]) -> Vec<u8> {
        let mut out = vec![0u8; 80];
        out[..header.len()].copy_from_slice(header);
        out.extend_from_slice(&(facets.len() as u32).to_le_bytes());
        for f in facets {
            out.extend_from_slice(&[0u8; 12]); // the normal, unused
            for v in f {
                for c in v {
                    out.extend_from_slice(&c.to_le_bytes());
                }
            }
            out.extend_from_slice(&[0, 0]);
        }
        out
    }

    fn ascii(facets: &[[[f32; 3]; 3]]) -> String {
        let mut s = String::from("solid tetra\n");
        for f in facets {
            s.push_str("facet normal 0 0 0\n outer loop\n");
            for v in f {
                s.push_str(&format!("  vertex {} {} {}\n", v[0], v[1], v[2]));
            }
            s.push_str(" endloop\nendfacet\n");
        }
        s.push_str("endsolid tetra\n");
        s
    }

    #[test]
    fn binary_and_ascii_weld_into_a_closed_tetrahedron() {
        let files = [
            binary(b"made by a test", &TETRA),
            // An exporter's binary header that starts like ascii.
            binary(b"solid tetra exported as binary", &TETRA),
            ascii(&TETRA).into_bytes(),
        ];
        for bytes in files {
            let f = TempFile::new("tetra.stl", &bytes);
            let m = read_mesh(&f.0, &ReadOptions::default()).unwrap();
            assert_eq!(m.positions.len(), 4);
            assert_eq!(
                m.triangles,
                vec![[0, 1, 2], [0, 2, 3], [0, 3, 1], [2, 1, 3]]
            );
            let stats = check_mesh(&m).unwrap();
            assert_eq!((stats.components, stats.boundary_loops), (1, 0));
        }
    }

    #[test]
    fn bad_files_get_one_line() {
        let mut nan = TETRA;
        nan[3][2][1] = f32::NAN;
        let cases: Vec<(Vec<u8>, &str)> = vec![
            (binary(b"", &[]), "bad.stl: no facets"),
            (
                binary(b"", &nan),
                "bad.stl: vertex 4: coordinate is not a finite number",
            ),
            // A facet count beyond the data: truncated.
            (
                binary(b"", &TETRA)[..120].to_vec(),
                "bad.stl: invalid STL: ",
            ),
            (
                b"solid x\nfacet normal 0 0 0\n outer loop\n vertex 1 2\n".to_vec(),
                "bad.stl: invalid STL: ",
            ),
        ];
        for (bytes, expected) in cases {
            let msg = parse(bytes, "bad.stl").unwrap_err().to_string();
            assert!(msg.starts_with(expected), "{msg}");
            assert!(!msg.contains('\n'), "{msg}");
        }
        // A count of 2^32 - 1 facets in a short file fails without
        // reserving memory for them.
        let mut huge = binary(b"", &TETRA);
        huge[80..84].copy_from_slice(&u32::MAX.to_le_bytes());
        assert!(parse(huge, "bad.stl").is_err());
    }
}
