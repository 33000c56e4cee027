//! Errors of the bindings and how they become JavaScript exceptions.

use std::fmt;

use splitstream_decoder_core::Error;
#[cfg(feature = "grid")]
use splitstream_sdk_native::grid_tile::GridTileError;
use wasm_bindgen::JsValue;

/// A failure: a class (for programs) and a one-line message (for people).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct SdkError {
    /// A decoder conformance class (`truncated`, `checksum-mismatch`, …,
    /// `api-misuse`), `invalid-argument` or `grid-tile`.
    pub class: &'static str,
    pub message: String,
}

impl SdkError {
    pub(crate) fn argument(message: impl Into<String>) -> SdkError {
        SdkError {
            class: "invalid-argument",
            message: message.into(),
        }
    }
}

impl From<Error> for SdkError {
    fn from(e: Error) -> Self {
        SdkError {
            class: e.class(),
            message: e.to_string(),
        }
    }
}

#[cfg(feature = "grid")]
impl From<GridTileError> for SdkError {
    fn from(e: GridTileError) -> Self {
        SdkError {
            class: "grid-tile",
            message: e.to_string(),
        }
    }
}

impl fmt::Display for SdkError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}: {}", self.class, self.message)
    }
}

impl std::error::Error for SdkError {}

/// A JavaScript `Error` named `SplitstreamError`, with `class` set.
impl From<SdkError> for JsValue {
    fn from(e: SdkError) -> JsValue {
        let error = js_sys::Error::new(&e.message);
        error.set_name("SplitstreamError");
        // Setting a property on a fresh Error object cannot fail.
        let _ = js_sys::Reflect::set(&error, &"class".into(), &e.class.into());
        error.into()
    }
}
