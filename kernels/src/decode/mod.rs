//! The decoder's refinement rounds on the GPU (SPEC §7; Cellier et al. 2012,
//! §3), one WGSL file per step:
//!
//! 1. `candidates.wgsl`: vertices with deficit 0, appended with an atomic
//!    counter (schedule `every-vertex`, format 3.6: every vertex below n, at
//!    its own index);
//! 2. `bitonic_sort.wgsl`: the candidates sorted ascending, the order the
//!    stream's flags follow (skipped under `every-vertex`: already sorted);
//! 3. `prefix_number.wgsl`: exclusive prefix sums number the flagged splits
//!    (C = n + j) and their new triangles (1 or 2 per split);
//! 4. `split_apply.wgsl`: canonical ring walk (decoder-core's ring.rs), the
//!    checks of SPEC §7.2-§7.5, then the corner rewrites and new triangles
//!    with their adjacency (decoder-core's split.rs), wing deficits (or
//!    valences), positions.
//!
//! The host ([`refine`], feature `wgpu`) supplies per round only what the
//! stream says: the candidate count, one flag bit per candidate and the
//! flagged splits' records with resolved positions. Without features only
//! the sources, layouts and the host-side adjacency builder are compiled.

pub mod adjacency;
pub mod device_state;
pub mod host;
pub mod layout;
#[cfg(feature = "opencl")]
pub mod ocl_refine;
#[cfg(feature = "wgpu")]
pub mod refine;
pub mod schedule;
pub mod sources;

pub use layout::{GpuRecord, KernelFault, Schedule};
pub use sources::DecodeModule;
