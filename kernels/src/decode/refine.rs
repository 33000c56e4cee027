//! Host glue (feature `wgpu`): buffers, pipelines and the dispatch schedule
//! of one refinement round, and the read-back of the state.
//!
//! A round is recorded into one compute pass and submitted without waiting:
//! the host supplies only what the stream says (candidate count, one flag
//! bit per candidate, the flagged splits' records) and the level's triangle
//! limit; the vertex and triangle counts live on the device. Faults found by
//! the kernels are read back with the state ([`Refiner::snapshot`]).

use std::sync::mpsc;

use super::device_state::{DeviceBuffer, DeviceState, PARAM_SLOTS, Rounds};
pub use super::host::{BaseMesh, RefineError, RoundInput, Schedule, Snapshot};
use super::layout::*;
use super::schedule::Entry;
use super::sources::DecodeModule;
use crate::gpu::{Api, GpuError, WgpuContext};

fn kernel_error(detail: impl ToString) -> RefineError {
    super::host::kernel_error(Api::Wgpu, detail)
}

/// Binding of the parameters (common.wgsl); [`DeviceBuffer`] `b` is bound
/// at `1 + b as u32`.
const PARAMS_BINDING: u32 = 0;

/// Every entry point's pipeline, indexed like [`Entry::ALL`].
struct Pipelines(Vec<wgpu::ComputePipeline>);

impl Pipelines {
    fn get(&self, entry: Entry) -> &wgpu::ComputePipeline {
        &self.0[entry as usize]
    }
}

/// The decoder's refinement on a wgpu device.
pub struct Refiner<'c> {
    ctx: &'c WgpuContext,
    params: wgpu::Buffer,
    /// Indexed by [`DeviceBuffer`].
    buffers: Vec<wgpu::Buffer>,
    bind_group: wgpu::BindGroup,
    pipelines: Pipelines,
    rounds: Rounds,
}

impl<'c> Refiner<'c> {
    /// Uploads `base` into buffers sized for `vertex_capacity` vertices and
    /// `triangle_capacity` triangles (the stream's header capacities), for
    /// a stream of the schedule `split-valences`.
    pub fn new(
        ctx: &'c WgpuContext,
        base: BaseMesh<'_>,
        vertex_capacity: u32,
        triangle_capacity: u32,
    ) -> Result<Refiner<'c>, RefineError> {
        Refiner::with_schedule(
            ctx,
            base,
            Schedule::SplitValences,
            vertex_capacity,
            triangle_capacity,
        )
    }

    /// [`Refiner::new`] for a stream of `schedule` (SPEC §3.2): `base`'s
    /// deficits are then what decoder-core's state holds under it (§6.2).
    pub fn with_schedule(
        ctx: &'c WgpuContext,
        base: BaseMesh<'_>,
        schedule: Schedule,
        vertex_capacity: u32,
        triangle_capacity: u32,
    ) -> Result<Refiner<'c>, RefineError> {
        let state = DeviceState::new(base, schedule, vertex_capacity, triangle_capacity)?;
        let device = &ctx.device;
        // Each buffer is bound whole: it must fit the device's binding limit
        // (lavapipe: 128 MiB, so about 2.8 M splits of records), or creating
        // the bind group fails validation.
        let limit = ctx
            .limits
            .max_storage_buffer_binding_size
            .min(ctx.limits.max_buffer_size);
        let mut buffers = Vec::with_capacity(DeviceBuffer::ALL.len());
        for b in DeviceBuffer::ALL {
            let bytes = 4 * state.words[b as usize];
            if bytes > limit {
                return Err(GpuError::TooLarge {
                    api: Api::Wgpu,
                    what: b.what(),
                    bytes,
                    limit,
                }
                .into());
            }
            // Every binding needs at least one element of its largest struct.
            buffers.push(device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(b.what()),
                size: bytes.max(64).next_multiple_of(16),
                usage: wgpu::BufferUsages::STORAGE
                    | wgpu::BufferUsages::COPY_DST
                    | wgpu::BufferUsages::COPY_SRC,
                mapped_at_creation: false,
            }));
        }
        for (b, words) in &state.uploads {
            ctx.queue
                .write_buffer(&buffers[*b as usize], 0, bytemuck::cast_slice(words));
        }
        let params = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("decode params"),
            size: PARAM_SLOT * PARAM_SLOTS as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let layout = bind_group_layout(device);
        let mut bind_entries: Vec<wgpu::BindGroupEntry> = DeviceBuffer::ALL
            .iter()
            .map(|&b| wgpu::BindGroupEntry {
                binding: 1 + b as u32,
                resource: buffers[b as usize].as_entire_binding(),
            })
            .collect();
        bind_entries.push(wgpu::BindGroupEntry {
            binding: PARAMS_BINDING,
            resource: wgpu::BindingResource::Buffer(wgpu::BufferBinding {
                buffer: &params,
                offset: 0,
                size: wgpu::BufferSize::new(core::mem::size_of::<Params>() as u64),
            }),
        });
        let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("decode"),
            layout: &layout,
            entries: &bind_entries,
        });
        let pipelines = pipelines(device, &layout);
        Ok(Refiner {
            ctx,
            params,
            buffers,
            bind_group,
            pipelines,
            rounds: state.rounds,
        })
    }

    /// Vertex count after the rounds submitted so far (assuming they passed).
    pub fn vertex_count(&self) -> u32 {
        self.rounds.vertex_count()
    }

    fn buffer(&self, b: DeviceBuffer) -> &wgpu::Buffer {
        &self.buffers[b as usize]
    }

    /// Records and submits one round; does not wait for it.
    pub fn round(&mut self, input: RoundInput<'_>) -> Result<(), RefineError> {
        let plan = self.rounds.plan(&input)?;
        let queue = &self.ctx.queue;
        if !input.records.is_empty() {
            queue.write_buffer(
                self.buffer(DeviceBuffer::Records),
                0,
                bytemuck::cast_slice(input.records),
            );
        }
        let flag_words = input.candidates.div_ceil(32) as usize;
        if flag_words > 0 {
            queue.write_buffer(
                self.buffer(DeviceBuffer::Flags),
                0,
                bytemuck::cast_slice(&input.flags[..flag_words]),
            );
        }
        let mut slots = vec![0u8; plan.len() * PARAM_SLOT as usize];
        for (i, d) in plan.iter().enumerate() {
            let at = i * PARAM_SLOT as usize;
            slots[at..at + core::mem::size_of::<Params>()]
                .copy_from_slice(bytemuck::bytes_of(&d.params));
        }
        queue.write_buffer(&self.params, 0, &slots);
        let mut encoder = self.ctx.device.create_command_encoder(&Default::default());
        {
            let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("decode round"),
                timestamp_writes: None,
            });
            for (i, d) in plan.iter().enumerate() {
                pass.set_pipeline(self.pipelines.get(d.entry));
                pass.set_bind_group(0, &self.bind_group, &[(i as u64 * PARAM_SLOT) as u32]);
                pass.dispatch_workgroups(d.groups, 1, 1);
            }
        }
        queue.submit([encoder.finish()]);
        self.rounds.submitted(&input);
        Ok(())
    }

    /// Waits for the submitted rounds and reads the state back (with the
    /// adjacency when `adjacency`). Resets the device's fault word, so each
    /// snapshot reports the faults since the previous one.
    pub fn snapshot(&mut self, adjacency: bool) -> Result<Snapshot, RefineError> {
        let counts = self.read_words(self.buffer(DeviceBuffer::Counts), COUNT_WORDS as u64)?;
        let (v, t) = (counts[COUNT_V] as usize, counts[COUNT_T] as usize);
        let fault = KernelFault::from_key(counts[COUNT_ERROR]);
        if fault.is_some() {
            self.ctx.queue.write_buffer(
                self.buffer(DeviceBuffer::Counts),
                4 * COUNT_ERROR as u64,
                bytemuck::bytes_of(&NONE),
            );
        }
        self.rounds.read_back(v as u32);
        Snapshot::read(v, t, adjacency, fault, |buffer, words| {
            self.read_words(self.buffer(buffer.into()), words as u64)
        })
    }

    /// Waits until the device has finished every submitted round.
    pub fn wait(&self) -> Result<(), RefineError> {
        self.ctx
            .device
            .poll(wgpu::PollType::wait_indefinitely())
            .map(|_| ())
            .map_err(kernel_error)
    }

    fn read_words(&self, buffer: &wgpu::Buffer, words: u64) -> Result<Vec<u32>, RefineError> {
        if words == 0 {
            return Ok(Vec::new());
        }
        let bytes = 4 * words;
        let staging = self.ctx.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("read back"),
            size: bytes,
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let mut encoder = self.ctx.device.create_command_encoder(&Default::default());
        encoder.copy_buffer_to_buffer(buffer, 0, &staging, 0, bytes);
        self.ctx.queue.submit([encoder.finish()]);
        let (tx, rx) = mpsc::channel();
        staging.map_async(wgpu::MapMode::Read, .., move |r| {
            let _ = tx.send(r);
        });
        self.wait()?;
        rx.recv().map_err(kernel_error)?.map_err(kernel_error)?;
        let view = staging.get_mapped_range(..).map_err(kernel_error)?;
        let words = bytemuck::cast_slice::<u8, u32>(&view).to_vec();
        drop(view);
        staging.unmap();
        Ok(words)
    }
}

fn bind_group_layout(device: &wgpu::Device) -> wgpu::BindGroupLayout {
    let mut entries = vec![wgpu::BindGroupLayoutEntry {
        binding: PARAMS_BINDING,
        visibility: wgpu::ShaderStages::COMPUTE,
        ty: wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Uniform,
            has_dynamic_offset: true,
            min_binding_size: wgpu::BufferSize::new(core::mem::size_of::<Params>() as u64),
        },
        count: None,
    }];
    for b in DeviceBuffer::ALL {
        entries.push(wgpu::BindGroupLayoutEntry {
            binding: 1 + b as u32,
            visibility: wgpu::ShaderStages::COMPUTE,
            ty: wgpu::BindingType::Buffer {
                ty: wgpu::BufferBindingType::Storage { read_only: false },
                has_dynamic_offset: false,
                min_binding_size: None,
            },
            count: None,
        });
    }
    device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("decode"),
        entries: &entries,
    })
}

fn pipelines(device: &wgpu::Device, layout: &wgpu::BindGroupLayout) -> Pipelines {
    let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
        label: Some("decode"),
        bind_group_layouts: &[Some(layout)],
        immediate_size: 0,
    });
    let modules: Vec<(DecodeModule, wgpu::ShaderModule)> = DecodeModule::ALL
        .iter()
        .map(|&m| {
            let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
                label: Some(m.name()),
                source: wgpu::ShaderSource::Wgsl(m.source().into()),
            });
            (m, module)
        })
        .collect();
    let make = |entry: Entry| {
        let module = &modules
            .iter()
            .find(|(k, _)| *k == entry.module())
            .expect("every module is built")
            .1;
        device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some(entry.name()),
            layout: Some(&pipeline_layout),
            module,
            entry_point: Some(entry.name()),
            compilation_options: Default::default(),
            cache: None,
        })
    };
    Pipelines(Entry::ALL.iter().map(|&e| make(e)).collect())
}
