//! The splitstream encoder.

pub mod baseline;
pub mod corner_table;
pub mod emit;
pub mod input;
pub mod mesh;
pub mod metrics;
mod prefetch;
pub mod quadric;
pub mod quantize;
pub mod simplify;
pub mod spatial_order;

pub use mesh::Mesh;
