//! Errors raised while reading an input file.
//!
//! Every message is a single line that starts with the file name, so a
//! command-line user can jump straight to the problem (`bunny.off: line 12:
//! ...`). Messages coming from the parsing crates are flattened to one line.

use std::fmt;
use std::io;

/// Every extension `read_mesh` understands, for the unknown-extension message.
pub const SUPPORTED_EXTENSIONS: &[&str] = &[
    "ply", "obj", "off", "gltf", "glb", "stl", "tif", "tiff", "asc", "npy", "npz",
];

/// The extensions `read_grid` understands (elevation grids only).
pub const GRID_EXTENSIONS: &[&str] = &["tif", "tiff", "asc", "npy", "npz"];

/// Why a file could not be turned into a [`crate::Mesh`].
#[derive(Debug)]
pub enum InputError {
    /// The file could not be opened or read.
    Io { file: String, source: io::Error },
    /// The file name has no extension the reader knows; `supported` lists
    /// those it does ([`SUPPORTED_EXTENSIONS`] for meshes,
    /// [`GRID_EXTENSIONS`] for grids).
    UnknownExtension {
        file: String,
        extension: String,
        supported: &'static [&'static str],
    },
    /// A text format failed at a known line (1-based).
    Line {
        file: String,
        line: usize,
        message: String,
    },
    /// A specific element (`face 12`, `vertex 3`, `row 7`) is invalid.
    Element {
        file: String,
        element: String,
        message: String,
    },
    /// The file is malformed in a way that has no line or element to point at
    /// (bad header, truncated binary data, error reported by a parsing crate).
    Malformed { file: String, message: String },
    /// The file is well formed but uses a feature this reader does not support.
    Unsupported { file: String, feature: String },
    /// An `.npz` archive has no array with the requested name.
    NpzArrayMissing {
        file: String,
        name: String,
        available: Vec<String>,
    },
    /// The file describes more vertices than a `u32` index can address.
    TooLarge { file: String, vertices: u64 },
}

impl InputError {
    pub(crate) fn io(file: &str, source: io::Error) -> Self {
        InputError::Io {
            file: file.to_owned(),
            source,
        }
    }

    pub(crate) fn line(file: &str, line: usize, message: impl Into<String>) -> Self {
        InputError::Line {
            file: file.to_owned(),
            line,
            message: one_line(&message.into()),
        }
    }

    pub(crate) fn element(
        file: &str,
        element: impl Into<String>,
        message: impl Into<String>,
    ) -> Self {
        InputError::Element {
            file: file.to_owned(),
            element: element.into(),
            message: one_line(&message.into()),
        }
    }

    pub(crate) fn malformed(file: &str, message: impl Into<String>) -> Self {
        InputError::Malformed {
            file: file.to_owned(),
            message: one_line(&message.into()),
        }
    }

    pub(crate) fn unsupported(file: &str, feature: impl Into<String>) -> Self {
        InputError::Unsupported {
            file: file.to_owned(),
            feature: one_line(&feature.into()),
        }
    }

    /// The file name the error is about, as it was given to `read_mesh`.
    pub fn file(&self) -> &str {
        match self {
            InputError::Io { file, .. }
            | InputError::UnknownExtension { file, .. }
            | InputError::Line { file, .. }
            | InputError::Element { file, .. }
            | InputError::Malformed { file, .. }
            | InputError::Unsupported { file, .. }
            | InputError::NpzArrayMissing { file, .. }
            | InputError::TooLarge { file, .. } => file,
        }
    }
}

/// Collapses all whitespace runs (crate messages contain `\n\t`) to one space.
pub(crate) fn one_line(message: &str) -> String {
    message.split_whitespace().collect::<Vec<_>>().join(" ")
}

impl fmt::Display for InputError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            InputError::Io { file, source } => {
                write!(
                    f,
                    "{file}: cannot read file: {}",
                    one_line(&source.to_string())
                )
            }
            InputError::UnknownExtension {
                file,
                extension,
                supported,
            } => {
                let list: Vec<String> = supported.iter().map(|e| format!(".{e}")).collect();
                if extension.is_empty() {
                    write!(
                        f,
                        "{file}: no file extension; supported: {}",
                        list.join(", ")
                    )
                } else {
                    write!(
                        f,
                        "{file}: unsupported extension '.{extension}'; supported: {}",
                        list.join(", ")
                    )
                }
            }
            InputError::Line {
                file,
                line,
                message,
            } => write!(f, "{file}: line {line}: {message}"),
            InputError::Element {
                file,
                element,
                message,
            } => write!(f, "{file}: {element}: {message}"),
            InputError::Malformed { file, message } => write!(f, "{file}: {message}"),
            InputError::Unsupported { file, feature } => {
                write!(f, "{file}: unsupported: {feature}")
            }
            InputError::NpzArrayMissing {
                file,
                name,
                available,
            } => write!(
                f,
                "{file}: no array named '{name}' in the archive (available: {})",
                if available.is_empty() {
                    "none".to_owned()
                } else {
                    available.join(", ")
                }
            ),
            InputError::TooLarge { file, vertices } => write!(
                f,
                "{file}: {vertices} vertices exceed the 32-bit index limit ({})",
                u32::MAX
            ),
        }
    }
}

impl std::error::Error for InputError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            InputError::Io { source, .. } => Some(source),
            _ => None,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn messages_are_single_line_and_name_the_file() {
        let errors = [
            InputError::io(
                "a.ply",
                io::Error::new(io::ErrorKind::NotFound, "gone\nreally"),
            ),
            InputError::UnknownExtension {
                file: "a.stl".into(),
                extension: "stl".into(),
                supported: SUPPORTED_EXTENSIONS,
            },
            InputError::line("bunny.off", 12, "expected 3 coordinates, found 2"),
            InputError::element("a.ply", "face 3", "bad\n\tthing"),
            InputError::malformed("a.ply", "x"),
            InputError::unsupported("a.off", "binary OFF"),
            InputError::NpzArrayMissing {
                file: "a.npz".into(),
                name: "z".into(),
                available: vec!["a".into()],
            },
            InputError::TooLarge {
                file: "a.npy".into(),
                vertices: 1 << 40,
            },
        ];
        for e in &errors {
            let s = e.to_string();
            assert!(!s.contains('\n') && !s.contains('\t'), "{s}");
            assert!(s.starts_with(e.file()), "{s}");
        }
        assert_eq!(
            errors[2].to_string(),
            "bunny.off: line 12: expected 3 coordinates, found 2"
        );
        assert!(errors[1].to_string().contains(".ply, .obj, .off"));
    }
}
