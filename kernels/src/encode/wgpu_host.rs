//! [`Device`] on wgpu: one pipeline per entry point (layouts derived from
//! the WGSL), storage buffers per [`Buffer`], one submission per dispatch
//! (each dispatch has its own parameters in the one uniform buffer, and
//! `write_buffer` is ordered before the next submission).

use std::collections::HashMap;
use std::time::Instant;

use super::layout::{GROUP, Params};
use super::{Buffer, Device, Kernel, OpenTimes, WgslModule};
use crate::gpu::{Api, DeviceInfo, GpuError, WgpuContext, open_wgpu};

pub struct WgpuDevice {
    ctx: WgpuContext,
    pipelines: HashMap<Kernel, wgpu::ComputePipeline>,
    buffers: HashMap<Buffer, wgpu::Buffer>,
    staging: Option<wgpu::Buffer>,
    opened: OpenTimes,
}

fn kernel_error(detail: impl ToString) -> GpuError {
    GpuError::Kernel {
        api: Api::Wgpu,
        detail: detail.to_string(),
    }
}

impl WgpuDevice {
    pub fn new(n: usize, corners: usize) -> Result<WgpuDevice, GpuError> {
        let started = Instant::now();
        let ctx = open_wgpu()?;
        let context = started.elapsed();
        let scope = ctx.device.push_error_scope(wgpu::ErrorFilter::Validation);
        let mut modules = HashMap::new();
        for module in WgslModule::ALL {
            let source = module.source();
            let shader = ctx
                .device
                .create_shader_module(wgpu::ShaderModuleDescriptor {
                    label: Some(module.name()),
                    source: wgpu::ShaderSource::Wgsl(source.into()),
                });
            modules.insert(module, shader);
        }
        let mut pipelines = HashMap::new();
        for kernel in Kernel::ALL {
            let pipeline = ctx
                .device
                .create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                    label: Some(kernel.entry()),
                    layout: None,
                    module: &modules[&kernel.module()],
                    entry_point: Some(kernel.entry()),
                    compilation_options: Default::default(),
                    cache: None,
                });
            pipelines.insert(kernel, pipeline);
        }
        if let Some(e) = pollster::block_on(scope.pop()) {
            return Err(kernel_error(format!("pipeline creation: {e}")));
        }
        let compile = started.elapsed() - context;
        let mut device = WgpuDevice {
            ctx,
            pipelines,
            buffers: HashMap::new(),
            staging: None,
            opened: OpenTimes {
                context,
                compile,
                ..OpenTimes::default()
            },
        };
        for buffer in Buffer::ALL {
            let bytes = 4 * buffer.words(n, corners) as u64;
            device.allocate(buffer, bytes)?;
        }
        device.opened.buffers = started.elapsed() - context - compile;
        Ok(device)
    }

    fn allocate(&mut self, buffer: Buffer, bytes: u64) -> Result<(), GpuError> {
        let limits = &self.ctx.limits;
        let (usage, limit) = if buffer == Buffer::Params {
            (
                wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
                limits.max_uniform_buffer_binding_size,
            )
        } else {
            (
                wgpu::BufferUsages::STORAGE
                    | wgpu::BufferUsages::COPY_DST
                    | wgpu::BufferUsages::COPY_SRC,
                limits
                    .max_storage_buffer_binding_size
                    .min(limits.max_buffer_size),
            )
        };
        if bytes > limit {
            return Err(GpuError::TooLarge {
                api: Api::Wgpu,
                what: "a mesh buffer",
                bytes,
                limit,
            });
        }
        let b = self.ctx.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("splitstream"),
            size: bytes.max(16),
            usage,
            mapped_at_creation: false,
        });
        self.buffers.insert(buffer, b);
        Ok(())
    }

    fn submit(&self, encoder: wgpu::CommandEncoder) {
        self.ctx.queue.submit([encoder.finish()]);
    }

    fn encoder(&self) -> wgpu::CommandEncoder {
        self.ctx
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor { label: None })
    }
}

impl Device for WgpuDevice {
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
        let bytes = 4 * words.len() as u64;
        if self.buffers[&buffer].size() < bytes {
            self.allocate(buffer, bytes.next_power_of_two())?;
        }
        self.ctx
            .queue
            .write_buffer(&self.buffers[&buffer], 0, bytemuck::cast_slice(words));
        Ok(())
    }

    fn read_into(&mut self, buffer: Buffer, out: &mut [u32]) -> Result<(), GpuError> {
        if out.is_empty() {
            return Ok(());
        }
        let bytes = 4 * out.len() as u64;
        if self.staging.as_ref().is_none_or(|s| s.size() < bytes) {
            self.staging = Some(self.ctx.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("splitstream readback"),
                size: bytes.next_power_of_two(),
                usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            }));
        }
        let staging = self.staging.as_ref().expect("allocated above");
        let mut encoder = self.encoder();
        encoder.copy_buffer_to_buffer(&self.buffers[&buffer], 0, staging, 0, bytes);
        self.submit(encoder);
        let (send, receive) = std::sync::mpsc::channel();
        staging.map_async(wgpu::MapMode::Read, 0..bytes, move |r| {
            let _ = send.send(r);
        });
        self.ctx
            .device
            .poll(wgpu::PollType::wait_indefinitely())
            .map_err(kernel_error)?;
        receive
            .recv()
            .map_err(kernel_error)?
            .map_err(|e| kernel_error(format!("readback: {e}")))?;
        {
            let view = staging
                .get_mapped_range(0..bytes)
                .map_err(|e| kernel_error(format!("readback: {e}")))?;
            out.copy_from_slice(bytemuck::cast_slice(&view));
        }
        staging.unmap();
        Ok(())
    }

    fn zero(&mut self, buffer: Buffer) -> Result<(), GpuError> {
        let mut encoder = self.encoder();
        encoder.clear_buffer(&self.buffers[&buffer], 0, None);
        self.submit(encoder);
        Ok(())
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
        self.ctx.queue.write_buffer(
            &self.buffers[&Buffer::Params],
            0,
            bytemuck::bytes_of(params),
        );
        let pipeline = &self.pipelines[&kernel];
        let entries: Vec<wgpu::BindGroupEntry> = kernel
            .slots()
            .iter()
            .map(|&slot| wgpu::BindGroupEntry {
                binding: slot as u32,
                resource: self.buffers[&Buffer::for_slot(slot, list)].as_entire_binding(),
            })
            .collect();
        let bind_group = self
            .ctx
            .device
            .create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some(kernel.entry()),
                layout: &pipeline.get_bind_group_layout(0),
                entries: &entries,
            });
        let max = self.ctx.limits.max_compute_workgroups_per_dimension.max(1);
        let groups = items.div_ceil(GROUP);
        let (x, y) = (groups.min(max), groups.div_ceil(max));
        let mut encoder = self.encoder();
        {
            let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some(kernel.entry()),
                timestamp_writes: None,
            });
            pass.set_pipeline(pipeline);
            pass.set_bind_group(0, &bind_group, &[]);
            pass.dispatch_workgroups(x, y, 1);
        }
        self.submit(encoder);
        Ok(())
    }
}
