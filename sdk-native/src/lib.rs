//! Native SDK for splitstream clients.
//!
//! * [`Session`]: a progressive decoder owning its memory (sized from the
//!   stream header once), fed level by level and decoded level by level or
//!   round by round; what sdk-wasm and the C ABI wrap.
//! * [`grid_tile`]: a client-side simplifier for regular elevation tiles
//!   (quad-tree split and merge with edge straightening, after Rishe et al.,
//!   "Mesh Simplification Algorithm for Online 3D GIS", 2005).
//! * [`threaded`]: one stream decoded on two cores, the split records
//!   read on a second thread.
//! * [`view`]: how many levels a viewer needs, from each level's geometric
//!   error projected on screen ([`Session::level_for_screen_error`]).
//! * [`gpu`] (feature `gpu`): the refinement rounds on a wgpu device,
//!   checked round by round against decoder-core.
//! * [`ffi`]: the C ABI (header `include/splitstream.h`). `unsafe` code is
//!   denied everywhere else in the crate.
#![deny(unsafe_code)]

pub mod ffi;
#[cfg(feature = "gpu")]
pub mod gpu;
pub mod grid_tile;
pub mod threaded;
pub mod view;

pub use ffi::{Refusal, Session};
pub use view::{ScreenView, ViewError};

// The README's Rust examples run as doctests, so they follow the API (one
// of them uses the `gpu` module, which the workspace's tests enable).
#[cfg(all(doctest, feature = "gpu"))]
#[doc = include_str!("../README.md")]
struct ReadmeExamples;
