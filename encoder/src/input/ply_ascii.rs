//! The payload of an ASCII PLY file, element by element: the project's own
//! reader of the values (the header stays `ply-rs-bw`'s). The crate's line
//! grammar refused numbers that C readers and the writers people use
//! produce (`.5`, `1.`, `nan`, `inf`, a `uchar` colour written `255.0`),
//! blank lines, and an element continued on the next line, each with a dump
//! of its grammar in place of a message (an audit of real-world files,
//! 2026-12-08). Here the values are words: an element starts on a new
//! line, may go on over the following ones, and must not leave words on
//! its last line; each word is read as its property's type says, an
//! integer also where it is written as a whole decimal; every error names
//! the line, the element and the property.

use std::io::BufRead;

use ply_rs_bw::ply::{ElementDef, PropertyType, ScalarType};

use super::InputError;

/// A cursor over the words of an ASCII payload.
pub(super) struct AsciiPayload<'f, R> {
    reader: R,
    file: &'f str,
    /// The number of the line in `text` (1-based, the header's counted).
    line: usize,
    text: String,
    /// Byte ranges of the unread words of `text`.
    words: Vec<(usize, usize)>,
    next: usize,
}

/// What an element of the payload gave: its x, y, z where it has them,
/// and the vertex indices of its index list.
#[derive(Default)]
pub(super) struct AsciiElement {
    pub(super) xyz: [f64; 3],
    pub(super) indices: Vec<i64>,
}

impl<'f, R: BufRead> AsciiPayload<'f, R> {
    /// `line`: the number of the header's last line.
    pub(super) fn new(reader: R, file: &'f str, line: usize) -> Self {
        AsciiPayload {
            reader,
            file,
            line,
            text: String::new(),
            words: Vec::new(),
            next: 0,
        }
    }

    fn error(&self, message: String) -> InputError {
        InputError::line(self.file, self.line, message)
    }

    /// Reads lines until one holds a word; false at the file's end.
    fn next_line(&mut self) -> Result<bool, InputError> {
        loop {
            self.text.clear();
            self.line += 1;
            let read = self
                .reader
                .read_line(&mut self.text)
                .map_err(|e| self.error(format!("cannot read: {e}")))?;
            if read == 0 {
                return Ok(false);
            }
            self.words.clear();
            self.next = 0;
            let bytes = self.text.as_bytes();
            let mut i = 0;
            while i < bytes.len() {
                while i < bytes.len() && bytes[i].is_ascii_whitespace() {
                    i += 1;
                }
                let start = i;
                while i < bytes.len() && !bytes[i].is_ascii_whitespace() {
                    i += 1;
                }
                if i > start {
                    self.words.push((start, i));
                }
            }
            if !self.words.is_empty() {
                return Ok(true);
            }
        }
    }

    /// The next word, from the following lines where this one is used up;
    /// `what` names the element for the file's end.
    fn word(&mut self, what: &dyn Fn() -> String) -> Result<(usize, usize), InputError> {
        if self.next == self.words.len() && !self.next_line()? {
            return Err(self.error(format!("the file ends inside {}", what())));
        }
        self.next += 1;
        Ok(self.words[self.next - 1])
    }

    /// Reads element `i` of `def` (its count `def.count`), keeping x, y, z
    /// and the list `index_list` names.
    pub(super) fn element(
        &mut self,
        def: &ElementDef,
        i: usize,
        index_list: impl Fn(&str) -> bool,
    ) -> Result<AsciiElement, InputError> {
        let name = &def.name;
        let what = || format!("{name} {i}");
        // An element starts on a line of its own.
        if self.next < self.words.len() {
            return Err(self.error(format!(
                "more values than the {name}'s {} properties",
                def.properties.len()
            )));
        }
        if !self.next_line()? {
            return Err(self.error(format!(
                "the file ends: cannot read {name} {i} of {}",
                def.count
            )));
        }
        let mut out = AsciiElement::default();
        for (property, p) in &def.properties {
            match &p.data_type {
                PropertyType::Scalar(t) => {
                    let (a, b) = self.word(&what)?;
                    let v = value(&self.text[a..b], t).map_err(|m| {
                        self.error(format!("{name} {i}, property '{property}': {m}"))
                    })?;
                    if let Some(k) = ["x", "y", "z"].iter().position(|axis| axis == property) {
                        out.xyz[k] = v;
                    }
                }
                PropertyType::List(count_type, item_type) => {
                    let (a, b) = self.word(&what)?;
                    let count = value(&self.text[a..b], count_type)
                        .ok()
                        .filter(|c| *c >= 0.0)
                        .ok_or_else(|| {
                            self.error(format!(
                                "{name} {i}, list '{property}': '{}' is not a count",
                                &self.text[a..b]
                            ))
                        })? as u64;
                    let keep = index_list(property);
                    for _ in 0..count {
                        let (a, b) = self.word(&what)?;
                        let v = value(&self.text[a..b], item_type).map_err(|m| {
                            self.error(format!("{name} {i}, list '{property}': {m}"))
                        })?;
                        if keep {
                            out.indices.push(v as i64);
                        }
                    }
                }
            }
        }
        Ok(out)
    }

    /// Fails where the last element left words on its line.
    pub(super) fn finish(&self, def: &ElementDef) -> Result<(), InputError> {
        if self.next < self.words.len() {
            return Err(self.error(format!(
                "more values than the {}'s {} properties",
                def.name,
                def.properties.len()
            )));
        }
        Ok(())
    }
}

/// A word as a value of type `t`: floats as their own width reads them
/// (`.5`, `1.`, `nan`, `inf` included), integers in their type's range,
/// also when written as a whole decimal (`255.0`).
fn value(word: &str, t: &ScalarType) -> Result<f64, String> {
    let (low, high): (f64, f64) = match t {
        ScalarType::Float => {
            return word
                .parse::<f32>()
                .map(f64::from)
                .map_err(|_| format!("'{word}' is not a number"));
        }
        ScalarType::Double => {
            return word
                .parse::<f64>()
                .map_err(|_| format!("'{word}' is not a number"));
        }
        ScalarType::Char => (i8::MIN.into(), i8::MAX.into()),
        ScalarType::UChar => (0.0, u8::MAX.into()),
        ScalarType::Short => (i16::MIN.into(), i16::MAX.into()),
        ScalarType::UShort => (0.0, u16::MAX.into()),
        ScalarType::Int => (i32::MIN.into(), i32::MAX.into()),
        ScalarType::UInt => (0.0, u32::MAX.into()),
    };
    let v = match word.parse::<i64>() {
        Ok(v) => v as f64,
        Err(_) => match word.parse::<f64>() {
            Ok(v) if v.fract() == 0.0 => v,
            _ => return Err(format!("'{word}' is not an integer")),
        },
    };
    if !(low..=high).contains(&v) {
        return Err(format!("{word} is outside the type's range {low}..={high}"));
    }
    Ok(v)
}
