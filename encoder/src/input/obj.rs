//! Wavefront OBJ reader on top of `tobj` (positions and faces only).
//!
//! tobj re-indexes vertices per object/group, which would disconnect groups
//! that share vertices. We therefore hand it only the `v` and `f` statements
//! (no `o`/`g`/`usemtl`/`mtllib`), so it builds one model whose indices keep
//! every shared vertex shared. tobj resolves negative (relative) indices and
//! fan-triangulates polygons; vertices no face uses are not returned.

use std::io::Cursor;
use std::path::Path;

use crate::Mesh;

use super::{InputError, check_vertex_count};

pub(super) fn read(path: &Path, file: &str) -> Result<Mesh, InputError> {
    let bytes = std::fs::read(path).map_err(|e| InputError::io(file, e))?;
    let text = String::from_utf8_lossy(&bytes);
    parse(&text, file)
}

/// Keeps `v` and `f` statements (and their `\` continuation lines).
fn geometry_only(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    let mut continuing = false;
    for line in text.lines() {
        let keep = continuing || matches!(line.split_whitespace().next(), Some("v" | "f"));
        if keep {
            out.push_str(line);
            out.push('\n');
        }
        continuing = keep && line.trim_end().ends_with('\\');
    }
    out
}

pub(super) fn parse(text: &str, file: &str) -> Result<Mesh, InputError> {
    let filtered = geometry_only(text);
    let options = tobj::LoadOptions {
        triangulate: true,
        single_index: false,
        ignore_points: true,
        ignore_lines: true,
    };
    let (models, _materials) =
        tobj::load_obj_buf(&mut Cursor::new(filtered.as_bytes()), &options, |_| {
            Err(tobj::LoadError::OpenFileFailed)
        })
        .map_err(|e| InputError::malformed(file, format!("invalid OBJ: {e}")))?;

    let mut mesh = Mesh::default();
    for model in models {
        let base = mesh.positions.len() as u64;
        let positions = &model.mesh.positions;
        check_vertex_count(file, base + positions.len() as u64 / 3)?;
        mesh.positions
            .extend(positions.chunks_exact(3).map(|p| [p[0], p[1], p[2]]));
        mesh.triangles.extend(
            model
                .mesh
                .indices
                .chunks_exact(3)
                .map(|t| [t[0] + base as u32, t[1] + base as u32, t[2] + base as u32]),
        );
    }
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

    #[test]
    fn bad_indices_fail() {
        for text in [
            "v 0 0 0\nf 1 2 3\n",
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 x\n",
            "v 0 0\n",
        ] {
            let msg = parse(text, "bad.obj").unwrap_err().to_string();
            assert!(msg.starts_with("bad.obj: invalid OBJ: "), "{msg}");
        }
    }
}
