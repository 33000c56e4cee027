//! The splitstream encoder.

pub mod mesh;
pub mod quadric;

pub use mesh::Mesh;
