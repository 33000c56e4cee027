//! The device GPU decoding runs on: a wgpu adapter (WGSL kernels) or, with
//! the `opencl` feature, an OpenCL device (the OpenCL C port).

use splitstream_kernels::gpu::{Api, DeviceInfo, GpuError, WgpuContext, open_wgpu};

/// An opened device of one compute API.
pub enum GpuDevice {
    /// Boxed: a wgpu context is several times larger than an OpenCL one.
    Wgpu(Box<WgpuContext>),
    #[cfg(feature = "opencl")]
    OpenCl(splitstream_kernels::gpu::OclContext),
}

impl GpuDevice {
    /// Opens the first device of `api` (wgpu honours the WGPU_* variables).
    pub fn open(api: Api) -> Result<GpuDevice, GpuError> {
        match api {
            Api::Wgpu => open_wgpu().map(|ctx| GpuDevice::Wgpu(Box::new(ctx))),
            #[cfg(feature = "opencl")]
            Api::OpenCl => splitstream_kernels::gpu::open_opencl().map(GpuDevice::OpenCl),
            #[cfg(not(feature = "opencl"))]
            Api::OpenCl => Err(GpuError::NotCompiled { api }),
        }
    }

    /// What was opened.
    pub fn info(&self) -> &DeviceInfo {
        match self {
            GpuDevice::Wgpu(ctx) => &ctx.info,
            #[cfg(feature = "opencl")]
            GpuDevice::OpenCl(ctx) => &ctx.info,
        }
    }
}
