//! Writing decoded meshes as binary little-endian PLY, OBJ or glTF binary
//! (GLB).

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
        "ply" | "obj" | "glb" => Ok(ext),
        _ => Err(format!(
            "{}: output must end in .ply, .obj or .glb",
            path.display()
        )),
    }
}

/// Refuses, before any work, a stream output that would overwrite a mesh:
/// a name with an input format's extension (`encode mine.ply -o mine.ply`
/// replaced the mesh with the stream, and `-o x.ply` wrote a stream no mesh
/// reader opens), or the input file itself (`input`: `encode`'s; a
/// transcode may rewrite its own stream). A folder that does not exist is
/// also named now, not after the encoding.
pub fn check_stream_output(path: &Path, input: Option<&Path>) -> Result<(), String> {
    let name = path.display();
    let ext = path
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default();
    if splitstream_encoder::input::SUPPORTED_EXTENSIONS.contains(&ext.as_str()) {
        return Err(format!(
            "{name}: a stream would be written under a mesh or grid file's extension (.{ext}); name it .sps"
        ));
    }
    if let Some(input) = input {
        let same = match (std::fs::canonicalize(path), std::fs::canonicalize(input)) {
            (Ok(a), Ok(b)) => a == b,
            _ => false,
        };
        if same {
            return Err(format!("{name} is the input file: choose another output"));
        }
    }
    let parent = path.parent().filter(|p| !p.as_os_str().is_empty());
    if let Some(dir) = parent
        && !dir.is_dir()
    {
        return Err(format!(
            "{name}: the folder {} does not exist",
            dir.display()
        ));
    }
    Ok(())
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
        "glb" => w.write_all(&glb(positions, triangles)?).map_err(io)?,
        _ => return Err(format!("{name}: output must end in .ply, .obj or .glb")),
    }
    w.flush().map_err(io)
}

/// A GLB holding one mesh: f32 positions relative to the bounding box's
/// centre, and that centre as the node's translation. JSON numbers keep
/// f64, so a large offset (geographic coordinates) survives in readers that
/// compose transforms in double precision (three.js, Cesium, this crate's),
/// where absolute f32 positions would lose it.
fn glb(positions: &[[f64; 3]], triangles: &[[u32; 3]]) -> Result<Vec<u8>, String> {
    let (lo, hi) = positions.iter().fold(
        ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]),
        |(lo, hi), p| {
            (
                std::array::from_fn(|k| lo[k].min(p[k])),
                std::array::from_fn(|k| hi[k].max(p[k])),
            )
        },
    );
    let centre: [f64; 3] = if positions.is_empty() {
        [0.0; 3]
    } else {
        std::array::from_fn(|k| (lo[k] + hi[k]) / 2.0)
    };
    let mut bin = Vec::with_capacity(12 * positions.len() + 12 * triangles.len());
    let (mut min, mut max) = ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]);
    for p in positions {
        for k in 0..3 {
            let v = (p[k] - centre[k]) as f32;
            min[k] = min[k].min(v);
            max[k] = max[k].max(v);
            bin.extend_from_slice(&v.to_le_bytes());
        }
    }
    let position_bytes = bin.len();
    for t in triangles {
        for v in t {
            bin.extend_from_slice(&v.to_le_bytes());
        }
    }
    if positions.is_empty() {
        (min, max) = ([0.0; 3], [0.0; 3]);
    }
    const ARRAY_BUFFER: u32 = 34962;
    const ELEMENT_ARRAY_BUFFER: u32 = 34963;
    const FLOAT: u32 = 5126;
    const UNSIGNED_INT: u32 = 5125;
    let document = serde_json::json!({
        "asset": { "version": "2.0", "generator": "splitstream" },
        "scene": 0,
        "scenes": [{ "nodes": [0] }],
        "nodes": [{ "mesh": 0, "translation": centre }],
        "meshes": [{ "primitives": [{ "attributes": { "POSITION": 0 }, "indices": 1 }] }],
        "accessors": [
            { "bufferView": 0, "componentType": FLOAT, "count": positions.len(),
              "type": "VEC3", "min": min, "max": max },
            { "bufferView": 1, "componentType": UNSIGNED_INT, "count": 3 * triangles.len(),
              "type": "SCALAR" }
        ],
        "bufferViews": [
            { "buffer": 0, "byteOffset": 0, "byteLength": position_bytes,
              "target": ARRAY_BUFFER },
            { "buffer": 0, "byteOffset": position_bytes,
              "byteLength": bin.len() - position_bytes, "target": ELEMENT_ARRAY_BUFFER }
        ],
        "buffers": [{ "byteLength": bin.len() }]
    });
    let json = serde_json::to_vec(&document).map_err(|e| e.to_string())?;
    if json.len() + bin.len() + 28 > u32::MAX as usize {
        return Err("the mesh is too large for one GLB (4 GiB)".into());
    }
    let glb = gltf::binary::Glb {
        header: gltf::binary::Header {
            magic: *b"glTF",
            version: 2,
            length: 0, // computed by `to_vec`
        },
        json: json.into(),
        bin: Some(bin.into()),
    };
    glb.to_vec().map_err(|e| e.to_string())
}
