//! Native SDK for splitstream streams (Rust API and C ABI).
//!
//! Not built yet: this crate is an empty placeholder in the fixed workspace
//! layout. It exports nothing, so nothing can mistake it for a working SDK.
