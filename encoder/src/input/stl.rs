//! STL reader, binary and ascii, by hand.
//!
//! STL stores each triangle with three coordinates of its own; corners
//! whose f32 coordinates are equal are welded into one vertex (-0.0 and 0.0
//! count as equal, and are stored as 0.0), which is how STL meshes share
//! vertices at all. Input vertex ids (as `--permutation` reports them)
//! number the distinct positions in the order the facets first use them,
//! corners in facet order. Coordinates are the file's f32 values; facet
//! normals and attribute bytes are ignored.
//!
//! A file is binary when its size is exactly that of a binary STL (84 +
//! 50 bytes per facet, the facet count at byte 80), even when its header
//! begins with `solid`, as some exporters' do; otherwise it is ascii when it
//! begins (after an optional UTF-8 BOM and blanks) with the word `solid`
//! and holds no NUL byte, and else a binary file whose size does not match
//! its facet count, which the error says.
//!
//! Ascii: every `solid … endsolid` block of the file is read (their facets
//! form one mesh), keywords in any case, words separated by any ASCII
//! whitespace; every syntax error names its line.
//!
//! This replaces `stl_io`, which read only the first solid of an ascii
//! file, welded on f32 bit patterns (so -0.0 and 0.0 stayed apart and
//! closed meshes cracked), refused `solid` without a name or followed by a
//! tab, leading blanks, uppercase keywords and NaN facet normals, and said
//! "failed to fill whole buffer" of a binary file that was truncated.

use std::collections::HashMap;
use std::collections::hash_map::Entry;
use std::path::Path;

use crate::Mesh;

use super::{InputError, check_vertex_count, text_of};

/// The 80-byte header and the u32 facet count.
const HEADER: usize = 84;
/// A binary facet: normal and three corners (12 f32) and a u16 attribute.
const FACET: usize = 50;

pub(super) fn read(path: &Path, file: &str) -> Result<Mesh, InputError> {
    let bytes = std::fs::read(path).map_err(|e| InputError::io(file, e))?;
    parse(&bytes, file)
}

pub(super) fn parse(bytes: &[u8], file: &str) -> Result<Mesh, InputError> {
    let declared = declared_facets(bytes);
    if let Some(count) = declared
        && binary_size(count) == bytes.len() as u64
    {
        return parse_binary(bytes.get(HEADER..).unwrap_or_default(), count, file);
    }
    let solid = begins_with_solid(bytes);
    // An ascii STL never holds a NUL byte; a binary one whose header begins
    // with "solid" nearly always does (in its facet count, if nowhere else).
    let nul = bytes.contains(&0);
    if solid && !nul {
        return parse_ascii(&text_of(bytes), file);
    }
    let not_ascii = if solid {
        "it begins with 'solid' but holds NUL bytes, so it is not ascii STL either"
    } else {
        "not ascii STL either (no 'solid' at the start)"
    };
    let len = bytes.len() as u64;
    let message = match declared {
        None => format!(
            "{len} bytes: too short for a binary STL (an 80-byte header and a \
             facet count come first), and {not_ascii}"
        ),
        Some(0) => format!(
            "binary STL header declares 0 facets, but {} bytes of facet data \
             follow it; {not_ascii}",
            len - HEADER as u64
        ),
        Some(count) => format!(
            "binary STL header declares {count} facets ({} bytes), the file has \
             {len} bytes; {not_ascii}",
            binary_size(count),
        ),
    };
    Err(InputError::malformed(file, message))
}

/// The facet count of a binary header (the u32 at byte 80), if the file
/// is that long.
fn declared_facets(bytes: &[u8]) -> Option<u64> {
    let count: [u8; 4] = bytes.get(80..HEADER)?.try_into().ok()?;
    Some(u32::from_le_bytes(count) as u64)
}

/// The size of a binary STL of `count` facets (no overflow: `count` is a
/// u32).
fn binary_size(count: u64) -> u64 {
    HEADER as u64 + FACET as u64 * count
}

/// Whether the file begins, after an optional UTF-8 BOM and blanks, with
/// the word `solid` in any case.
fn begins_with_solid(bytes: &[u8]) -> bool {
    let start = bytes
        .strip_prefix(b"\xEF\xBB\xBF")
        .unwrap_or(bytes)
        .trim_ascii_start();
    match start.split_first_chunk::<5>() {
        Some((word, rest)) => {
            word.eq_ignore_ascii_case(b"solid")
                && rest.first().is_none_or(|b| b.is_ascii_whitespace())
        }
        None => false,
    }
}

/// The facets after the header, `count` of them (the caller checked the
/// size, so nothing here is proportional to a claimed count alone).
fn parse_binary(facets: &[u8], count: u64, file: &str) -> Result<Mesh, InputError> {
    let (facets, _) = facets.as_chunks::<FACET>();
    debug_assert_eq!(facets.len() as u64, count);
    let mut weld = Welder::new(file, facets.len());
    for (i, facet) in facets.iter().enumerate() {
        // 12 f32: the normal, unused, then the three corners.
        let (words, _) = facet.as_chunks::<4>();
        let mut corners = [[0f32; 3]; 3];
        for (c, word) in corners
            .as_flattened_mut()
            .iter_mut()
            .zip(words.iter().skip(3))
        {
            *c = f32::from_le_bytes(*word);
        }
        for (k, corner) in corners.iter().enumerate() {
            if let Some(c) = corner.iter().find(|c| !c.is_finite()) {
                return Err(InputError::element(
                    file,
                    format!("facet {i}, corner {k}"),
                    format!("coordinate is not a finite number ({c})"),
                ));
            }
        }
        weld.facet(corners)?;
    }
    weld.finish()
}

fn parse_ascii(text: &str, file: &str) -> Result<Mesh, InputError> {
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    let mut words = Words::new(text, file);
    let mut weld = Welder::new(file, 0);
    let mut solids = 0usize;
    loop {
        match words.word() {
            Some(w) if w.eq_ignore_ascii_case("solid") => words.skip_line(),
            None if solids > 0 => break,
            found => {
                let expected = if solids == 0 {
                    "'solid'"
                } else {
                    "'solid' or the end of the file after 'endsolid'"
                };
                return Err(words.unexpected(expected, found));
            }
        }
        solids += 1;
        loop {
            match words.word() {
                Some(w) if w.eq_ignore_ascii_case("endsolid") => {
                    words.skip_line();
                    break;
                }
                Some(w) if w.eq_ignore_ascii_case("facet") => {
                    let corners = facet(&mut words)?;
                    weld.facet(corners)?;
                }
                found => return Err(words.unexpected("'facet' or 'endsolid'", found)),
            }
        }
    }
    weld.finish()
}

/// One facet after its `facet` keyword, up to and with `endfacet`.
fn facet(words: &mut Words<'_>) -> Result<[[f32; 3]; 3], InputError> {
    words.keyword("normal")?;
    // Any three words: normals are never used (some exporters write NaN).
    for found in 0..3 {
        if words.operand().is_none() {
            return Err(words.error(format!(
                "expected 3 numbers after 'facet normal', found {found}"
            )));
        }
    }
    words.keyword("outer")?;
    words.keyword("loop")?;
    let mut corners = [[0f32; 3]; 3];
    for (k, corner) in corners.iter_mut().enumerate() {
        match words.word() {
            Some(w) if w.eq_ignore_ascii_case("vertex") => {}
            Some(w) if w.eq_ignore_ascii_case("endloop") => {
                return Err(words.error(format!(
                    "expected 'vertex', found 'endloop' (a facet loop with {k} \
                     vertices; STL facets have 3)"
                )));
            }
            found => return Err(words.unexpected("'vertex'", found)),
        }
        for (found, c) in corner.iter_mut().enumerate() {
            let Some(w) = words.operand() else {
                return Err(words.error(format!(
                    "expected 3 coordinates after 'vertex', found {found}"
                )));
            };
            *c = match w.parse::<f32>() {
                Ok(c) if c.is_finite() => c,
                Ok(_) => {
                    return Err(
                        words.error(format!("coordinate {} is not a finite number", shown(w)))
                    );
                }
                Err(_) => {
                    return Err(words.error(format!("{} is not a number", shown(w))));
                }
            };
        }
    }
    match words.word() {
        Some(w) if w.eq_ignore_ascii_case("endloop") => {}
        Some(w) if w.eq_ignore_ascii_case("vertex") => {
            return Err(words.error(
                "expected 'endloop', found 'vertex' (a facet loop with more than 3 \
                 vertices; STL facets have 3)",
            ));
        }
        found => return Err(words.unexpected("'endloop'", found)),
    }
    words.keyword("endfacet")?;
    Ok(corners)
}

/// A word as an error message quotes it: at most 40 characters, escaped.
fn shown(word: &str) -> String {
    let mut out = String::from("'");
    out.extend(word.chars().take(40).flat_map(char::escape_debug));
    if word.chars().nth(40).is_some() {
        out.push('…');
    }
    out.push('\'');
    out
}

/// The whitespace-separated words of an ascii STL, with the line of the
/// last word read (1-based) for error messages.
struct Words<'a> {
    rest: &'a str,
    file: &'a str,
    /// The line `rest` starts on.
    line: usize,
    /// The line of the last word read.
    word_line: usize,
}

impl<'a> Words<'a> {
    fn new(text: &'a str, file: &'a str) -> Self {
        Words {
            rest: text,
            file,
            line: 1,
            word_line: 1,
        }
    }

    /// The next word, on whatever line.
    fn word(&mut self) -> Option<&'a str> {
        self.skip_blanks(false);
        self.take_word()
    }

    /// The next word if it is on the line of the last one.
    fn operand(&mut self) -> Option<&'a str> {
        self.skip_blanks(true);
        self.take_word()
    }

    /// Skips the blanks before the next word, or only those before the
    /// end of the line.
    fn skip_blanks(&mut self, within_line: bool) {
        let stop = self
            .rest
            .find(|c: char| !c.is_ascii_whitespace() || (within_line && c == '\n'))
            .unwrap_or(self.rest.len());
        let (blanks, rest) = self.rest.split_at(stop);
        self.line += blanks.bytes().filter(|&b| b == b'\n').count();
        self.rest = rest;
    }

    /// The word `rest` starts with, if it starts with one.
    fn take_word(&mut self) -> Option<&'a str> {
        let end = self
            .rest
            .find(|c: char| c.is_ascii_whitespace())
            .unwrap_or(self.rest.len());
        if end == 0 {
            return None;
        }
        let (word, rest) = self.rest.split_at(end);
        self.rest = rest;
        self.word_line = self.line;
        Some(word)
    }

    /// Drops the rest of the current line (a solid's name).
    fn skip_line(&mut self) {
        match self.rest.split_once('\n') {
            Some((_, rest)) => {
                self.rest = rest;
                self.line += 1;
            }
            None => self.rest = "",
        }
    }

    /// Reads `keyword` (any case) or fails naming what is there instead.
    fn keyword(&mut self, keyword: &str) -> Result<(), InputError> {
        match self.word() {
            Some(w) if w.eq_ignore_ascii_case(keyword) => Ok(()),
            found => Err(self.unexpected(&format!("'{keyword}'"), found)),
        }
    }

    fn unexpected(&self, expected: &str, found: Option<&str>) -> InputError {
        let found = found.map_or_else(|| "the end of the file".to_owned(), shown);
        self.error(format!("expected {expected}, found {found}"))
    }

    /// An error at the line of the last word read.
    fn error(&self, message: impl Into<String>) -> InputError {
        InputError::line(self.file, self.word_line, message)
    }
}

/// Builds the mesh, welding corners by position.
struct Welder<'f> {
    file: &'f str,
    mesh: Mesh,
    /// Vertex ids by coordinate bits, -0.0 folded into 0.0 (foldhash, as in
    /// the glTF reader: a file is not a hash-flooding threat worth SipHash).
    ids: HashMap<[u32; 3], u32, foldhash::fast::RandomState>,
}

impl<'f> Welder<'f> {
    /// `facets`: how many are coming, where known (0 otherwise).
    fn new(file: &'f str, facets: usize) -> Self {
        // About half as many vertices as facets on a closed mesh.
        let vertices = facets / 2 + 3;
        Welder {
            file,
            mesh: Mesh {
                positions: Vec::with_capacity(vertices),
                triangles: Vec::with_capacity(facets),
            },
            ids: HashMap::with_capacity_and_hasher(vertices, Default::default()),
        }
    }

    /// Adds a facet of finite corners.
    fn facet(&mut self, corners: [[f32; 3]; 3]) -> Result<(), InputError> {
        let mut triangle = [0u32; 3];
        for (id, corner) in triangle.iter_mut().zip(corners) {
            // + 0.0 turns -0.0 into 0.0, so both weld.
            let p = corner.map(|c| c + 0.0);
            *id = match self.ids.entry(p.map(f32::to_bits)) {
                Entry::Occupied(e) => *e.get(),
                Entry::Vacant(e) => {
                    let next = self.mesh.positions.len();
                    check_vertex_count(self.file, next as u64 + 1)?;
                    self.mesh.positions.push(p.map(f64::from));
                    *e.insert(next as u32)
                }
            };
        }
        self.mesh.triangles.push(triangle);
        Ok(())
    }

    fn finish(self) -> Result<Mesh, InputError> {
        if self.mesh.triangles.is_empty() {
            return Err(InputError::malformed(self.file, "no facets"));
        }
        Ok(self.mesh)
    }
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

    /// TETRA's triangles, welded.
    const TETRA_TRIANGLES: [[u32; 3]; 4] = [[0, 1, 2], [0, 2, 3], [0, 3, 1], [2, 1, 3]];

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

    /// One solid's text, coordinates as Rust writes them (`-0` for -0.0).
    fn solid(name: &str, facets: &[[[f32; 3]; 3]]) -> String {
        let mut s = format!("solid {name}\n");
        for f in facets {
            s.push_str("facet normal 0 0 0\n outer loop\n");
            for v in f {
                s.push_str(&format!("  vertex {} {} {}\n", v[0], v[1], v[2]));
            }
            s.push_str(" endloop\nendfacet\n");
        }
        s.push_str(&format!("endsolid {name}\n"));
        s
    }

    fn ascii(facets: &[[[f32; 3]; 3]]) -> String {
        solid("tetra", facets)
    }

    fn error(bytes: &[u8]) -> String {
        let msg = parse(bytes, "bad.stl").unwrap_err().to_string();
        assert!(!msg.contains('\n'), "{msg}");
        msg
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
            assert_eq!(m.triangles, TETRA_TRIANGLES);
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
                "bad.stl: facet 3, corner 2: coordinate is not a finite number (NaN)",
            ),
            // A facet count beyond the data: truncated.
            (
                binary(b"", &TETRA)[..120].to_vec(),
                "bad.stl: binary STL header declares 4 facets (284 bytes), the file has 120 bytes",
            ),
            (
                b"solid x\nfacet normal 0 0 0\n outer loop\n vertex 1 2\n".to_vec(),
                "bad.stl: line 4: expected 3 coordinates after 'vertex', found 2",
            ),
        ];
        for (bytes, expected) in cases {
            let msg = error(&bytes);
            assert!(msg.starts_with(expected), "{msg}");
        }
        // A count of 2^32 - 1 facets in a short file fails without
        // reserving memory for them.
        let mut huge = binary(b"", &TETRA);
        huge[80..84].copy_from_slice(&u32::MAX.to_le_bytes());
        assert!(error(&huge).starts_with(
            "bad.stl: binary STL header declares 4294967295 facets (214748364834 bytes), \
             the file has 284 bytes"
        ));
    }

    /// Every solid of an ascii file is read, and their facets weld into one
    /// mesh (only the first was read before, silently).
    #[test]
    fn every_solid_of_an_ascii_file_is_read() {
        let two = format!(
            "{}{}\n\n  \r\n",
            solid("a", &TETRA[..2]),
            solid("b", &TETRA[2..])
        );
        let m = parse(two.as_bytes(), "two.stl").unwrap();
        assert_eq!(m.positions.len(), 4);
        assert_eq!(m.triangles, TETRA_TRIANGLES);
        check_mesh(&m).unwrap();
        let three = format!(
            "{}{}{}",
            solid("a", &TETRA[..1]),
            solid("", &[]),
            solid("c", &TETRA[1..])
        );
        assert_eq!(
            parse(three.as_bytes(), "three.stl").unwrap().triangles,
            TETRA_TRIANGLES
        );
        // Anything but another solid after an endsolid is an error.
        let trailing = format!("{}facet normal 0 0 0\n", solid("a", &TETRA));
        assert_eq!(
            error(trailing.as_bytes()),
            "bad.stl: line 31: expected 'solid' or the end of the file after 'endsolid', \
             found 'facet'"
        );
    }

    /// A unit cube, counter-clockwise seen from outside.
    fn cube() -> Vec<[[f32; 3]; 3]> {
        let corner = |i: u32| [i & 1, (i >> 1) & 1, (i >> 2) & 1].map(|c| c as f32);
        [
            [0, 2, 1],
            [1, 2, 3],
            [4, 5, 6],
            [5, 7, 6],
            [0, 1, 4],
            [1, 5, 4],
            [2, 6, 3],
            [3, 6, 7],
            [0, 4, 2],
            [2, 4, 6],
            [1, 3, 5],
            [3, 7, 5],
        ]
        .iter()
        .map(|t| t.map(corner))
        .collect()
    }

    /// -0.0 and 0.0 weld (on f32 bit patterns they did not, and the cube
    /// cracked into 11 vertices); the numbering stays that of first use.
    #[test]
    fn signed_zeros_weld() {
        let mut facets = cube();
        for f in facets.iter_mut().skip(1).step_by(2) {
            for c in f.as_flattened_mut() {
                if *c == 0.0 {
                    *c = -0.0;
                }
            }
        }
        let text = solid("cube", &facets);
        assert!(text.contains("vertex -0 1 -0"), "{text}");
        let exponents = text
            .replace("-0 ", "-0.000000e+00 ")
            .replace("-0\n", "-0.000000e+00\n");
        for bytes in [
            binary(b"", &facets),
            text.into_bytes(),
            exponents.into_bytes(),
        ] {
            let m = parse(&bytes, "cube.stl").unwrap();
            assert_eq!(m.positions.len(), 8);
            let stats = check_mesh(&m).unwrap();
            assert_eq!((stats.components, stats.boundary_loops), (1, 0));
            // Stored as 0.0, whichever sign came first.
            assert!(
                m.positions
                    .as_flattened()
                    .iter()
                    .all(|c| c.is_sign_positive())
            );
            // First use: 0, 2, 1 of the first facet, then 3, ...
            assert_eq!(m.triangles[..2], [[0, 1, 2], [2, 1, 3]]);
            assert_eq!(m.positions[1], [0.0, 1.0, 0.0]);
        }
    }

    /// `solid` alone, a tab, blanks before it, a BOM, CRLF, uppercase
    /// keywords, words split across lines: all read (stl_io refused them).
    #[test]
    fn ascii_keywords_in_any_case_and_any_blanks() {
        let plain = ascii(&TETRA);
        let upper = plain
            .lines()
            .map(|l| {
                let (indent, rest) = l.split_at(l.len() - l.trim_start().len());
                let (keywords, numbers) = match rest.find(|c: char| c.is_ascii_digit() || c == '-')
                {
                    Some(i) => rest.split_at(i),
                    None => (rest, ""),
                };
                format!("{indent}{}{numbers}\n", keywords.to_uppercase())
            })
            .collect::<String>();
        assert!(
            upper.contains("FACET NORMAL 0 0 0\n OUTER LOOP\n  VERTEX 0 0 0\n  VERTEX 0 1 0\n")
        );
        assert!(upper.starts_with("SOLID TETRA\n") && upper.ends_with("ENDSOLID TETRA\n"));
        let variants = [
            plain.replacen("solid tetra", "solid", 1),
            plain.replacen("solid tetra", "solid\tmy part", 1),
            format!("\n  \t\n   {plain}"),
            format!("\u{feff}{plain}"),
            format!("\u{feff} \r\n{plain}"),
            plain.replace('\n', "\r\n"),
            plain.replace(' ', "\t\t"),
            plain.replace("endsolid tetra", "endsolid"),
            upper,
            plain
                .replace("facet normal", "Facet\nNormal")
                .replace("outer loop", "OUTER\tLoop"),
        ];
        for text in variants {
            let m = parse(text.as_bytes(), "tetra.stl").unwrap_or_else(|e| panic!("{e}\n{text}"));
            assert_eq!(m.triangles, TETRA_TRIANGLES, "{text}");
        }
    }

    /// Facet normals are never used: NaN ones are read; coordinates that are
    /// not finite are refused, naming their line.
    #[test]
    fn nan_normals_are_ignored_but_not_nan_coordinates() {
        let plain = ascii(&TETRA);
        for normal in [
            "nan nan nan",
            "-nan -nan -nan",
            "NaN -nan(ind) 1.#QNAN",
            "-0.000000e+00 inf x",
        ] {
            let text = plain.replacen("normal 0 0 0", &format!("normal {normal}"), 2);
            let m = parse(text.as_bytes(), "tetra.stl").unwrap();
            assert_eq!(m.triangles, TETRA_TRIANGLES);
        }
        for (coordinate, expected) in [
            ("nan", "coordinate 'nan' is not a finite number"),
            ("-inf", "coordinate '-inf' is not a finite number"),
            ("1e39", "coordinate '1e39' is not a finite number"),
            ("1,5", "'1,5' is not a number"),
        ] {
            let text = plain.replacen("vertex 0 1 0", &format!("vertex 0 {coordinate} 0"), 1);
            assert_eq!(
                error(text.as_bytes()),
                format!("bad.stl: line 5: {expected}")
            );
        }
    }

    #[test]
    fn errors_say_what_is_wrong() {
        // 20 facets declared, 12 there.
        let mut truncated = binary(b"", &[TETRA[0]; 12]);
        truncated[80..84].copy_from_slice(&20u32.to_le_bytes());
        assert_eq!(truncated.len(), 684);
        assert!(error(&truncated).starts_with(
            "bad.stl: binary STL header declares 20 facets (1084 bytes), the file has 684 bytes"
        ));
        // The same with a header that begins like ascii.
        let mut solid_header = binary(b"solid part", &TETRA);
        solid_header.truncate(200);
        assert_eq!(
            error(&solid_header),
            "bad.stl: binary STL header declares 4 facets (284 bytes), the file has 200 bytes; \
             it begins with 'solid' but holds NUL bytes, so it is not ascii STL either"
        );
        let mut no_count = binary(b"", &TETRA);
        no_count[80..84].copy_from_slice(&0u32.to_le_bytes());
        assert_eq!(
            error(&no_count),
            "bad.stl: binary STL header declares 0 facets, but 200 bytes of facet data follow \
             it; not ascii STL either (no 'solid' at the start)"
        );
        assert_eq!(
            error(b"ply\nformat ascii 1.0\n"),
            "bad.stl: 21 bytes: too short for a binary STL (an 80-byte header and a facet count \
             come first), and not ascii STL either (no 'solid' at the start)"
        );
        assert_eq!(
            error(b"solid empty\nendsolid empty\n"),
            "bad.stl: no facets"
        );
        let plain = ascii(&TETRA);
        let lines: Vec<&str> = plain.lines().collect();
        let edited = |line: usize, with: &str| {
            let mut l = lines.clone();
            l[line - 1] = with;
            l.join("\n")
        };
        let nines = "9".repeat(60);
        let cases = [
            // Two vertices, then endloop.
            (
                edited(13, "endloop"),
                "line 13: expected 'vertex', found 'endloop' (a facet loop with 2 vertices; \
                 STL facets have 3)"
                    .to_owned(),
            ),
            // Four vertices.
            (
                edited(6, "vertex 0 0 0\nvertex 1 1 1"),
                "line 7: expected 'endloop', found 'vertex' (a facet loop with more than 3 \
                 vertices; STL facets have 3)"
                    .to_owned(),
            ),
            (
                edited(2, "facet normal 0 0"),
                "line 2: expected 3 numbers after 'facet normal', found 2".to_owned(),
            ),
            (
                edited(3, "outer"),
                "line 4: expected 'loop', found 'vertex'".to_owned(),
            ),
            (
                edited(7, "endfacet"),
                "line 7: expected 'endloop', found 'endfacet'".to_owned(),
            ),
            (
                edited(8, "endfacet x"),
                "line 8: expected 'facet' or 'endsolid', found 'x'".to_owned(),
            ),
            (
                edited(9, "face normal 0 0 1"),
                "line 9: expected 'facet' or 'endsolid', found 'face'".to_owned(),
            ),
            (
                lines[..29].join("\n"),
                "line 29: expected 'facet' or 'endsolid', found the end of the file".to_owned(),
            ),
            (
                lines[..4].join("\n"),
                "line 4: expected 'vertex', found the end of the file".to_owned(),
            ),
            (
                edited(4, &format!("vertex 0 1 {nines}")),
                format!(
                    "line 4: coordinate '{}…' is not a finite number",
                    &nines[..40]
                ),
            ),
            (
                edited(4, "vertex 0 1 \u{1}"),
                "line 4: '\\u{1}' is not a number".to_owned(),
            ),
        ];
        for (text, expected) in cases {
            assert_eq!(
                error(text.as_bytes()),
                format!("bad.stl: {expected}"),
                "{text}"
            );
        }
    }

    /// Every prefix of good files, and every byte of them changed, reads or
    /// fails without panicking (a fuzz target does this at large).
    #[test]
    fn damaged_files_never_panic() {
        let files = [
            binary(b"solid x", &TETRA),
            binary(b"", &TETRA),
            ascii(&TETRA).into_bytes(),
        ];
        for file in &files {
            for end in 0..=file.len() {
                let _ = parse(&file[..end], "x.stl");
            }
            for i in 0..file.len() {
                for byte in [0, b' ', b'\n', 0xff, b'e', b'-'] {
                    let mut damaged = file.clone();
                    damaged[i] = byte;
                    let _ = parse(&damaged, "x.stl");
                }
            }
        }
    }
}
