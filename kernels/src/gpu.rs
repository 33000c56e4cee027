//! Device acquisition for the kernels, with one typed error for everything
//! that can go wrong between "is there a GPU stack" and "the kernel ran".

use std::fmt;

/// The compute API a device is driven through.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Api {
    /// WGSL through wgpu (Vulkan, Metal, DX12).
    Wgpu,
    /// OpenCL C through ocl (any OpenCL 1.2 ICD: GPU drivers, pocl).
    OpenCl,
}

impl Api {
    pub fn name(self) -> &'static str {
        match self {
            Api::Wgpu => "wgpu",
            Api::OpenCl => "opencl",
        }
    }

    /// Cargo feature of splitstream-kernels that builds this API's host glue.
    pub fn feature(self) -> &'static str {
        match self {
            Api::Wgpu => "wgpu",
            Api::OpenCl => "opencl",
        }
    }

    /// Whether this build has the host glue for the API.
    pub fn compiled(self) -> bool {
        match self {
            Api::Wgpu => cfg!(feature = "wgpu"),
            Api::OpenCl => cfg!(feature = "opencl"),
        }
    }
}

impl fmt::Display for Api {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// Why a GPU backend could not be used or failed.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum GpuError {
    /// This build lacks the API's host glue (cargo feature off).
    NotCompiled { api: Api },
    /// No adapter / platform / device was found.
    NoAdapter { api: Api, detail: String },
    /// An adapter was found but no device could be opened on it.
    NoDevice { api: Api, detail: String },
    /// The data does not fit the device's limits.
    TooLarge {
        api: Api,
        what: &'static str,
        bytes: u64,
        limit: u64,
    },
    /// Compiling, launching or reading back a kernel failed.
    Kernel { api: Api, detail: String },
}

impl GpuError {
    pub fn api(&self) -> Api {
        match self {
            GpuError::NotCompiled { api }
            | GpuError::NoAdapter { api, .. }
            | GpuError::NoDevice { api, .. }
            | GpuError::TooLarge { api, .. }
            | GpuError::Kernel { api, .. } => *api,
        }
    }

    /// Whether the backend is simply not there (as opposed to failing):
    /// tests skip on these outside CI.
    pub fn is_unavailable(&self) -> bool {
        matches!(
            self,
            GpuError::NotCompiled { .. } | GpuError::NoAdapter { .. } | GpuError::NoDevice { .. }
        )
    }
}

impl fmt::Display for GpuError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            GpuError::NotCompiled { api } => write!(
                f,
                "backend {api} is not in this build (rebuild with cargo feature `{}`)",
                api.feature()
            ),
            GpuError::NoAdapter { api, detail } => {
                write!(f, "backend {api}: no adapter found ({detail})")
            }
            GpuError::NoDevice { api, detail } => {
                write!(f, "backend {api}: could not open a device ({detail})")
            }
            GpuError::TooLarge {
                api,
                what,
                bytes,
                limit,
            } => write!(
                f,
                "backend {api}: {what} needs {bytes} bytes, over the device limit of {limit}"
            ),
            GpuError::Kernel { api, detail } => write!(f, "backend {api}: {detail}"),
        }
    }
}

impl std::error::Error for GpuError {}

/// What was opened, for reports ("llvmpipe (LLVM 15, 256 bits), Vulkan, Cpu").
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct DeviceInfo {
    pub api: Api,
    pub name: String,
    /// Driver / backend / device type, free text.
    pub detail: String,
}

impl fmt::Display for DeviceInfo {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}: {} ({})", self.api, self.name, self.detail)
    }
}

#[cfg(feature = "wgpu")]
pub use wgpu_context::{WgpuContext, open_wgpu};

#[cfg(feature = "wgpu")]
mod wgpu_context {
    use super::{Api, DeviceInfo, GpuError};

    /// An opened wgpu device and queue.
    pub struct WgpuContext {
        pub device: wgpu::Device,
        pub queue: wgpu::Queue,
        pub info: DeviceInfo,
        pub limits: wgpu::Limits,
    }

    /// Opens the first adapter wgpu offers, honouring the WGPU_* variables
    /// (WGPU_BACKEND=vulkan makes a missing driver fail loudly instead of
    /// falling back to GL). Asks for the adapter's own limits, since big
    /// meshes exceed the defaults (128 MiB per storage binding).
    pub fn open_wgpu() -> Result<WgpuContext, GpuError> {
        let instance =
            wgpu::Instance::new(wgpu::InstanceDescriptor::new_without_display_handle_from_env());
        let options = wgpu::RequestAdapterOptions {
            power_preference: wgpu::PowerPreference::HighPerformance,
            ..Default::default()
        };
        let adapter = pollster::block_on(instance.request_adapter(&options)).map_err(|e| {
            GpuError::NoAdapter {
                api: Api::Wgpu,
                detail: e.to_string(),
            }
        })?;
        let a = adapter.get_info();
        let limits = adapter.limits();
        let descriptor = wgpu::DeviceDescriptor {
            label: Some("splitstream"),
            required_limits: limits.clone(),
            ..Default::default()
        };
        let (device, queue) =
            pollster::block_on(adapter.request_device(&descriptor)).map_err(|e| {
                GpuError::NoDevice {
                    api: Api::Wgpu,
                    detail: e.to_string(),
                }
            })?;
        Ok(WgpuContext {
            device,
            queue,
            info: DeviceInfo {
                api: Api::Wgpu,
                name: a.name.clone(),
                detail: format!("{:?}, {:?}, {}", a.backend, a.device_type, a.driver_info),
            },
            limits,
        })
    }
}

#[cfg(feature = "opencl")]
pub use ocl_context::{OclContext, open_opencl};

#[cfg(feature = "opencl")]
mod ocl_context {
    use super::{Api, DeviceInfo, GpuError};

    /// An opened OpenCL context and queue on one device.
    pub struct OclContext {
        pub context: ocl::Context,
        pub device: ocl::Device,
        pub queue: ocl::Queue,
        pub info: DeviceInfo,
    }

    fn no_adapter(detail: impl ToString) -> GpuError {
        GpuError::NoAdapter {
            api: Api::OpenCl,
            detail: detail.to_string(),
        }
    }

    /// Opens the first device of the first platform that has one (GPUs
    /// before other device types).
    pub fn open_opencl() -> Result<OclContext, GpuError> {
        // core::get_platform_ids returns an error (Platform::list panics)
        // when the ICD loader finds no platform.
        let ids = ocl::core::get_platform_ids().map_err(|e| {
            no_adapter(format!(
                "no OpenCL platform: {}",
                e.to_string().lines().next().unwrap_or("")
            ))
        })?;
        let mut found = None;
        for gpu_only in [true, false] {
            for &id in &ids {
                let platform = ocl::Platform::new(id);
                let kind = gpu_only.then_some(ocl::flags::DEVICE_TYPE_GPU);
                if let Ok(devices) = ocl::Device::list(platform, kind)
                    && let Some(&device) = devices.first()
                {
                    found = Some((platform, device));
                    break;
                }
            }
            if found.is_some() {
                break;
            }
        }
        let (platform, device) =
            found.ok_or_else(|| no_adapter(format!("{} platforms, no device", ids.len())))?;
        let no_device = |e: ocl::Error| GpuError::NoDevice {
            api: Api::OpenCl,
            detail: e.to_string(),
        };
        let context = ocl::Context::builder()
            .platform(platform)
            .devices(device)
            .build()
            .map_err(no_device)?;
        let queue = ocl::Queue::new(&context, device, None).map_err(no_device)?;
        let info = DeviceInfo {
            api: Api::OpenCl,
            name: device.name().unwrap_or_default(),
            detail: format!(
                "{} {}",
                platform.name().unwrap_or_default(),
                platform.version().unwrap_or_default()
            ),
        };
        Ok(OclContext {
            context,
            device,
            queue,
            info,
        })
    }
}

/// Opens a device of `api` and says what it is (for reports and for
/// checking availability up front).
pub fn describe(api: Api) -> Result<DeviceInfo, GpuError> {
    match api {
        #[cfg(feature = "wgpu")]
        Api::Wgpu => open_wgpu().map(|c| c.info),
        #[cfg(feature = "opencl")]
        Api::OpenCl => open_opencl().map(|c| c.info),
        #[allow(unreachable_patterns)]
        api => Err(GpuError::NotCompiled { api }),
    }
}
