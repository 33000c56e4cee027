//! Compute kernels of splitstream and their host glue.
//!
//! * [`encode`]: the encoder's parallel simplification steps (Cellier et
//!   al. 2012, §2) as WGSL and OpenCL C kernels: quadric init, best edge per
//!   vertex, reciprocal local-minimum selection, and the upload of the
//!   topology the CPU changed.
//! * [`decode`]: the decoder's refinement rounds (Cellier et al. 2012, §3)
//!   as WGSL kernels: candidates by atomic append, bitonic sort, prefix
//!   numbering of new vertices and triangles, parallel split apply.
//! * [`gpu`]: device acquisition with typed errors (features `wgpu`, `opencl`).
//!
//! Without features the crate only exposes the kernel sources and the
//! `bytemuck` buffer layouts, so tools can validate or embed the kernels
//! without pulling in a GPU stack.

pub mod decode;
pub mod encode;
pub mod gpu;
