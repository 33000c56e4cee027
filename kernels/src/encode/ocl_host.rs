//! [`Device`] on OpenCL (ocl): one program from the concatenated `.cl`
//! sources, `u32` buffers per [`Buffer`] (the kernels reinterpret them),
//! one in-order queue, kernel arguments in `Kernel::slots` order.

use std::collections::HashMap;
use std::time::Instant;

use super::layout::Params;
use super::{Buffer, Device, Kernel, OpenTimes};
use crate::gpu::{Api, DeviceInfo, GpuError, OclContext, open_opencl};

/// Work-items per work-group of every dispatch.
const LOCAL_SIZE: usize = 64;

pub struct OclDevice {
    ctx: OclContext,
    program: ocl::Program,
    buffers: HashMap<Buffer, ocl::Buffer<u32>>,
    max_alloc: u64,
    opened: OpenTimes,
}

fn kernel_error(what: &str, e: impl ToString) -> GpuError {
    let text = e.to_string();
    // ocl errors span many lines (build logs); keep them, prefixed.
    GpuError::Kernel {
        api: Api::OpenCl,
        detail: format!("{what}: {}", text.trim()),
    }
}

/// Builds the encoder's OpenCL program on `ctx`'s device.
pub fn build_program(ctx: &OclContext) -> Result<ocl::Program, GpuError> {
    ocl::Program::builder()
        .src(super::sources::opencl_program())
        .devices(ctx.device)
        .cmplr_opt("-cl-std=CL1.2")
        .build(&ctx.context)
        .map_err(|e| kernel_error("building the OpenCL program", e))
}

impl OclDevice {
    pub fn new(n: usize, corners: usize) -> Result<OclDevice, GpuError> {
        let started = Instant::now();
        let ctx = open_opencl()?;
        let context = started.elapsed();
        let program = build_program(&ctx)?;
        let compile = started.elapsed() - context;
        let max_alloc = match ctx.device.info(ocl::enums::DeviceInfo::MaxMemAllocSize) {
            Ok(ocl::enums::DeviceInfoResult::MaxMemAllocSize(b)) => b,
            _ => u64::MAX,
        };
        let mut device = OclDevice {
            ctx,
            program,
            buffers: HashMap::new(),
            max_alloc,
            opened: OpenTimes {
                context,
                compile,
                ..OpenTimes::default()
            },
        };
        for buffer in Buffer::ALL {
            device.allocate(buffer, buffer.words(n, corners))?;
        }
        device.opened.buffers = started.elapsed() - context - compile;
        Ok(device)
    }

    fn allocate(&mut self, buffer: Buffer, words: usize) -> Result<(), GpuError> {
        let bytes = 4 * words as u64;
        if bytes > self.max_alloc {
            return Err(GpuError::TooLarge {
                api: Api::OpenCl,
                what: "a mesh buffer",
                bytes,
                limit: self.max_alloc,
            });
        }
        let b = ocl::Buffer::<u32>::builder()
            .queue(self.ctx.queue.clone())
            .len(words.max(4))
            .fill_val(0)
            .build()
            .map_err(|e| kernel_error("allocating a buffer", e))?;
        self.buffers.insert(buffer, b);
        Ok(())
    }
}

impl Device for OclDevice {
    fn info(&self) -> &DeviceInfo {
        &self.ctx.info
    }
    fn open_times(&self) -> OpenTimes {
        self.opened
    }

    fn write(&mut self, buffer: Buffer, words: &[u32]) -> Result<(), GpuError> {
        if words.is_empty() {
            return Ok(());
        }
        if self.buffers[&buffer].len() < words.len() {
            self.allocate(buffer, words.len().next_power_of_two())?;
        }
        self.buffers[&buffer]
            .write(words)
            .len(words.len())
            .enq()
            .map_err(|e| kernel_error("writing a buffer", e))
    }

    fn read_into(&mut self, buffer: Buffer, out: &mut [u32]) -> Result<(), GpuError> {
        if !out.is_empty() {
            let words = out.len();
            self.buffers[&buffer]
                .read(out)
                .len(words)
                .enq()
                .map_err(|e| kernel_error("reading a buffer", e))?;
        }
        Ok(())
    }

    fn zero(&mut self, buffer: Buffer) -> Result<(), GpuError> {
        self.buffers[&buffer]
            .cmd()
            .fill(0, None)
            .enq()
            .map_err(|e| kernel_error("clearing a buffer", e))
    }

    fn run(
        &mut self,
        kernel: Kernel,
        params: &Params,
        items: u32,
        list: Buffer,
    ) -> Result<(), GpuError> {
        if items == 0 {
            return Ok(());
        }
        self.write(
            Buffer::Params,
            bytemuck::cast_slice(std::slice::from_ref(params)),
        )?;
        let mut builder = ocl::Kernel::builder();
        builder
            .program(&self.program)
            .name(kernel.entry())
            .queue(self.ctx.queue.clone())
            // A fixed local size, and a global size rounded up to it (the
            // kernels bound their index): pocl compiles one work-group
            // function per local size, so letting it choose per dispatch
            // recompiles on every new list length.
            .global_work_size((items as usize).next_multiple_of(LOCAL_SIZE))
            .local_work_size(LOCAL_SIZE);
        for &slot in kernel.slots() {
            builder.arg(&self.buffers[&Buffer::for_slot(slot, list)]);
        }
        let k = builder
            .build()
            .map_err(|e| kernel_error(kernel.entry(), e))?;
        // SAFETY: every argument is a live buffer of this context sized for
        // the mesh, and each kernel bounds its indices by the counts in Params.
        unsafe { k.enq() }.map_err(|e| kernel_error(kernel.entry(), e))
    }
}
