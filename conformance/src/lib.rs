//! The splitstream conformance suite: a versioned set of test vectors
//! (`vectors/<version>/`, made by [`generate`]), the protocol a decoder under
//! test speaks ([`protocol`]), the decoders compiled in ([`builtin`]) and the
//! runner ([`runner`]). See conformance/README.md.

pub mod builtin;
#[cfg(feature = "gpu")]
pub mod builtin_gpu;
pub mod generate;
pub mod manifest;
pub mod protocol;
pub mod runner;
