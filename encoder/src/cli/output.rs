//! Writing decoded meshes as binary little-endian PLY or OBJ.

use std::io::{BufWriter, Write};
use std::path::Path;

/// The output format of `path`, or an error naming it, so commands can
/// refuse a bad output before doing their work.
pub fn mesh_extension(path: &Path) -> Result<String, String> {
    let ext = path
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default();
    match ext.as_str() {
        "ply" | "obj" => Ok(ext),
        _ => Err(format!(
            "{}: output must end in .ply or .obj",
            path.display()
        )),
    }
}

/// Writes `positions` and `triangles` to `path`, format chosen by extension.
pub fn write_mesh(
    path: &Path,
    positions: &[[f64; 3]],
    triangles: &[[u32; 3]],
) -> Result<(), String> {
    let name = path.display();
    let ext = mesh_extension(path)?;
    let file = std::fs::File::create(path).map_err(|e| format!("{name}: {e}"))?;
    let mut w = BufWriter::new(file);
    let io = |e: std::io::Error| format!("{name}: {e}");
    match ext.as_str() {
        "ply" => {
            write!(
                w,
                "ply\nformat binary_little_endian 1.0\ncomment written by splitstream\n\
                 element vertex {}\nproperty double x\nproperty double y\nproperty double z\n\
                 element face {}\nproperty list uchar uint vertex_indices\nend_header\n",
                positions.len(),
                triangles.len()
            )
            .map_err(io)?;
            for p in positions {
                for v in p {
                    w.write_all(&v.to_le_bytes()).map_err(io)?;
                }
            }
            for t in triangles {
                w.write_all(&[3]).map_err(io)?;
                for v in t {
                    w.write_all(&v.to_le_bytes()).map_err(io)?;
                }
            }
        }
        "obj" => {
            writeln!(w, "# written by splitstream").map_err(io)?;
            for p in positions {
                writeln!(w, "v {} {} {}", p[0], p[1], p[2]).map_err(io)?;
            }
            for t in triangles {
                writeln!(w, "f {} {} {}", t[0] + 1, t[1] + 1, t[2] + 1).map_err(io)?;
            }
        }
        _ => return Err(format!("{name}: output must end in .ply or .obj")),
    }
    w.flush().map_err(io)
}
