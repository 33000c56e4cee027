//! WGSL and OpenCL compute kernels for the splitstream encoder and decoder.
//!
//! Not built yet: this crate is an empty placeholder in the fixed workspace
//! layout. It exports nothing, so nothing can mistake it for working kernels.
