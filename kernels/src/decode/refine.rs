//! Host glue (feature `wgpu`): buffers, pipelines and the dispatch schedule
//! of one refinement round, and the read-back of the state.
//!
//! A round is recorded into one compute pass and submitted without waiting:
//! the host supplies only what the stream says (candidate count, one flag
//! bit per candidate, the flagged splits' records) and the level's triangle
//! limit; the vertex and triangle counts live on the device. Faults found by
//! the kernels are read back with the state ([`Refiner::snapshot`]).

use std::sync::mpsc;

use wgpu::util::DeviceExt;

use super::adjacency::build_adjacency;
pub use super::host::{BaseMesh, RefineError, RoundInput, Schedule, Snapshot};
use super::host::{StateBuffer, check_base, check_round, position_limit, round_split_capacity};
use super::layout::*;
use super::schedule::{Entry, round_schedule, scan_words};
use super::sources::DecodeModule;
use crate::gpu::{Api, GpuError, WgpuContext};

fn kernel_error(detail: impl ToString) -> RefineError {
    super::host::kernel_error(Api::Wgpu, detail)
}

/// Parameter slots one round may use (sort stages dominate: 2^24 candidates
/// need 17 + 16 * 17 / 2 < 200).
const PARAM_SLOTS: usize = 512;

/// Binding numbers (common.wgsl and the step files).
mod binding {
    pub const PARAMS: u32 = 0;
    pub const COUNTS: u32 = 1;
    pub const POSITIONS: u32 = 2;
    pub const CORNERS: u32 = 3;
    pub const OPPOSITE: u32 = 4;
    pub const VERTEX_CORNER: u32 = 5;
    pub const DEFICIT: u32 = 6;
    pub const MARK: u32 = 7;
    pub const USES: u32 = 8;
    pub const CAND: u32 = 9;
    pub const FLAGS: u32 = 10;
    pub const RECORDS: u32 = 11;
    pub const SCAN: u32 = 12;
    pub const SPLITS: u32 = 13;
    pub const STORAGE: u32 = 13;
}

struct Buffers {
    params: wgpu::Buffer,
    counts: wgpu::Buffer,
    positions: wgpu::Buffer,
    corners: wgpu::Buffer,
    opposite: wgpu::Buffer,
    vertex_corner: wgpu::Buffer,
    deficit: wgpu::Buffer,
    flags: wgpu::Buffer,
    records: wgpu::Buffer,
}

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
    buffers: Buffers,
    bind_group: wgpu::BindGroup,
    pipelines: Pipelines,
    vertex_capacity: u32,
    triangle_capacity: u32,
    split_capacity: u32,
    /// First scan word after the values (block sums live there).
    scan_scratch: u32,
    pos_limit: u32,
    /// Vertex count as the host tracks it (the device has its own).
    vertex_count: u32,
    /// `Params::schedule` of every dispatch.
    schedule: u32,
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
        check_base(&base, vertex_capacity, triangle_capacity)?;
        let v0 = base.positions.len() as u32;
        let t0 = base.triangles.len() as u32;
        let (opposite, vertex_corner) =
            build_adjacency(base.triangles, v0).map_err(RefineError::Base)?;
        let split_capacity = round_split_capacity(vertex_capacity, v0);
        let sort_capacity = vertex_capacity.max(WORKGROUP).next_power_of_two();
        let scan_len = vertex_capacity.max(1);
        let device = &ctx.device;
        let storage = wgpu::BufferUsages::STORAGE
            | wgpu::BufferUsages::COPY_DST
            | wgpu::BufferUsages::COPY_SRC;
        // Every binding needs at least one element of its largest struct.
        let sized = |label: &str, bytes: u64| {
            device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size: bytes.max(64).next_multiple_of(16),
                usage: storage,
                mapped_at_creation: false,
            })
        };
        let filled = |label: &str, contents: &[u8], bytes: u64| {
            let buffer = sized(label, bytes);
            ctx.queue.write_buffer(&buffer, 0, contents);
            buffer
        };
        let vcap = vertex_capacity as u64;
        let tcap = triangle_capacity as u64;
        // Each buffer is bound whole: it must fit the device's binding limit
        // (lavapipe: 128 MiB, so about 2.8 M splits of records), or creating
        // the bind group fails validation.
        let limit = ctx
            .limits
            .max_storage_buffer_binding_size
            .min(ctx.limits.max_buffer_size);
        for (what, bytes) in [
            ("the positions buffer", 12 * vcap),
            ("the corner buffers", 12 * tcap),
            ("the split records buffer", 48 * split_capacity as u64),
            (
                "the splits buffer",
                4 * SPLIT_WORDS as u64 * split_capacity as u64,
            ),
            ("the candidates buffer", 4 * sort_capacity as u64),
            ("the scan buffer", 4 * scan_words(scan_len)),
        ] {
            if bytes > limit {
                return Err(GpuError::TooLarge {
                    api: Api::Wgpu,
                    what,
                    bytes,
                    limit,
                }
                .into());
            }
        }
        let corners: Vec<u32> = base.triangles.iter().flatten().copied().collect();
        let deficits: Vec<u32> = base.deficits.iter().map(|&d| d as u32).collect();
        let counts: [u32; COUNT_WORDS] = [v0, t0, 0, NONE];
        let buffers = Buffers {
            params: device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("decode params"),
                size: PARAM_SLOT * PARAM_SLOTS as u64,
                usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            }),
            counts: device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("decode counts"),
                contents: bytemuck::cast_slice(&counts),
                usage: storage,
            }),
            positions: filled("positions", bytemuck::cast_slice(base.positions), 12 * vcap),
            corners: filled("corners", bytemuck::cast_slice(&corners), 12 * tcap),
            opposite: filled("opposite", bytemuck::cast_slice(&opposite), 12 * tcap),
            vertex_corner: filled(
                "vertex_corner",
                bytemuck::cast_slice(&vertex_corner),
                4 * vcap,
            ),
            deficit: filled("deficit", bytemuck::cast_slice(&deficits), 4 * vcap),
            flags: sized("flags", 4 * vcap.div_ceil(32)),
            records: sized("records", 48 * split_capacity as u64),
        };
        let mark = sized("mark", 4 * vcap);
        let uses = sized("uses", 4 * vcap);
        let cand = sized("candidates", 4 * sort_capacity as u64);
        let scan = sized("scan", 4 * scan_words(scan_len));
        let splits = sized("splits", 4 * SPLIT_WORDS as u64 * split_capacity as u64);

        let layout = bind_group_layout(device);
        let b = &buffers;
        let entries: Vec<(u32, &wgpu::Buffer)> = vec![
            (binding::COUNTS, &b.counts),
            (binding::POSITIONS, &b.positions),
            (binding::CORNERS, &b.corners),
            (binding::OPPOSITE, &b.opposite),
            (binding::VERTEX_CORNER, &b.vertex_corner),
            (binding::DEFICIT, &b.deficit),
            (binding::MARK, &mark),
            (binding::USES, &uses),
            (binding::CAND, &cand),
            (binding::FLAGS, &b.flags),
            (binding::RECORDS, &b.records),
            (binding::SCAN, &scan),
            (binding::SPLITS, &splits),
        ];
        let mut bind_entries: Vec<wgpu::BindGroupEntry> = entries
            .iter()
            .map(|&(binding, buffer)| wgpu::BindGroupEntry {
                binding,
                resource: buffer.as_entire_binding(),
            })
            .collect();
        bind_entries.push(wgpu::BindGroupEntry {
            binding: binding::PARAMS,
            resource: wgpu::BindingResource::Buffer(wgpu::BufferBinding {
                buffer: &b.params,
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
            buffers,
            bind_group,
            pipelines,
            vertex_capacity,
            triangle_capacity,
            split_capacity,
            scan_scratch: scan_len,
            pos_limit: position_limit(base.bits),
            vertex_count: v0,
            schedule: schedule.word(),
        })
    }

    /// Vertex count after the rounds submitted so far (assuming they passed).
    pub fn vertex_count(&self) -> u32 {
        self.vertex_count
    }

    /// Records and submits one round; does not wait for it.
    pub fn round(&mut self, input: RoundInput<'_>) -> Result<(), RefineError> {
        let n = self.vertex_count;
        let s = input.records.len() as u32;
        check_round(&input, n, self.vertex_capacity, self.split_capacity)?;
        let queue = &self.ctx.queue;
        if !input.records.is_empty() {
            queue.write_buffer(
                &self.buffers.records,
                0,
                bytemuck::cast_slice(input.records),
            );
        }
        let flag_words = input.candidates.div_ceil(32) as usize;
        if flag_words > 0 {
            queue.write_buffer(
                &self.buffers.flags,
                0,
                bytemuck::cast_slice(&input.flags[..flag_words]),
            );
        }
        let sort_len = input.candidates.max(WORKGROUP).next_power_of_two();
        let common = Params {
            n,
            candidates: input.candidates,
            splits: s,
            sort_len,
            tri_limit: input.triangle_limit.min(self.triangle_capacity),
            pos_limit: self.pos_limit,
            schedule: self.schedule,
            ..Params::default()
        };
        let plan = round_schedule(common, self.scan_scratch);
        if plan.len() > PARAM_SLOTS {
            return Err(RefineError::Capacity {
                what: "dispatches per round",
                needed: plan.len() as u64,
                capacity: PARAM_SLOTS as u64,
            });
        }
        let mut slots = vec![0u8; plan.len() * PARAM_SLOT as usize];
        for (i, d) in plan.iter().enumerate() {
            let at = i * PARAM_SLOT as usize;
            slots[at..at + core::mem::size_of::<Params>()]
                .copy_from_slice(bytemuck::bytes_of(&d.params));
        }
        queue.write_buffer(&self.buffers.params, 0, &slots);
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
        self.vertex_count = n + s;
        Ok(())
    }

    /// Waits for the submitted rounds and reads the state back (with the
    /// adjacency when `adjacency`). Resets the device's fault word, so each
    /// snapshot reports the faults since the previous one.
    pub fn snapshot(&mut self, adjacency: bool) -> Result<Snapshot, RefineError> {
        let counts: Vec<u32> = self.read_words(&self.buffers.counts, COUNT_WORDS as u64)?;
        let (v, t) = (counts[COUNT_V] as u64, counts[COUNT_T] as u64);
        let fault = KernelFault::from_key(counts[COUNT_ERROR]);
        if fault.is_some() {
            self.ctx.queue.write_buffer(
                &self.buffers.counts,
                4 * COUNT_ERROR as u64,
                bytemuck::bytes_of(&NONE),
            );
        }
        self.vertex_count = v as u32;
        let (v, t) = (v as usize, t as usize);
        Snapshot::read(v, t, adjacency, fault, |buffer, words| {
            let b = &self.buffers;
            let source = match buffer {
                StateBuffer::Positions => &b.positions,
                StateBuffer::Deficit => &b.deficit,
                StateBuffer::Corners => &b.corners,
                StateBuffer::Opposite => &b.opposite,
                StateBuffer::VertexCorner => &b.vertex_corner,
            };
            self.read_words(source, words as u64)
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
        binding: binding::PARAMS,
        visibility: wgpu::ShaderStages::COMPUTE,
        ty: wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Uniform,
            has_dynamic_offset: true,
            min_binding_size: wgpu::BufferSize::new(core::mem::size_of::<Params>() as u64),
        },
        count: None,
    }];
    for b in binding::COUNTS..=binding::STORAGE {
        entries.push(wgpu::BindGroupLayoutEntry {
            binding: b,
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
