//! Where the simplification's data-parallel passes run.

use std::fmt;

pub use splitstream_kernels::gpu::GpuError;

/// The device that runs the simplifier's data-parallel passes.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Backend {
    /// Everything on the CPU threads (rayon), in f64.
    #[default]
    Cpu,
    /// Quadric init, best edge and selection as WGSL kernels through wgpu;
    /// topology on the CPU (see `simplify::gpu`).
    Wgpu,
    /// The same kernels in OpenCL C through ocl.
    OpenCl,
}

impl Backend {
    pub const ALL: [Backend; 3] = [Backend::Cpu, Backend::Wgpu, Backend::OpenCl];

    pub fn name(self) -> &'static str {
        match self {
            Backend::Cpu => "cpu",
            Backend::Wgpu => "wgpu",
            Backend::OpenCl => "opencl",
        }
    }

    /// The kernels API of a GPU backend (`None` for the CPU).
    pub fn api(self) -> Option<splitstream_kernels::gpu::Api> {
        use splitstream_kernels::gpu::Api;
        match self {
            Backend::Cpu => None,
            Backend::Wgpu => Some(Api::Wgpu),
            Backend::OpenCl => Some(Api::OpenCl),
        }
    }
}

impl fmt::Display for Backend {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl std::str::FromStr for Backend {
    type Err = String;
    fn from_str(s: &str) -> Result<Backend, String> {
        Backend::ALL
            .into_iter()
            .find(|b| b.name().eq_ignore_ascii_case(s))
            .ok_or_else(|| format!("unknown backend {s:?} (cpu, wgpu, opencl)"))
    }
}
