//! Native SDK for splitstream clients.
//!
//! So far it holds one piece: [`grid_tile`], a client-side simplifier for
//! regular elevation tiles (quad-tree split and merge with edge
//! straightening, after Rishe et al., "Mesh Simplification Algorithm for
//! Online 3D GIS", 2005). The API is plain Rust; a C ABI will follow.
#![forbid(unsafe_code)]

pub mod grid_tile;
