//! Browser SDK for splitstream streams: wasm-bindgen bindings of
//! splitstream-sdk-native's progressive decoder ([`StreamDecoder`]) and
//! grid-tile simplifier (`GridSimplifier`, feature `grid`, on by default). `wasm-bindgen` writes the
//! JavaScript glue and the TypeScript `.d.ts`; usage is in README.md.
//!
//! Errors reach JavaScript as exceptions: `Error` objects named
//! `SplitstreamError` with a `class` property (the decoder's conformance
//! error class, decoder-core SPEC §10, or `invalid-argument`, `grid-tile`)
//! and the decoder's one-line message.
//!
//! The methods are plain Rust too (errors as [`SdkError`], arrays as
//! slices), which is what the host unit tests exercise; only the
//! conversions to JavaScript typed arrays and exceptions need a browser or
//! node (tests/node).

mod decoder;
mod error;
#[cfg(feature = "grid")]
mod grid;

pub use decoder::StreamDecoder;
pub use error::SdkError;
#[cfg(feature = "grid")]
pub use grid::{GridSimplifier, TileStats};

#[cfg(test)]
mod tests;
