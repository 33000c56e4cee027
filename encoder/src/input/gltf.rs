//! glTF 2.0 reader: `.glb`, and `.gltf` with external or embedded (`data:`)
//! buffers. Positions and triangles only.
//!
//! What is read:
//! * the default scene (`scene`, else the first), each node's mesh placed by
//!   its world transform, composed in f64: a geographic model keeps its
//!   large offsets in node translations, and f32 would lose them. Without
//!   scenes, every mesh once, untransformed;
//! * every primitive in `TRIANGLES`, `TRIANGLE_STRIP` or `TRIANGLE_FAN` mode
//!   (points and lines are skipped); indexed or not; positions in float, or
//!   in integers under `KHR_mesh_quantization`; sparse accessors;
//! * a world transform with a negative determinant (a mirror) reverses the
//!   winding, as the glTF specification says.
//!
//! Exporters split a vertex wherever its normal, texture coordinate or
//! material changes, which would cut the surface along every seam. This
//! encoder streams positions only, so vertices at exactly the same world
//! position are welded into one: input vertex ids (as `--permutation`
//! reports them) number the distinct positions in the order they are first
//! met (scene order, then primitive order, then accessor order). Vertices
//! no triangle uses are left out.
//!
//! `gltf-json` parses the schema; the accessors are read here with every
//! range checked, because the `gltf` crate's own readers assume a validated
//! document and its validation rejects files that are fine for geometry
//! (a required texture extension, a POSITION accessor without min/max).
//! Node transforms come from the raw JSON, in f64, since `gltf-json` keeps
//! them in f32.

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use base64::Engine;
use glam::{DMat4, DQuat, DVec3};
use gltf::json::accessor::{ComponentType, Type};
use gltf::json::mesh::{Mode, Semantic};
use gltf::json::validation::Checked;
use gltf::json::{self, Value};

use crate::Mesh;

use super::{InputError, check_vertex_count};

/// Extensions whose data this reader cannot decode; a file that requires
/// one gets an error saying so instead of a wrong mesh.
const COMPRESSED_GEOMETRY: &[&str] = &["KHR_draco_mesh_compression", "EXT_meshopt_compression"];

/// Whether a required extension leaves the triangles and their positions
/// as the core specification reads them: quantized positions (which this
/// reader decodes), and extensions of materials, textures, lights and
/// metadata.
fn geometry_neutral(name: &str) -> bool {
    name == "KHR_mesh_quantization"
        || [
            "KHR_materials_",
            "KHR_texture_",
            "EXT_texture_",
            "KHR_lights_",
            "KHR_xmp",
        ]
        .iter()
        .any(|prefix| name.starts_with(prefix))
}

pub(super) fn read(path: &Path, file: &str) -> Result<Mesh, InputError> {
    let bytes = std::fs::read(path).map_err(|e| InputError::io(file, e))?;
    parse(&bytes, path.parent(), file)
}

/// Reads a glTF document from `bytes` (GLB or JSON). External buffers are
/// looked up relative to `base` (none: external buffers are an error).
pub(super) fn parse(bytes: &[u8], base: Option<&Path>, file: &str) -> Result<Mesh, InputError> {
    let (json_bytes, bin) = split_container(bytes, file)?;
    // The version first, from the JSON as it is: a glTF 1.0 document failed
    // the 2.0 schema with a message about a map where a list was expected.
    let raw: Value = json::deserialize::from_slice(json_bytes)
        .map_err(|e| InputError::malformed(file, format!("invalid glTF JSON: {e}")))?;
    if let Some(version) = raw.pointer("/asset/version").and_then(Value::as_str)
        && !version.starts_with("2.")
    {
        return Err(InputError::unsupported(
            file,
            format!("glTF version {version} (2.x is read)"),
        ));
    }
    let root = json::Root::from_slice(json_bytes)
        .map_err(|e| InputError::malformed(file, format!("invalid glTF JSON: {e}")))?;
    if !root.asset.version.starts_with("2.") {
        return Err(InputError::unsupported(
            file,
            format!("glTF version {} (2.x is read)", root.asset.version),
        ));
    }
    for name in &root.extensions_required {
        if COMPRESSED_GEOMETRY.contains(&name.as_str()) {
            return Err(compressed(file, name));
        }
        // A loader must refuse a file that requires an extension it does not
        // know (glTF 2.0, 3.12): one such as EXT_mesh_gpu_instancing changes
        // what the geometry is, and was read as if absent.
        if !geometry_neutral(name) {
            return Err(InputError::unsupported(
                file,
                format!("the file requires the extension {name}, which this reader does not apply"),
            ));
        }
    }
    let mut reader = Reader {
        file,
        root: &root,
        raw: &raw,
        base,
        bin,
        buffers: vec![None; root.buffers.len()],
        mesh: Mesh::default(),
        weld: HashMap::default(),
        non_triangle_primitives: 0,
    };
    for (mesh, world) in reader.instances()? {
        reader.add_mesh(mesh, &world)?;
    }
    if reader.mesh.triangles.is_empty() {
        let why = if reader.non_triangle_primitives > 0 {
            format!(
                "no triangles in the scene ({} point or line primitives skipped)",
                reader.non_triangle_primitives
            )
        } else {
            "no triangles in the scene".to_owned()
        };
        return Err(InputError::malformed(file, why));
    }
    Ok(reader.mesh)
}

/// The JSON text and, for a GLB, its binary chunk.
fn split_container<'a>(
    bytes: &'a [u8],
    file: &str,
) -> Result<(&'a [u8], Option<&'a [u8]>), InputError> {
    if !bytes.starts_with(b"glTF") {
        return Ok((bytes, None));
    }
    // `Glb::from_slice` subtracts the 12-byte header from the declared
    // length without checking it; refuse such a header first.
    let declared = bytes
        .get(8..12)
        .map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
        .unwrap_or(0);
    if declared < 12 {
        return Err(InputError::malformed(
            file,
            format!("GLB header declares {declared} bytes (at least 12 needed)"),
        ));
    }
    let glb = gltf::binary::Glb::from_slice(bytes)
        .map_err(|e| InputError::malformed(file, format!("invalid GLB: {e}")))?;
    // The slices borrow `bytes`; re-derive them so they outlive `glb`.
    let json_len = glb.json.len();
    let json = &bytes[20..20 + json_len];
    let bin = glb.bin.as_ref().map(|b| {
        let start = 20 + json_len + 8;
        &bytes[start..start + b.len()]
    });
    Ok((json, bin))
}

fn compressed(file: &str, extension: &str) -> InputError {
    InputError::unsupported(
        file,
        format!(
            "{extension} (compressed geometry): decompress the file first, e.g. with glTF-Transform"
        ),
    )
}

/// Numbers from a JSON array of exactly `N` numbers.
fn numbers<const N: usize>(value: Option<&Value>) -> Option<[f64; N]> {
    let items = value?.as_array()?;
    if items.len() != N {
        return None;
    }
    let mut out = [0.0; N];
    for (o, v) in out.iter_mut().zip(items) {
        *o = v.as_f64()?;
    }
    Some(out)
}

/// A node's local transform: `matrix` (column-major, as glTF stores it),
/// or translation · rotation · scale.
fn local_transform(node: &Value, index: usize, file: &str) -> Result<DMat4, InputError> {
    let bad =
        |what: &str| InputError::element(file, format!("node {index}"), format!("invalid {what}"));
    if let Some(matrix) = node.get("matrix") {
        let m = numbers::<16>(Some(matrix)).ok_or_else(|| bad("matrix"))?;
        return Ok(DMat4::from_cols_array(&m));
    }
    let t = match node.get("translation") {
        Some(v) => numbers::<3>(Some(v)).ok_or_else(|| bad("translation"))?,
        None => [0.0; 3],
    };
    let q = match node.get("rotation") {
        Some(v) => numbers::<4>(Some(v)).ok_or_else(|| bad("rotation"))?,
        None => [0.0, 0.0, 0.0, 1.0],
    };
    let s = match node.get("scale") {
        Some(v) => numbers::<3>(Some(v)).ok_or_else(|| bad("scale"))?,
        None => [1.0; 3],
    };
    Ok(DMat4::from_scale_rotation_translation(
        DVec3::from_array(s),
        DQuat::from_array(q),
        DVec3::from_array(t),
    ))
}

/// A primitive's triangles as corner indices, in the specification's
/// order for each mode; strips and fans skip the triangles with a repeated
/// index they use as joints, lists keep them for the checker.
fn triangles(mode: Mode, corners: &[u32]) -> Vec<[u32; 3]> {
    let joint = |t: &[u32; 3]| t[0] == t[1] || t[1] == t[2] || t[0] == t[2];
    match mode {
        Mode::Triangles => corners
            .chunks_exact(3)
            .map(|c| [c[0], c[1], c[2]])
            .collect(),
        // {v_i, v_i+(1+i%2), v_i+(2-i%2)}
        Mode::TriangleStrip => corners
            .windows(3)
            .enumerate()
            .map(|(i, c)| {
                if i % 2 == 0 {
                    [c[0], c[1], c[2]]
                } else {
                    [c[0], c[2], c[1]]
                }
            })
            .filter(|t| !joint(t))
            .collect(),
        // {v_i+1, v_i+2, v_0}
        Mode::TriangleFan => corners
            .get(1..)
            .unwrap_or_default()
            .windows(2)
            .map(|c| [c[0], c[1], corners[0]])
            .filter(|t| !joint(t))
            .collect(),
        _ => Vec::new(),
    }
}

struct Reader<'a> {
    file: &'a str,
    root: &'a json::Root,
    raw: &'a Value,
    base: Option<&'a Path>,
    bin: Option<&'a [u8]>,
    /// Buffers, loaded when an accessor first needs them.
    buffers: Vec<Option<Vec<u8>>>,
    mesh: Mesh,
    /// World position (bit patterns, -0 folded into 0) → vertex id.
    /// Welded ids by position bits (foldhash: a file is not a hash-flooding
    /// threat worth SipHash's cost, several times foldhash's on 24-byte keys).
    weld: HashMap<[u64; 3], u32, foldhash::fast::RandomState>,
    non_triangle_primitives: usize,
}

/// An accessor's elements as located in its buffer.
struct Layout {
    component: ComponentType,
    components: usize,
    normalized: bool,
}

impl<'a> Reader<'a> {
    fn element(&self, element: String, message: impl Into<String>) -> InputError {
        InputError::element(self.file, element, message)
    }

    /// Every mesh to place, with its world transform, in scene order.
    fn instances(&self) -> Result<Vec<(usize, DMat4)>, InputError> {
        let root = self.root;
        if root.scenes.is_empty() {
            return Ok((0..root.meshes.len())
                .map(|m| (m, DMat4::IDENTITY))
                .collect());
        }
        let scene_index = root.scene.map_or(0, |s| s.value());
        let scene = root.scenes.get(scene_index).ok_or_else(|| {
            InputError::malformed(
                self.file,
                format!(
                    "scene {scene_index} does not exist ({} scenes)",
                    root.scenes.len()
                ),
            )
        })?;
        let raw_nodes = self.raw.get("nodes").and_then(Value::as_array);
        let mut visited = vec![false; root.nodes.len()];
        let mut out = Vec::new();
        // Depth-first, children in order, so ids follow the document.
        let mut stack: Vec<(usize, DMat4)> = scene
            .nodes
            .iter()
            .rev()
            .map(|n| (n.value(), DMat4::IDENTITY))
            .collect();
        while let Some((index, parent)) = stack.pop() {
            let node = root.nodes.get(index).ok_or_else(|| {
                InputError::malformed(
                    self.file,
                    format!("node {index} does not exist ({} nodes)", root.nodes.len()),
                )
            })?;
            if std::mem::replace(&mut visited[index], true) {
                return Err(self.element(
                    format!("node {index}"),
                    "reached twice: the nodes do not form trees",
                ));
            }
            let raw = raw_nodes.and_then(|n| n.get(index)).unwrap_or(&Value::Null);
            let world = parent * local_transform(raw, index, self.file)?;
            if let Some(mesh) = node.mesh {
                out.push((mesh.value(), world));
            }
            for child in node.children.iter().flatten().rev() {
                stack.push((child.value(), world));
            }
        }
        Ok(out)
    }

    fn add_mesh(&mut self, mesh_index: usize, world: &DMat4) -> Result<(), InputError> {
        let root = self.root;
        let mesh = root.meshes.get(mesh_index).ok_or_else(|| {
            InputError::malformed(
                self.file,
                format!(
                    "mesh {mesh_index} does not exist ({} meshes)",
                    root.meshes.len()
                ),
            )
        })?;
        // Negative for a mirror (an affine matrix: its 3 × 3 part's sign).
        let mirrored = world.determinant() < 0.0;
        for (p, primitive) in mesh.primitives.iter().enumerate() {
            let name = || format!("mesh {mesh_index} primitive {p}");
            let draco = self
                .raw
                .pointer(&format!("/meshes/{mesh_index}/primitives/{p}/extensions"))
                .and_then(|e| e.get(COMPRESSED_GEOMETRY[0]));
            if draco.is_some() {
                return Err(compressed(self.file, COMPRESSED_GEOMETRY[0]));
            }
            let mode = match primitive.mode {
                Checked::Valid(mode) => mode,
                Checked::Invalid => return Err(self.element(name(), "invalid mode")),
            };
            if !matches!(
                mode,
                Mode::Triangles | Mode::TriangleStrip | Mode::TriangleFan
            ) {
                self.non_triangle_primitives += 1;
                continue;
            }
            let position = primitive
                .attributes
                .get(&Checked::Valid(Semantic::Positions))
                .ok_or_else(|| self.element(name(), "no POSITION attribute"))?;
            let local = self.positions(position.value())?;
            let corners = match primitive.indices {
                Some(accessor) => self.indices(accessor.value(), local.len())?,
                None => (0..local.len() as u32).collect(),
            };
            let triangles = triangles(mode, &corners);
            let ids = self.weld(&local, &triangles, world)?;
            self.mesh.triangles.extend(triangles.iter().map(|t| {
                let t = t.map(|c| ids[c as usize]);
                if mirrored { [t[0], t[2], t[1]] } else { t }
            }));
        }
        Ok(())
    }

    /// Maps each vertex the triangles use to a welded id, adding new ones
    /// in accessor order; vertices no triangle uses (a buffer shared by
    /// primitives that each index part of it) are left out.
    fn weld(
        &mut self,
        local: &[[f64; 3]],
        triangles: &[[u32; 3]],
        world: &DMat4,
    ) -> Result<Vec<u32>, InputError> {
        const UNUSED: u32 = u32::MAX;
        let mut ids = vec![UNUSED; local.len()];
        for &c in triangles.iter().flatten() {
            ids[c as usize] = 0;
        }
        self.weld.reserve(local.len());
        for (id, &p) in ids.iter_mut().zip(local) {
            if *id == UNUSED {
                continue;
            }
            let q = world.transform_point3(DVec3::from_array(p)).to_array();
            // +0.0 folds -0.0 into 0.0, so both weld.
            let key = q.map(|c| (c + 0.0).to_bits());
            let next = self.mesh.positions.len();
            *id = *self.weld.entry(key).or_insert_with(|| {
                self.mesh.positions.push(q);
                next as u32
            });
            check_vertex_count(self.file, self.mesh.positions.len() as u64)?;
        }
        Ok(ids)
    }

    /// A POSITION accessor's values: float, or integers (normalized or not)
    /// under KHR_mesh_quantization.
    fn positions(&mut self, index: usize) -> Result<Vec<[f64; 3]>, InputError> {
        let (layout, values) = self.accessor(index)?;
        let name = format!("accessor {index}");
        if layout.components != 3 {
            return Err(self.element(name, "POSITION must be VEC3"));
        }
        if layout.component == ComponentType::U32 {
            return Err(self.element(name, "POSITION cannot be UNSIGNED_INT"));
        }
        let scale = match (layout.normalized, layout.component) {
            (false, _) | (_, ComponentType::F32) => 1.0,
            (true, ComponentType::I8) => 1.0 / 127.0,
            (true, ComponentType::U8) => 1.0 / 255.0,
            (true, ComponentType::I16) => 1.0 / 32767.0,
            (true, _) => 1.0 / 65535.0,
        };
        let signed_normalized =
            layout.normalized && matches!(layout.component, ComponentType::I8 | ComponentType::I16);
        let convert = |x: f64| {
            let x = x * scale;
            // The specification's max(c / 127.0, -1.0).
            if signed_normalized { x.max(-1.0) } else { x }
        };
        let out: Vec<[f64; 3]> = values
            .chunks_exact(3)
            .map(|c| [convert(c[0]), convert(c[1]), convert(c[2])])
            .collect();
        if let Some(i) = out.iter().position(|p| p.iter().any(|c| !c.is_finite())) {
            return Err(self.element(
                format!("accessor {index} element {i}"),
                "not a finite number",
            ));
        }
        Ok(out)
    }

    /// An index accessor's values, each checked against the vertex count.
    fn indices(&mut self, index: usize, vertices: usize) -> Result<Vec<u32>, InputError> {
        let (layout, values) = self.accessor(index)?;
        let name = format!("accessor {index}");
        if layout.components != 1
            || layout.normalized
            || !matches!(
                layout.component,
                ComponentType::U8 | ComponentType::U16 | ComponentType::U32
            )
        {
            return Err(self.element(
                name,
                "indices must be SCALAR UNSIGNED_BYTE, UNSIGNED_SHORT or UNSIGNED_INT",
            ));
        }
        let mut out = Vec::with_capacity(values.len());
        for (i, &v) in values.iter().enumerate() {
            if v >= vertices as f64 {
                return Err(self.element(
                    format!("accessor {index} element {i}"),
                    format!(
                        "vertex index {v} out of range (the primitive has {vertices} vertices)"
                    ),
                ));
            }
            out.push(v as u32);
        }
        Ok(out)
    }

    /// An accessor's components as f64 (exact for every glTF component
    /// type), with its sparse substitutions applied.
    fn accessor(&mut self, index: usize) -> Result<(Layout, Vec<f64>), InputError> {
        let name = format!("accessor {index}");
        let accessor =
            self.root.accessors.get(index).ok_or_else(|| {
                InputError::malformed(self.file, format!("{name} does not exist"))
            })?;
        let component = match accessor.component_type {
            Checked::Valid(c) => c.0,
            Checked::Invalid => return Err(self.element(name, "invalid componentType")),
        };
        let components = match accessor.type_ {
            Checked::Valid(Type::Scalar) => 1,
            Checked::Valid(Type::Vec2) => 2,
            Checked::Valid(Type::Vec3) => 3,
            Checked::Valid(Type::Vec4) => 4,
            _ => return Err(self.element(name, "not a SCALAR or VECn accessor")),
        };
        let count = usize::try_from(accessor.count.0)
            .map_err(|_| self.element(name.clone(), "count too large"))?;
        let layout = Layout {
            component,
            components,
            normalized: accessor.normalized,
        };
        let mut values = match accessor.buffer_view {
            Some(view) => self.read_elements(
                &name,
                view.value(),
                accessor.byte_offset.map_or(0, |o| o.0),
                count,
                component,
                components,
            )?,
            // Sparse values over zeros: nothing bounds the count but the
            // memory, so ask for it rather than abort.
            None if accessor.sparse.is_some() => {
                let mut zeros = Vec::new();
                count
                    .checked_mul(components)
                    .filter(|&n| zeros.try_reserve_exact(n).is_ok())
                    .map(|n| zeros.resize(n, 0.0))
                    .ok_or_else(|| {
                        self.element(name.clone(), format!("count {count} is too large"))
                    })?;
                zeros
            }
            None => return Err(self.element(name, "has neither bufferView nor sparse data")),
        };
        if let Some(sparse) = &accessor.sparse {
            let n = usize::try_from(sparse.count.0)
                .map_err(|_| self.element(name.clone(), "sparse count too large"))?;
            let index_type = match sparse.indices.component_type {
                Checked::Valid(c) => c.0,
                Checked::Invalid => {
                    return Err(self.element(name, "invalid sparse index componentType"));
                }
            };
            let at = self.read_elements(
                &name,
                sparse.indices.buffer_view.value(),
                sparse.indices.byte_offset.0,
                n,
                index_type,
                1,
            )?;
            let new = self.read_elements(
                &name,
                sparse.values.buffer_view.value(),
                sparse.values.byte_offset.0,
                n,
                component,
                components,
            )?;
            for (k, &i) in at.iter().enumerate() {
                let i = i as usize;
                if i >= count {
                    return Err(self.element(
                        name,
                        format!("sparse index {i} out of range (count {count})"),
                    ));
                }
                values[i * components..(i + 1) * components]
                    .copy_from_slice(&new[k * components..(k + 1) * components]);
            }
        }
        Ok((layout, values))
    }

    /// `count` elements of `components` values each from a buffer view,
    /// every byte range checked before it is read.
    fn read_elements(
        &mut self,
        name: &str,
        view_index: usize,
        offset: u64,
        count: usize,
        component: ComponentType,
        components: usize,
    ) -> Result<Vec<f64>, InputError> {
        let view = self.root.buffer_views.get(view_index).ok_or_else(|| {
            InputError::malformed(
                self.file,
                format!("{name}: bufferView {view_index} does not exist"),
            )
        })?;
        let size = component_size(component);
        let element = size * components as u64;
        let stride = view.byte_stride.map_or(element, |s| s.0 as u64);
        if stride < element {
            return Err(self.element(
                format!("bufferView {view_index}"),
                format!("byteStride {stride} is smaller than {name}'s {element}-byte elements"),
            ));
        }
        let view_start = view.byte_offset.map_or(0, |o| o.0);
        let view_length = view.byte_length.0;
        let needed = match count {
            0 => Some(offset),
            _ => (count as u64 - 1)
                .checked_mul(stride)
                .and_then(|b| b.checked_add(element))
                .and_then(|b| b.checked_add(offset)),
        };
        if needed.is_none_or(|n| n > view_length) {
            return Err(self.element(
                name.to_owned(),
                format!("{count} elements from byte {offset} overrun bufferView {view_index} ({view_length} bytes)"),
            ));
        }
        let buffer = view.buffer.value();
        let file = self.file;
        let data = self.buffer(buffer)?;
        let end = view_start.checked_add(view_length);
        let Some(bytes) = end.and_then(|end| data.get(view_start as usize..end as usize)) else {
            return Err(InputError::element(
                file,
                format!("bufferView {view_index}"),
                format!(
                    "bytes {view_start}..+{view_length} overrun buffer {buffer} ({} bytes)",
                    data.len()
                ),
            ));
        };
        let bytes = &bytes[offset as usize..];
        let mut out = Vec::with_capacity(count * components);
        for e in 0..count {
            let at = e * stride as usize;
            for c in 0..components {
                let b = &bytes[at + c * size as usize..];
                out.push(match component {
                    ComponentType::I8 => b[0] as i8 as f64,
                    ComponentType::U8 => b[0] as f64,
                    ComponentType::I16 => i16::from_le_bytes([b[0], b[1]]) as f64,
                    ComponentType::U16 => u16::from_le_bytes([b[0], b[1]]) as f64,
                    ComponentType::U32 => u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f64,
                    ComponentType::F32 => f32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f64,
                });
            }
        }
        Ok(out)
    }

    /// Buffer `index`'s bytes (at most its byteLength), loaded once.
    fn buffer(&mut self, index: usize) -> Result<&[u8], InputError> {
        let name = format!("buffer {index}");
        let buffer =
            self.root.buffers.get(index).ok_or_else(|| {
                InputError::malformed(self.file, format!("{name} does not exist"))
            })?;
        if self.buffers[index].is_none() {
            let data = match (&buffer.uri, self.bin) {
                (Some(uri), _) => self.load_uri(&name, uri)?,
                (None, Some(bin)) if index == 0 => bin.to_vec(),
                (None, _) => {
                    return Err(self.element(name, "has no uri and is not the GLB's binary chunk"));
                }
            };
            let length = buffer.byte_length.0;
            if (data.len() as u64) < length {
                return Err(self.element(
                    name,
                    format!("holds {} bytes, byteLength says {length}", data.len()),
                ));
            }
            self.buffers[index] = Some(data[..length as usize].to_vec());
        }
        Ok(self.buffers[index].as_deref().unwrap_or_default())
    }

    fn load_uri(&self, name: &str, uri: &str) -> Result<Vec<u8>, InputError> {
        if let Some(rest) = uri.strip_prefix("data:") {
            let Some((kind, payload)) = rest.split_once(',') else {
                return Err(self.element(name.to_owned(), "malformed data URI"));
            };
            if !kind.ends_with(";base64") {
                return Err(self.element(name.to_owned(), "data URI is not base64"));
            }
            return base64::engine::general_purpose::STANDARD
                .decode(payload)
                .map_err(|e| self.element(name.to_owned(), format!("data URI: {e}")));
        }
        if uri.contains("://") {
            return Err(self.element(
                name.to_owned(),
                format!("remote uri '{uri}' is not fetched"),
            ));
        }
        let Some(base) = self.base else {
            return Err(self.element(
                name.to_owned(),
                format!("external uri '{uri}' without a directory"),
            ));
        };
        let relative: PathBuf = percent_encoding::percent_decode_str(uri)
            .decode_utf8_lossy()
            .into_owned()
            .into();
        let path = base.join(relative);
        std::fs::read(&path).map_err(|e| {
            self.element(
                name.to_owned(),
                format!("cannot read '{}': {e}", path.display()),
            )
        })
    }
}

fn component_size(component: ComponentType) -> u64 {
    match component {
        ComponentType::I8 | ComponentType::U8 => 1,
        ComponentType::I16 | ComponentType::U16 => 2,
        ComponentType::U32 | ComponentType::F32 => 4,
    }
}

#[cfg(test)]
mod tests {
    use super::super::test_util::TempFile;
    use super::super::{ReadOptions, check_mesh, read_mesh};
    use super::*;
    use serde_json::json;

    /// Little-endian bytes of f32 positions.
    fn f32_bytes(values: &[f32]) -> Vec<u8> {
        values.iter().flat_map(|v| v.to_le_bytes()).collect()
    }

    fn data_uri(bytes: &[u8]) -> String {
        format!(
            "data:application/octet-stream;base64,{}",
            base64::engine::general_purpose::STANDARD.encode(bytes)
        )
    }

    /// A unit square in z = 0 (two triangles) as f32 positions.
    const SQUARE: [f32; 12] = [0., 0., 0., 1., 0., 0., 1., 1., 0., 0., 1., 0.];

    /// A document with one buffer (embedded) whose first view holds
    /// `positions` and second `indices` (if any); `extra` is merged into
    /// the root, `primitive` into the primitive.
    fn document(positions: &[u8], indices: Option<(&[u8], u32)>, extra: Value) -> Value {
        let mut bin = positions.to_vec();
        let mut views = vec![json!({"buffer": 0, "byteLength": positions.len()})];
        let mut accessors = vec![json!({
            "bufferView": 0, "componentType": 5126, "count": positions.len() / 12, "type": "VEC3"
        })];
        let mut primitive = json!({"attributes": {"POSITION": 0}});
        if let Some((bytes, component)) = indices {
            let size = match component {
                5121 => 1,
                5123 => 2,
                _ => 4,
            };
            views.push(json!({"buffer": 0, "byteOffset": bin.len(), "byteLength": bytes.len()}));
            accessors.push(json!({
                "bufferView": 1, "componentType": component, "count": bytes.len() / size,
                "type": "SCALAR"
            }));
            primitive["indices"] = json!(1);
            bin.extend_from_slice(bytes);
        }
        let mut doc = json!({
            "asset": {"version": "2.0"},
            "buffers": [{"byteLength": bin.len(), "uri": data_uri(&bin)}],
            "bufferViews": views,
            "accessors": accessors,
            "meshes": [{"primitives": [primitive]}],
            "scenes": [{"nodes": [0]}],
            "nodes": [{"mesh": 0}],
        });
        merge(&mut doc, extra);
        doc
    }

    /// Recursively merges objects and arrays (element by element); other
    /// values replace.
    fn merge(into: &mut Value, from: Value) {
        match (into, from) {
            (Value::Object(a), Value::Object(b)) => {
                for (k, v) in b {
                    merge(a.entry(k).or_insert(Value::Null), v);
                }
            }
            (Value::Array(a), Value::Array(b)) => {
                for (i, v) in b.into_iter().enumerate() {
                    match a.get_mut(i) {
                        Some(slot) => merge(slot, v),
                        None => a.push(v),
                    }
                }
            }
            (a, b) => *a = b,
        }
    }

    fn read_doc(doc: &Value) -> Result<Mesh, InputError> {
        parse(doc.to_string().as_bytes(), None, "t.gltf")
    }

    fn square_indexed(extra: Value) -> Value {
        let indices: Vec<u8> = [0u16, 1, 2, 0, 2, 3]
            .iter()
            .flat_map(|i| i.to_le_bytes())
            .collect();
        document(&f32_bytes(&SQUARE), Some((&indices, 5123)), extra)
    }

    #[test]
    fn indexed_triangles_of_every_index_width() {
        for (component, size) in [(5121u32, 1usize), (5123, 2), (5125, 4)] {
            let indices: Vec<u8> = [0u32, 1, 2, 0, 2, 3]
                .iter()
                .flat_map(|i| i.to_le_bytes()[..size].to_vec())
                .collect();
            let doc = document(&f32_bytes(&SQUARE), Some((&indices, component)), json!({}));
            let m = read_doc(&doc).unwrap();
            assert_eq!(m.positions.len(), 4);
            assert_eq!(m.triangles, vec![[0, 1, 2], [0, 2, 3]]);
            check_mesh(&m).unwrap();
        }
    }

    #[test]
    fn vertices_no_triangle_uses_are_left_out() {
        // Two primitives share one POSITION accessor of six vertices and
        // index a triangle each; vertices 1 and 4 are used by neither.
        let positions = [
            0., 0., 0., 9., 9., 9., 1., 0., 0., 1., 1., 0., 8., 8., 8., 0., 1., 0.,
        ];
        let indices: Vec<u8> = vec![0, 2, 3, 0, 3, 5];
        let mut doc = document(&f32_bytes(&positions), Some((&indices, 5121)), json!({}));
        doc["bufferViews"][1]["byteLength"] = json!(3);
        doc["bufferViews"].as_array_mut().unwrap().push(json!(
            {"buffer": 0, "byteOffset": 72 + 3, "byteLength": 3}
        ));
        doc["accessors"][1]["count"] = json!(3);
        doc["accessors"].as_array_mut().unwrap().push(json!(
            {"bufferView": 2, "componentType": 5121, "count": 3, "type": "SCALAR"}
        ));
        doc["meshes"][0]["primitives"]
            .as_array_mut()
            .unwrap()
            .push(json!({"attributes": {"POSITION": 0}, "indices": 2}));
        let m = read_doc(&doc).unwrap();
        assert_eq!(
            m.positions,
            vec![[0., 0., 0.], [1., 0., 0.], [1., 1., 0.], [0., 1., 0.]]
        );
        assert_eq!(m.triangles, vec![[0, 1, 2], [0, 2, 3]]);
        check_mesh(&m).unwrap();
    }

    #[test]
    fn unindexed_corners_weld_into_shared_vertices() {
        // Two triangles with a vertex of their own per corner, and -0.0
        // against 0.0: one welded square.
        let corners = [
            0., 0., 0., 1., 0., 0., 1., 1., 0., -0., 0., 0., 1., 1., 0., 0., 1., -0.,
        ];
        let m = read_doc(&document(&f32_bytes(&corners), None, json!({}))).unwrap();
        assert_eq!(m.positions.len(), 4);
        assert_eq!(m.triangles, vec![[0, 1, 2], [0, 2, 3]]);
    }

    #[test]
    fn strips_and_fans_follow_the_specification_and_skip_joints() {
        // Strip 0 1 3 2 over the square: (0,1,3) and (1,2,3) after the odd
        // triangle's swap, both counter-clockwise.
        let strip: Vec<u8> = [0u8, 1, 3, 2].to_vec();
        let mut doc = document(&f32_bytes(&SQUARE), Some((&strip, 5121)), json!({}));
        doc["meshes"][0]["primitives"][0]["mode"] = json!(5);
        let m = read_doc(&doc).unwrap();
        assert_eq!(m.triangles, vec![[0, 1, 3], [1, 2, 3]]);
        check_mesh(&m).unwrap();
        // A repeated index is a joint, not a triangle.
        let joint: Vec<u8> = [0u8, 1, 3, 3, 2].to_vec();
        let mut doc = document(&f32_bytes(&SQUARE), Some((&joint, 5121)), json!({}));
        doc["meshes"][0]["primitives"][0]["mode"] = json!(5);
        assert_eq!(read_doc(&doc).unwrap().triangles.len(), 1);
        // Fan 0 1 2 3: (1,2,0) and (2,3,0).
        let fan: Vec<u8> = [0u8, 1, 2, 3].to_vec();
        let mut doc = document(&f32_bytes(&SQUARE), Some((&fan, 5121)), json!({}));
        doc["meshes"][0]["primitives"][0]["mode"] = json!(6);
        assert_eq!(
            read_doc(&doc).unwrap().triangles,
            vec![[1, 2, 0], [2, 3, 0]]
        );
    }

    #[test]
    fn node_transforms_compose_in_f64_and_mirrors_flip_the_winding() {
        // Parent: a translation f32 cannot hold; child: a quarter turn about
        // z and a scale of 2, as translation/rotation/scale.
        let s = std::f64::consts::FRAC_1_SQRT_2;
        let doc = square_indexed(json!({
            "scenes": [{"nodes": [1]}],
            "nodes": [
                {"mesh": 0, "rotation": [0, 0, s, s], "scale": [2, 2, 2]},
                {"translation": [500000.123456, 4000000.5, -0.25], "children": [0]}
            ]
        }));
        let m = read_doc(&doc).unwrap();
        let expected = [[0., 0.], [0., 2.], [-2., 2.], [-2., 0.]];
        for (p, e) in m.positions.iter().zip(expected) {
            assert!((p[0] - (500000.123456 + e[0])).abs() < 1e-9, "{p:?}");
            assert!((p[1] - (4000000.5 + e[1])).abs() < 1e-9, "{p:?}");
            assert_eq!(p[2], -0.25);
        }
        assert_eq!(m.triangles, vec![[0, 1, 2], [0, 2, 3]]);
        // A mirror (column-major matrix, x negated) reverses the winding,
        // so the surface still faces out.
        let doc = square_indexed(json!({"nodes": [{"mesh": 0, "matrix":
            [-1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 10, 0, 0, 1]}]}));
        let m = read_doc(&doc).unwrap();
        assert_eq!(m.positions[1], [9.0, 0.0, 0.0]);
        assert_eq!(m.triangles, vec![[0, 2, 1], [0, 3, 2]]);
    }

    #[test]
    fn instances_and_scenes() {
        // The mesh placed twice: two squares; without scenes: once, as is.
        let doc = square_indexed(json!({
            "scenes": [{"nodes": [0, 1]}],
            "nodes": [{"mesh": 0}, {"mesh": 0, "translation": [5, 0, 0]}]
        }));
        let m = read_doc(&doc).unwrap();
        assert_eq!((m.positions.len(), m.triangles.len()), (8, 4));
        assert_eq!(m.positions[4], [5.0, 0.0, 0.0]);
        let mut doc = square_indexed(json!({}));
        doc.as_object_mut().unwrap().remove("scenes");
        doc.as_object_mut().unwrap().remove("nodes");
        assert_eq!(read_doc(&doc).unwrap().triangles.len(), 2);
        // `scene` picks the scene: scene 1 is empty.
        let doc = square_indexed(json!({"scene": 1, "scenes": [{"nodes": [0]}, {"nodes": []}]}));
        let err = read_doc(&doc).unwrap_err().to_string();
        assert_eq!(err, "t.gltf: no triangles in the scene");
    }

    #[test]
    fn quantized_interleaved_and_sparse_positions() {
        // KHR_mesh_quantization: normalized i16 positions, interleaved with
        // 2 bytes of padding (stride 8).
        let mut bin = Vec::new();
        for p in [
            [0i16, 0, 0],
            [32767, 0, 0],
            [32767, 32767, 0],
            [0, -32768, 0],
        ] {
            for c in p {
                bin.extend_from_slice(&c.to_le_bytes());
            }
            bin.extend_from_slice(&[0xAA, 0xAA]);
        }
        let mut doc = square_indexed(json!({"extensionsRequired": ["KHR_mesh_quantization"]}));
        let indices = [0u8, 1, 2, 0, 2, 3];
        bin.extend_from_slice(&indices);
        doc["buffers"] = json!([{"byteLength": bin.len(), "uri": data_uri(&bin)}]);
        doc["bufferViews"] = json!([
            {"buffer": 0, "byteLength": 32, "byteStride": 8},
            {"buffer": 0, "byteOffset": 32, "byteLength": 6}
        ]);
        doc["accessors"] = json!([
            {"bufferView": 0, "componentType": 5122, "normalized": true, "count": 4, "type": "VEC3"},
            {"bufferView": 1, "componentType": 5121, "count": 6, "type": "SCALAR"}
        ]);
        let m = read_doc(&doc).unwrap();
        assert_eq!(
            m.positions,
            vec![[0., 0., 0.], [1., 0., 0.], [1., 1., 0.], [0., -1., 0.]]
        );
        // Sparse: vertex 3 of the float square replaced by (0, 2, 0).
        let mut bin = f32_bytes(&SQUARE);
        bin.extend_from_slice(&[0, 1, 2, 0, 2, 3]);
        bin.extend_from_slice(&[3, 0, 0, 0]); // the sparse index (u8, padded)
        bin.extend_from_slice(&f32_bytes(&[0., 2., 0.]));
        let mut doc = square_indexed(json!({}));
        doc["buffers"] = json!([{"byteLength": bin.len(), "uri": data_uri(&bin)}]);
        doc["bufferViews"] = json!([
            {"buffer": 0, "byteLength": 48},
            {"buffer": 0, "byteOffset": 48, "byteLength": 6},
            {"buffer": 0, "byteOffset": 54, "byteLength": 1},
            {"buffer": 0, "byteOffset": 58, "byteLength": 12}
        ]);
        doc["accessors"] = json!([
            {"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3",
             "sparse": {"count": 1, "indices": {"bufferView": 2, "componentType": 5121},
                        "values": {"bufferView": 3}}},
            {"bufferView": 1, "componentType": 5121, "count": 6, "type": "SCALAR"}
        ]);
        assert_eq!(read_doc(&doc).unwrap().positions[3], [0., 2., 0.]);
    }

    /// The square as a GLB whose binary chunk `bin` holds its f32 positions
    /// then its u8 indices; returns the JSON document too.
    fn square_glb(bin: &[u8]) -> (Value, Vec<u8>) {
        let mut doc = square_indexed(json!({}));
        doc["bufferViews"] = json!([
            {"buffer": 0, "byteLength": 48}, {"buffer": 0, "byteOffset": 48, "byteLength": 6}
        ]);
        doc["accessors"][1]["componentType"] = json!(5121);
        doc["buffers"] = json!([{"byteLength": bin.len()}]);
        let glb = gltf::binary::Glb {
            header: gltf::binary::Header {
                magic: *b"glTF",
                version: 2,
                length: 0,
            },
            json: doc.to_string().into_bytes().into(),
            bin: Some(bin.to_vec().into()),
        }
        .to_vec()
        .unwrap();
        (doc, glb)
    }

    #[test]
    fn glb_and_external_buffers() {
        // The same square as GLB (buffer 0 = the binary chunk) and as JSON
        // with an external, percent-encoded file name.
        let mut bin = f32_bytes(&SQUARE);
        bin.extend_from_slice(&[0, 1, 2, 0, 2, 3]);
        let (mut doc, glb) = square_glb(&bin);
        let f = TempFile::new("square.glb", &glb);
        let m = read_mesh(&f.0, &ReadOptions::default()).unwrap();
        assert_eq!(m.triangles, vec![[0, 1, 2], [0, 2, 3]]);
        let b = TempFile::new("sq data.bin", &bin);
        let name =
            b.0.file_name()
                .unwrap()
                .to_string_lossy()
                .replace(' ', "%20");
        doc["buffers"] = json!([{"byteLength": bin.len(), "uri": name}]);
        let f = TempFile::new("square.gltf", doc.to_string().as_bytes());
        let m = read_mesh(&f.0, &ReadOptions::default()).unwrap();
        assert_eq!(m.triangles, vec![[0, 1, 2], [0, 2, 3]]);
        drop(b);
        let err = read_mesh(&f.0, &ReadOptions::default())
            .unwrap_err()
            .to_string();
        assert!(err.contains("buffer 0: cannot read"), "{err}");
    }

    #[test]
    fn bad_documents_get_one_line_naming_the_problem() {
        let cases: Vec<(Value, &str)> = vec![
            (
                square_indexed(json!({"extensionsRequired": ["KHR_draco_mesh_compression"]})),
                "unsupported: KHR_draco_mesh_compression (compressed geometry)",
            ),
            (
                square_indexed(json!({"asset": {"version": "1.0"}})),
                "unsupported: glTF version 1.0",
            ),
            (
                // A 1.0 document's own layout (meshes as a map) is named
                // by its version, not by the 2.0 schema's complaint.
                json!({"asset": {"version": "1.0"}, "meshes": {}}),
                "unsupported: glTF version 1.0",
            ),
            (
                square_indexed(json!({"extensionsRequired": ["EXT_mesh_gpu_instancing"]})),
                "unsupported: the file requires the extension EXT_mesh_gpu_instancing",
            ),
            (
                square_indexed(
                    json!({"meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "mode": 0}]}]}),
                ),
                "no triangles in the scene (1 point or line primitives skipped)",
            ),
            (
                square_indexed(json!({"accessors": [{}, {"count": 7}]})),
                "accessor 1: 7 elements from byte 0 overrun bufferView 1 (12 bytes)",
            ),
            (
                square_indexed(json!({"accessors": [{"type": "VEC2"}]})),
                "accessor 0: POSITION must be VEC3",
            ),
            (
                square_indexed(json!({"buffers": [{"byteLength": 1000}]})),
                "buffer 0: holds 60 bytes, byteLength says 1000",
            ),
            (
                square_indexed(json!({"bufferViews": [{"byteLength": 48, "byteOffset": 40}]})),
                "bufferView 0: bytes 40..+48 overrun buffer 0 (60 bytes)",
            ),
            (
                square_indexed(json!({"nodes": [{"mesh": 0, "children": [0]}]})),
                "node 0: reached twice: the nodes do not form trees",
            ),
            (
                square_indexed(json!({"nodes": [{"mesh": 3}]})),
                "mesh 3 does not exist",
            ),
            (
                square_indexed(json!({"nodes": [{"mesh": 0, "translation": [1, 2]}]})),
                "invalid glTF JSON: invalid length 2, expected an array of length 3",
            ),
            (
                square_indexed(json!({"buffers": [{"uri": "data:text/plain,abc"}]})),
                "buffer 0: data URI is not base64",
            ),
            (
                square_indexed(
                    json!({"accessors": [{"bufferView": null, "count": 4_000_000_000_000_000u64,
                    "sparse": {"count": 1, "indices": {"bufferView": 1, "componentType": 5123},
                               "values": {"bufferView": 0}}}]}),
                ),
                "accessor 0: count 4000000000000000 is too large",
            ),
            (
                square_indexed(json!({"buffers": [{"uri": "https://example.com/a.bin"}]})),
                "remote uri 'https://example.com/a.bin' is not fetched",
            ),
        ];
        for (doc, expected) in cases {
            let err = read_doc(&doc).unwrap_err().to_string();
            assert!(
                err.starts_with("t.gltf: ") && err.contains(expected),
                "{err}\n  expected: {expected}"
            );
            assert!(!err.contains('\n'));
        }
        // An index past the vertices.
        let indices: Vec<u8> = [0u16, 1, 4].iter().flat_map(|i| i.to_le_bytes()).collect();
        let doc = document(&f32_bytes(&SQUARE), Some((&indices, 5123)), json!({}));
        let err = read_doc(&doc).unwrap_err().to_string();
        assert!(
            err.contains("accessor 1 element 2: vertex index 4 out of range"),
            "{err}"
        );
        // A Draco primitive without the extension listed as required.
        let mut doc = square_indexed(json!({}));
        doc["meshes"][0]["primitives"][0]["extensions"] =
            json!({"KHR_draco_mesh_compression": {"bufferView": 0, "attributes": {}}});
        assert!(
            read_doc(&doc)
                .unwrap_err()
                .to_string()
                .contains("KHR_draco")
        );
        // NaN cannot be written in JSON, but it can in a buffer.
        let mut positions = SQUARE;
        positions[4] = f32::NAN;
        let doc = document(&f32_bytes(&positions), None, json!({}));
        let err = read_doc(&doc).unwrap_err().to_string();
        assert!(
            err.contains("accessor 0 element 1: not a finite number"),
            "{err}"
        );
    }

    #[test]
    fn truncated_and_mutated_glb_never_panic() {
        let mut bin = f32_bytes(&SQUARE);
        bin.extend_from_slice(&[0, 1, 2, 0, 2, 3, 0, 0]);
        let (_, glb) = square_glb(&bin);
        assert!(parse(&glb, None, "m.glb").is_ok());
        for cut in 0..glb.len() {
            let _ = parse(&glb[..cut], None, "m.glb");
        }
        // Every byte set to a few values: the header, the chunk lengths,
        // the JSON digits and the binary data all take bad values.
        for at in 0..glb.len() {
            for value in [0u8, 0x01, 0x7F, 0xFF, b'9'] {
                let mut bad = glb.clone();
                bad[at] = value;
                let _ = parse(&bad, None, "m.glb");
            }
        }
        let mut header = glb.clone();
        header[8..12].copy_from_slice(&3u32.to_le_bytes());
        let err = parse(&header, None, "m.glb").unwrap_err().to_string();
        assert_eq!(
            err,
            "m.glb: GLB header declares 3 bytes (at least 12 needed)"
        );
    }
}
