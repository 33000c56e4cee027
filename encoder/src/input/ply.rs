//! PLY reader (ascii, binary little and big endian) on top of `ply-rs-bw`.
//!
//! One element type serves every PLY element so that unknown elements
//! (edges, materials) are parsed and ignored instead of rejected; only the
//! `vertex` x/y/z (any numeric type) and the `face` `vertex_indices` or
//! `vertex_index` list are kept. Polygons are fan-triangulated.

use std::fs::File;
use std::io::{BufRead, BufReader};
use std::path::Path;

use ply_rs_bw::parser::{ParseError, Parser, Reader};
use ply_rs_bw::ply::{
    BeginList, Encoding, Property, PropertyAccess, PropertyAccessResult, PropertyType,
};

use crate::Mesh;

use super::ply_ascii::AsciiPayload;
use super::{InputError, Polygons, check_vertex_count, push_polygon};

/// Whatever a PLY element carries that we care about.
#[derive(Default)]
struct Element {
    xyz: [f64; 3],
    indices_i32: Vec<i32>,
    indices_u32: Vec<u32>,
    /// Index lists stored with other integer types, widened.
    indices_other: Vec<i64>,
}

fn is_index_list(name: &str) -> bool {
    name == "vertex_indices" || name == "vertex_index"
}

impl Element {
    fn set_coord(&mut self, name: &str, value: f64) -> PropertyAccessResult {
        let k = match name {
            "x" => 0,
            "y" => 1,
            "z" => 2,
            _ => return PropertyAccessResult::Ignored,
        };
        self.xyz[k] = value;
        PropertyAccessResult::Set
    }

    fn set_other_list(
        &mut self,
        name: &str,
        values: impl Iterator<Item = i64>,
    ) -> PropertyAccessResult {
        if !is_index_list(name) {
            return PropertyAccessResult::Ignored;
        }
        self.indices_other = values.collect();
        PropertyAccessResult::Set
    }

    fn indices(&self) -> impl Iterator<Item = i64> + '_ {
        self.indices_i32
            .iter()
            .map(|&i| i as i64)
            .chain(self.indices_u32.iter().map(|&i| i as i64))
            .chain(self.indices_other.iter().copied())
    }
}

impl PropertyAccess for Element {
    fn new() -> Self {
        Element::default()
    }
    fn set_char(&mut self, name: &str, v: i8) -> PropertyAccessResult {
        self.set_coord(name, v as f64)
    }
    fn set_uchar(&mut self, name: &str, v: u8) -> PropertyAccessResult {
        self.set_coord(name, v as f64)
    }
    fn set_short(&mut self, name: &str, v: i16) -> PropertyAccessResult {
        self.set_coord(name, v as f64)
    }
    fn set_ushort(&mut self, name: &str, v: u16) -> PropertyAccessResult {
        self.set_coord(name, v as f64)
    }
    fn set_int(&mut self, name: &str, v: i32) -> PropertyAccessResult {
        self.set_coord(name, v as f64)
    }
    fn set_uint(&mut self, name: &str, v: u32) -> PropertyAccessResult {
        self.set_coord(name, v as f64)
    }
    fn set_float(&mut self, name: &str, v: f32) -> PropertyAccessResult {
        self.set_coord(name, v as f64)
    }
    fn set_double(&mut self, name: &str, v: f64) -> PropertyAccessResult {
        self.set_coord(name, v)
    }
    fn set_property(&mut self, _name: &str, _p: Property) -> PropertyAccessResult {
        PropertyAccessResult::Ignored
    }
    fn begin_list_int(&mut self, name: &str, _len: usize) -> BeginList<'_, i32> {
        if is_index_list(name) {
            BeginList::Fill(&mut self.indices_i32)
        } else {
            BeginList::UseSetter
        }
    }
    fn begin_list_uint(&mut self, name: &str, _len: usize) -> BeginList<'_, u32> {
        if is_index_list(name) {
            BeginList::Fill(&mut self.indices_u32)
        } else {
            BeginList::UseSetter
        }
    }
    fn set_list_char(&mut self, name: &str, v: Vec<i8>) -> PropertyAccessResult {
        self.set_other_list(name, v.into_iter().map(i64::from))
    }
    fn set_list_uchar(&mut self, name: &str, v: Vec<u8>) -> PropertyAccessResult {
        self.set_other_list(name, v.into_iter().map(i64::from))
    }
    fn set_list_short(&mut self, name: &str, v: Vec<i16>) -> PropertyAccessResult {
        self.set_other_list(name, v.into_iter().map(i64::from))
    }
    fn set_list_ushort(&mut self, name: &str, v: Vec<u16>) -> PropertyAccessResult {
        self.set_other_list(name, v.into_iter().map(i64::from))
    }
    fn set_list_int(&mut self, name: &str, v: Vec<i32>) -> PropertyAccessResult {
        self.set_other_list(name, v.into_iter().map(i64::from))
    }
    fn set_list_uint(&mut self, name: &str, v: Vec<u32>) -> PropertyAccessResult {
        self.set_other_list(name, v.into_iter().map(i64::from))
    }
    fn set_list_float(&mut self, _name: &str, _v: Vec<f32>) -> PropertyAccessResult {
        PropertyAccessResult::Ignored
    }
    fn set_list_double(&mut self, _name: &str, _v: Vec<f64>) -> PropertyAccessResult {
        PropertyAccessResult::Ignored
    }
}

pub(super) fn read(path: &Path, file: &str) -> Result<Mesh, InputError> {
    let f = File::open(path).map_err(|e| InputError::io(file, e))?;
    let parser = Parser::<Element>::new();
    let mut buffered = BufReader::new(f);
    // A UTF-8 byte order mark before `ply` is skipped, as the text readers
    // skip it (`text_of`).
    if buffered
        .fill_buf()
        .map_err(|e| InputError::io(file, e))?
        .starts_with(super::UTF8_BOM)
    {
        buffered.consume(super::UTF8_BOM.len());
    }
    let mut reader = Reader::new(buffered);
    let header = parser
        .read_header(&mut reader)
        .map_err(|e| ply_error(file, &e, true))?;
    let vertex_count = check_header(file, &header)?;
    // ASCII payload lines are numbered on from the header's last line
    // (`line()` is the number of the line the reader is at).
    let line = reader.line().saturating_sub(1);
    let mut mesh = Mesh {
        positions: Vec::with_capacity(vertex_count.min(PREALLOCATED)),
        triangles: Vec::new(),
    };
    let mut faces = Faces {
        vertex_count,
        read: 0,
        polygons: Polygons::default(),
    };
    // Each element goes into the mesh as it is read: holding them all
    // first, as `read_payload` does, kept a `Vec` alive per face (about 100
    // bytes a face) and walked them all again. Binary elements are parsed
    // by the crate (`read_*_endian_element`), ASCII ones by `ply_ascii`.
    let mut keep = |name: &str, e: Element, mesh: &mut Mesh| match name {
        "vertex" => {
            mesh.positions.push(e.xyz);
            Ok(())
        }
        "face" => faces.push(&mut mesh.triangles, &e, file),
        _ => Ok(()),
    };
    if header.encoding == Encoding::Ascii {
        let mut payload = AsciiPayload::new(reader.get_mut(), file, line);
        for (name, def) in &header.elements {
            if name == "face" {
                mesh.triangles.reserve(def.count.min(PREALLOCATED));
            }
            for i in 0..def.count {
                let e = payload.element(def, i, is_index_list)?;
                let e = Element {
                    xyz: e.xyz,
                    indices_other: e.indices,
                    ..Element::default()
                };
                keep(name, e, &mut mesh)?;
            }
            payload.finish(def)?;
        }
    } else {
        let big = header.encoding == Encoding::BinaryBigEndian;
        for (name, def) in &header.elements {
            // A binary element without properties has no bytes: its count,
            // up to 2^64 − 1, would be a loop over nothing (every element
            // with a property reads a byte at least, so the file's end
            // bounds the others).
            if def.properties.is_empty() {
                continue;
            }
            if name == "face" {
                mesh.triangles.reserve(def.count.min(PREALLOCATED));
            }
            for i in 0..def.count {
                let inner = reader.get_mut();
                let e = if big {
                    parser.read_big_endian_element(inner, def)
                } else {
                    parser.read_little_endian_element(inner, def)
                };
                let e = e.map_err(|e| binary_error(file, name, i, def.count, &e))?;
                keep(name, e, &mut mesh)?;
            }
        }
    }
    faces.polygons.untangle(&mut mesh);
    Ok(mesh)
}

/// Capacity reserved from a header's element count at most: a header may
/// claim more elements than its file holds.
const PREALLOCATED: usize = 1 << 20;

/// Checks that the header declares what a mesh needs (`vertex` x, y, z
/// scalars; a `face` index list) before any payload is read, and answers
/// the vertex count.
fn check_header(file: &str, header: &ply_rs_bw::ply::Header) -> Result<usize, InputError> {
    let vertex_def = header
        .elements
        .get("vertex")
        .ok_or_else(|| InputError::malformed(file, "PLY has no 'vertex' element"))?;
    for axis in ["x", "y", "z"] {
        match vertex_def.properties.get(axis).map(|p| &p.data_type) {
            Some(PropertyType::Scalar(_)) => {}
            Some(PropertyType::List(..)) => {
                return Err(InputError::malformed(
                    file,
                    format!("PLY vertex property '{axis}' is a list"),
                ));
            }
            None => {
                return Err(InputError::malformed(
                    file,
                    format!("PLY vertex element has no '{axis}' property"),
                ));
            }
        }
    }
    let face_def = header
        .elements
        .get("face")
        .ok_or_else(|| InputError::malformed(file, "PLY has no 'face' element"))?;
    let has_list = face_def
        .properties
        .iter()
        .any(|(name, p)| is_index_list(name) && matches!(p.data_type, PropertyType::List(..)));
    if !has_list {
        return Err(InputError::malformed(
            file,
            "PLY face element has no 'vertex_indices' or 'vertex_index' list",
        ));
    }
    check_vertex_count(file, vertex_def.count as u64)?;
    Ok(vertex_def.count)
}

/// The faces read so far, triangulated as they come.
struct Faces {
    /// The header's vertex count: faces may come before the vertices.
    vertex_count: usize,
    read: usize,
    polygons: Polygons,
}

impl Faces {
    fn push(
        &mut self,
        triangles: &mut Vec<[u32; 3]>,
        face: &Element,
        file: &str,
    ) -> Result<(), InputError> {
        push_polygon(
            triangles,
            face.indices(),
            self.vertex_count,
            &mut self.polygons,
        )
        .map_err(|m| InputError::element(file, format!("face {}", self.read), m))?;
        self.read += 1;
        Ok(())
    }
}

/// A binary element that could not be read, in one line: which element,
/// which of how many, and why (most often the file ends early).
fn binary_error(file: &str, name: &str, i: usize, count: usize, e: &ParseError) -> InputError {
    let why = match e.kind() {
        std::io::ErrorKind::UnexpectedEof => "the file ends".to_owned(),
        _ => ply_message(e),
    };
    InputError::malformed(
        file,
        format!("invalid PLY: cannot read {name} {i} of {count}: {why}"),
    )
}

/// Turns a `ply-rs-bw` error into one readable line: the line number only
/// where lines mean something (header, ascii payload), and the offending
/// text plus the innermost cause instead of the nested restatements.
fn ply_error(file: &str, e: &ParseError, text: bool) -> InputError {
    let message = ply_message(e);
    match e.line() {
        Some(line) if text && line > 0 => InputError::line(file, line, message),
        _ => InputError::malformed(file, format!("invalid PLY: {message}")),
    }
}

/// The readable part of a `ply-rs-bw` error: the offending text and the
/// innermost cause.
fn ply_message(e: &ParseError) -> String {
    let message = e.to_string();
    let message = match message.strip_prefix("Line ") {
        Some(rest) => rest.split_once(": ").map_or(message.as_str(), |(_, m)| m),
        None => message.as_str(),
    };
    match (
        message.split_once("String: '"),
        message.rsplit_once("Error: "),
    ) {
        (Some((_, rest)), Some((_, cause))) => {
            let quoted = rest.split_once('\'').map_or(rest, |(q, _)| q).trim();
            // The header grammar's own error is a dump of the tokens it
            // expected: say instead what the line should have been.
            if cause.starts_with("ParseError") {
                format!("cannot parse '{quoted}': {}", header_line_hint(quoted))
            } else {
                format!("cannot parse '{quoted}': {cause}")
            }
        }
        _ => message.to_owned(),
    }
}

/// What a header line that the grammar refused should look like, by its
/// first word.
fn header_line_hint(line: &str) -> &'static str {
    let first = line.split_ascii_whitespace().next().unwrap_or("");
    match first {
        "property" => {
            "not a property ('property TYPE NAME' or 'property list COUNT_TYPE TYPE NAME', TYPE one of char, uchar, short, ushort, int, uint, float, double, or int8 ... float64)"
        }
        "format" => {
            "not a format line ('format ascii 1.0', 'format binary_little_endian 1.0' or 'format binary_big_endian 1.0')"
        }
        "element" => "not an element ('element NAME COUNT')",
        _ if first.parse::<f64>().is_ok() => "a value inside the header: is 'end_header' missing?",
        _ => {
            "not a PLY header line (the file starts with 'ply', then 'format', 'comment', 'obj_info', 'element' and 'property' lines, and 'end_header')"
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::test_util::TempFile;
    use super::super::{ReadOptions, check_mesh, read_mesh};
    use super::*;

    const ASCII: &str = "ply\nformat ascii 1.0\ncomment a unit square as one quad plus a triangle\n\
element vertex 5\nproperty float x\nproperty float y\nproperty float z\nproperty uchar red\n\
element face 2\nproperty list uchar int vertex_indices\nend_header\n\
0 0 0 255\n1 0 0 0\n1 1 0 0\n0 1 0 0\n2 0.5 0 0\n4 0 1 2 3\n3 1 4 2\n";

    fn expected() -> Mesh {
        Mesh {
            positions: vec![
                [0., 0., 0.],
                [1., 0., 0.],
                [1., 1., 0.],
                [0., 1., 0.],
                [2., 0.5, 0.],
            ],
            triangles: vec![[0, 1, 2], [0, 2, 3], [1, 4, 2]],
        }
    }

    fn binary(big_endian: bool, index_name: &str) -> Vec<u8> {
        let fmt = if big_endian {
            "binary_big_endian"
        } else {
            "binary_little_endian"
        };
        let mut out = format!(
            "ply\nformat {fmt} 1.0\nelement vertex 5\nproperty double x\nproperty double y\nproperty double z\n\
element edge 1\nproperty int vertex1\nproperty int vertex2\n\
element face 2\nproperty list uchar uint {index_name}\nend_header\n"
        )
        .into_bytes();
        for p in expected().positions {
            for c in p {
                out.extend(if big_endian {
                    c.to_be_bytes()
                } else {
                    c.to_le_bytes()
                });
            }
        }
        for i in [0i32, 1] {
            out.extend(if big_endian {
                i.to_be_bytes()
            } else {
                i.to_le_bytes()
            });
        }
        for face in [&[0u32, 1, 2, 3][..], &[1, 4, 2]] {
            out.push(face.len() as u8);
            for &i in face {
                out.extend(if big_endian {
                    i.to_be_bytes()
                } else {
                    i.to_le_bytes()
                });
            }
        }
        out
    }

    #[test]
    fn reads_ascii_with_quads() {
        let f = TempFile::new("sq.ply", ASCII.as_bytes());
        let m = read_mesh(&f.0, &ReadOptions::default()).unwrap();
        assert_eq!(m, expected());
        check_mesh(&m).unwrap();
    }

    /// Numbers and layouts the crate's ASCII grammar refused (an audit of
    /// real-world files, 2026-12-08) read as C readers read them: `.5`,
    /// `1.`, `-0.`, a `uchar` written `255.0`, NaN normals, blank lines,
    /// an element continued on the next line, CRLF.
    #[test]
    fn ascii_numbers_and_layouts_that_writers_produce() {
        let text = "ply\r\nformat ascii 1.0\r\nelement vertex 5\r\nproperty float x\r\nproperty float y\r\n\
property float z\r\nproperty float nx\r\nproperty uchar red\r\nelement face 2\r\n\
property list uchar int vertex_indices\r\nend_header\r\n\
.0 -0. 0 nan 255.0\r\n1. 0 0 inf 0\r\n\r\n1 1 0\r\n -nan 0\r\n0 1.0e0 0 0 0\r\n2 .5 0 0 0\r\n4 0 1 2 3\r\n3 1 4 2\r\n\r\n";
        let f = TempFile::new("writers.ply", text.as_bytes());
        let m = read_mesh(&f.0, &ReadOptions::default()).unwrap();
        assert_eq!(m, expected());
    }

    /// Header lines the grammar refuses are named with what they should
    /// have been, not with a dump of the grammar's expected tokens (an
    /// audit, 2026-12-08).
    #[test]
    fn header_errors_say_what_the_line_should_be() {
        for (text, message) in [
            (
                "PLY\nformat ascii 1.0\n",
                "line 1: cannot parse 'PLY': not a PLY header line",
            ),
            (
                "ply\nformat ascii 1.0\nelement vertex 1\nproperty half x\n",
                "line 4: cannot parse 'property half x': not a property ('property TYPE NAME'",
            ),
            (
                "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\n0 0 0\n",
                "line 5: cannot parse '0 0 0': a value inside the header: is 'end_header' missing?",
            ),
        ] {
            let f = TempFile::new("bad-header.ply", text.as_bytes());
            let err = read_mesh(&f.0, &ReadOptions::default())
                .unwrap_err()
                .to_string();
            assert!(err.contains(message), "{text:?}: {err}");
            assert!(!err.contains("ParseError"), "{err}");
        }
    }

    /// Every ASCII value error names its line, element and property, in
    /// one line (the crate's errors dumped their grammar).
    #[test]
    fn ascii_value_errors_name_line_element_and_property() {
        let head = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n\
property float z\nproperty uchar red\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n";
        for (body, message) in [
            (
                "0 0 0 0\n1 0 0 0\n0 1 zero 0\n3 0 1 2\n",
                "line 13: vertex 2, property 'z': 'zero' is not a number",
            ),
            (
                "0 0 0 256\n1 0 0 0\n0 1 0 0\n3 0 1 2\n",
                "line 11: vertex 0, property 'red': 256 is outside the type's range 0..=255",
            ),
            (
                "0 0 0 0 7\n1 0 0 0\n0 1 0 0\n3 0 1 2\n",
                "line 11: more values than the vertex's 4 properties",
            ),
            (
                "0 0 0 0\n1 0 0 0\n0 1 0 0\n3 0 1 2.5\n",
                "line 14: face 0, list 'vertex_indices': '2.5' is not an integer",
            ),
            (
                "0 0 0 0\n1 0 0 0\n0 1 0 0\n-1 0 1 2\n",
                "line 14: face 0, list 'vertex_indices': '-1' is not a count",
            ),
            (
                "0 0 0 0\n1 0 0 0\n0 1 0 0\n3 0 1\n",
                "line 15: the file ends inside face 0",
            ),
            (
                "0 0 0 0\n1 0 0 0\n",
                "line 13: the file ends: cannot read vertex 2 of 3",
            ),
        ] {
            let f = TempFile::new("bad-value.ply", format!("{head}{body}").as_bytes());
            let err = read_mesh(&f.0, &ReadOptions::default())
                .unwrap_err()
                .to_string();
            assert!(err.contains(message), "{body:?}: {err}");
            assert_eq!(err.lines().count(), 1, "{err}");
        }
    }

    /// A UTF-8 byte order mark before `ply` (found by an audit,
    /// 2026-12-08) is skipped, in ASCII and binary files alike.
    #[test]
    fn a_byte_order_mark_is_skipped() {
        let mut bytes = super::super::UTF8_BOM.to_vec();
        bytes.extend_from_slice(ASCII.as_bytes());
        let f = TempFile::new("bom.ply", &bytes);
        assert_eq!(
            read_mesh(&f.0, &ReadOptions::default()).unwrap(),
            expected()
        );
        let mut bytes = super::super::UTF8_BOM.to_vec();
        bytes.extend_from_slice(&binary(false, "vertex_indices"));
        let f = TempFile::new("bom-bin.ply", &bytes);
        assert_eq!(
            read_mesh(&f.0, &ReadOptions::default()).unwrap(),
            expected()
        );
    }

    #[test]
    fn reads_binary_both_endians_and_index_names() {
        for (big, name) in [
            (false, "vertex_indices"),
            (true, "vertex_index"),
            (true, "vertex_indices"),
        ] {
            let f = TempFile::new("bin.ply", &binary(big, name));
            let m = read_mesh(&f.0, &ReadOptions::default()).unwrap();
            assert_eq!(m, expected(), "big endian {big}, {name}");
        }
    }

    /// PLY lets elements come in any order: faces before their vertices
    /// are checked against the header's vertex count.
    #[test]
    fn faces_before_vertices() {
        let mut out = b"ply\nformat binary_little_endian 1.0\nelement face 2\n\
property list uchar int vertex_indices\nelement vertex 5\nproperty float x\n\
property float y\nproperty float z\nend_header\n"
            .to_vec();
        for face in [&[0i32, 1, 2, 3][..], &[1, 4, 2]] {
            out.push(face.len() as u8);
            out.extend(face.iter().flat_map(|i| i.to_le_bytes()));
        }
        for p in expected().positions {
            out.extend(p.iter().flat_map(|&c| (c as f32).to_le_bytes()));
        }
        let f = TempFile::new("faces-first.ply", &out);
        assert_eq!(
            read_mesh(&f.0, &ReadOptions::default()).unwrap(),
            expected()
        );
    }

    /// Found by reading the code (2026-12-08): a binary element declared
    /// with no properties and a count of 4 billion kept the reader looping
    /// over nothing for minutes (the reader before it too).
    #[test]
    fn a_huge_element_without_properties_is_skipped_at_once() {
        let mut bytes = b"ply\nformat binary_little_endian 1.0\nelement junk 4000000000\n\
element vertex 3\nproperty float x\nproperty float y\nproperty float z\n\
element face 1\nproperty list uchar int vertex_indices\nend_header\n"
            .to_vec();
        for p in [[0f32, 0., 0.], [1., 0., 0.], [0., 1., 0.]] {
            bytes.extend(p.iter().flat_map(|c| c.to_le_bytes()));
        }
        bytes.push(3);
        bytes.extend([0i32, 1, 2].iter().flat_map(|i| i.to_le_bytes()));
        let f = TempFile::new("junk.ply", &bytes);
        let m = read_mesh(&f.0, &ReadOptions::default()).unwrap();
        assert_eq!((m.positions.len(), m.triangles), (3, vec![[0, 1, 2]]));
    }

    #[test]
    fn truncated_binary_fails_cleanly() {
        let data = binary(false, "vertex_indices");
        for cut in [data.len() - 3, data.len() - 30, 180, 10] {
            let f = TempFile::new("trunc.ply", &data[..cut]);
            let err = read_mesh(&f.0, &ReadOptions::default()).unwrap_err();
            let msg = err.to_string();
            assert!(msg.contains("trunc.ply") && !msg.contains('\n'), "{msg}");
            if cut > 200 {
                assert!(msg.contains("of 2: the file ends"), "{msg}");
            }
        }
    }

    #[test]
    fn bad_index_and_missing_properties() {
        let bad = ASCII.replace("3 1 4 2", "3 1 7 2");
        let f = TempFile::new("bad.ply", bad.as_bytes());
        let msg = read_mesh(&f.0, &ReadOptions::default())
            .unwrap_err()
            .to_string();
        assert!(
            msg.ends_with("bad.ply: face 1: vertex index 7 out of range (the file has 5 vertices)"),
            "{msg}"
        );

        let noz = ASCII
            .replace("property float z\n", "")
            .replace(" 0 255\n", " 255\n")
            .replace(" 0 0\n", " 0\n");
        let f = TempFile::new("noz.ply", noz.as_bytes());
        let msg = read_mesh(&f.0, &ReadOptions::default())
            .unwrap_err()
            .to_string();
        assert!(msg.contains("no 'z' property"), "{msg}");

        let garbage = ASCII.replace("1 1 0 0", "1 one 0 0");
        let f = TempFile::new("garbage.ply", garbage.as_bytes());
        let msg = read_mesh(&f.0, &ReadOptions::default())
            .unwrap_err()
            .to_string();
        assert!(msg.contains("line 14: ") && !msg.contains('\n'), "{msg}");

        // An ASCII payload one line short: the line it ran out at.
        let short = ASCII.strip_suffix("3 1 4 2\n").unwrap();
        let f = TempFile::new("short.ply", short.as_bytes());
        let msg = read_mesh(&f.0, &ReadOptions::default())
            .unwrap_err()
            .to_string();
        assert!(
            msg.ends_with("short.ply: line 18: the file ends: cannot read face 1 of 2"),
            "{msg}"
        );
    }
}
