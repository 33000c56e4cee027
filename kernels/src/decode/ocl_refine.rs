//! Host glue for the OpenCL C port of the decoder kernels (feature
//! `opencl`): the same buffers, dispatch schedule ([`super::schedule`]) and
//! read-back as the wgpu host (`refine`), through `ocl`. Tested on
//! pocl (kernels/tests/decode_faults.rs).

use super::adjacency::build_adjacency;
pub use super::host::{BaseMesh, RefineError, RoundInput, Schedule, Snapshot};
use super::host::{StateBuffer, check_base, check_round, position_limit, round_split_capacity};
use super::layout::*;
use super::schedule::{Entry, round_schedule, scan_words};
use super::sources::opencl_program;
use crate::gpu::{Api, OclContext};

fn kernel_error(what: &str, e: impl core::fmt::Display) -> RefineError {
    super::host::kernel_error(Api::OpenCl, format!("{what}: {e}"))
}

/// Parameter slots one round may use (as the wgpu host).
const PARAM_SLOTS: usize = 512;
/// Words per parameter slot (`Params`, 48 bytes).
const PARAM_WORDS: usize = core::mem::size_of::<Params>() / 4;

// Device buffers, in kernel argument order after (params, slot):
// counts, positions, corners, opposite, vertex_corner, deficit, mark, uses,
// candidates, flags, records, scan, splits (common.cl: DECODE_ARGS).
const COUNTS: usize = 0;
const POSITIONS: usize = 1;
const CORNERS: usize = 2;
const OPPOSITE: usize = 3;
const VERTEX_CORNER: usize = 4;
const DEFICIT: usize = 5;
const FLAGS: usize = 9;
const RECORDS: usize = 10;

/// The decoder's refinement on an OpenCL device.
pub struct OclRefiner<'c> {
    ctx: &'c OclContext,
    params: ocl::Buffer<u32>,
    buffers: Vec<ocl::Buffer<u32>>,
    /// One kernel per entry point, indexed like [`Entry::ALL`].
    kernels: Vec<ocl::Kernel>,
    vertex_capacity: u32,
    triangle_capacity: u32,
    split_capacity: u32,
    scan_scratch: u32,
    pos_limit: u32,
    vertex_count: u32,
    /// `Params::schedule` of every dispatch.
    schedule: u32,
}

impl<'c> OclRefiner<'c> {
    /// Uploads `base` into buffers for `vertex_capacity` vertices and
    /// `triangle_capacity` triangles and builds the program, for a stream of
    /// the schedule `split-valences`.
    pub fn new(
        ctx: &'c OclContext,
        base: BaseMesh<'_>,
        vertex_capacity: u32,
        triangle_capacity: u32,
    ) -> Result<OclRefiner<'c>, RefineError> {
        OclRefiner::with_schedule(
            ctx,
            base,
            Schedule::SplitValences,
            vertex_capacity,
            triangle_capacity,
        )
    }

    /// [`OclRefiner::new`] for a stream of `schedule` (as the wgpu
    /// `Refiner::with_schedule`).
    pub fn with_schedule(
        ctx: &'c OclContext,
        base: BaseMesh<'_>,
        schedule: Schedule,
        vertex_capacity: u32,
        triangle_capacity: u32,
    ) -> Result<OclRefiner<'c>, RefineError> {
        check_base(&base, vertex_capacity, triangle_capacity)?;
        let v0 = base.positions.len() as u32;
        let t0 = base.triangles.len() as u32;
        let (opposite, vertex_corner) =
            build_adjacency(base.triangles, v0).map_err(RefineError::Base)?;
        let split_capacity = round_split_capacity(vertex_capacity, v0);
        let sort_capacity = vertex_capacity.max(WORKGROUP).next_power_of_two();
        let scan_len = vertex_capacity.max(1);
        let (vcap, tcap) = (vertex_capacity as usize, triangle_capacity as usize);
        let words = [
            COUNT_WORDS,
            3 * vcap,
            3 * tcap,
            3 * tcap,
            vcap,
            vcap,
            vcap,
            vcap,
            sort_capacity as usize,
            vcap.div_ceil(32),
            12 * split_capacity as usize,
            scan_words(scan_len) as usize,
            SPLIT_WORDS as usize * split_capacity as usize,
        ];
        let buffer = |len: usize| {
            ocl::Buffer::<u32>::builder()
                .queue(ctx.queue.clone())
                .len(len.max(16))
                .fill_val(0)
                .build()
                .map_err(|e| kernel_error("allocating a buffer", e))
        };
        let buffers = words
            .iter()
            .map(|&w| buffer(w))
            .collect::<Result<Vec<_>, _>>()?;
        let params = buffer(PARAM_SLOTS * PARAM_WORDS)?;
        let corners: Vec<u32> = base.triangles.iter().flatten().copied().collect();
        let deficits: Vec<u32> = base.deficits.iter().map(|&d| d as u32).collect();
        let uploads: [(usize, &[u32]); 6] = [
            (COUNTS, &[v0, t0, 0, NONE]),
            (POSITIONS, bytemuck::cast_slice(base.positions)),
            (CORNERS, &corners),
            (OPPOSITE, &opposite),
            (VERTEX_CORNER, &vertex_corner),
            (DEFICIT, &deficits),
        ];
        for (i, data) in uploads {
            write(&buffers[i], data)?;
        }
        let program = ocl::Program::builder()
            .src(opencl_program())
            .devices(ctx.device)
            .cmplr_opt("-cl-std=CL1.2")
            .build(&ctx.context)
            .map_err(|e| kernel_error("building the decoder's OpenCL program", e))?;
        let mut kernels = Vec::new();
        for entry in Entry::ALL {
            let mut builder = ocl::Kernel::builder();
            builder
                .program(&program)
                .name(entry.name())
                .queue(ctx.queue.clone())
                .arg(&params)
                .arg(0u32);
            for b in &buffers {
                builder.arg(b);
            }
            kernels.push(builder.build().map_err(|e| kernel_error(entry.name(), e))?);
        }
        Ok(OclRefiner {
            ctx,
            params,
            buffers,
            kernels,
            vertex_capacity,
            triangle_capacity,
            split_capacity,
            scan_scratch: scan_len,
            pos_limit: position_limit(base.bits),
            vertex_count: v0,
            schedule: schedule.word(),
        })
    }

    /// Enqueues one round (the queue is in order; nothing waits).
    pub fn round(&mut self, input: RoundInput<'_>) -> Result<(), RefineError> {
        let n = self.vertex_count;
        let s = input.records.len() as u32;
        check_round(&input, n, self.vertex_capacity, self.split_capacity)?;
        write(&self.buffers[RECORDS], bytemuck::cast_slice(input.records))?;
        let flag_words = input.candidates.div_ceil(32) as usize;
        write(&self.buffers[FLAGS], &input.flags[..flag_words])?;
        let common = Params {
            n,
            candidates: input.candidates,
            splits: s,
            sort_len: input.candidates.max(WORKGROUP).next_power_of_two(),
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
        let params: Vec<Params> = plan.iter().map(|d| d.params).collect();
        write(&self.params, bytemuck::cast_slice(&params))?;
        for (slot, d) in plan.iter().enumerate() {
            let kernel = &self.kernels[d.entry as usize];
            kernel
                .set_arg(1, slot as u32)
                .map_err(|e| kernel_error(d.entry.name(), e))?;
            let items = d.groups as usize * WORKGROUP as usize;
            // SAFETY: every argument is a live buffer of this context sized
            // for the capacities, and each kernel bounds its indices by the
            // counts of its parameter slot.
            unsafe {
                kernel
                    .cmd()
                    .global_work_size(items)
                    .local_work_size(WORKGROUP as usize)
                    .enq()
            }
            .map_err(|e| kernel_error(d.entry.name(), e))?;
        }
        self.vertex_count = n + s;
        Ok(())
    }

    /// Waits for the queue and reads the state back (as the wgpu
    /// `Refiner::snapshot`: the fault word is reset after a fault).
    pub fn snapshot(&mut self, adjacency: bool) -> Result<Snapshot, RefineError> {
        let counts = read(&self.buffers[COUNTS], COUNT_WORDS)?;
        let (v, t) = (counts[COUNT_V] as usize, counts[COUNT_T] as usize);
        let fault = KernelFault::from_key(counts[COUNT_ERROR]);
        if fault.is_some() {
            let reset = [v as u32, t as u32, counts[COUNT_CANDIDATES], NONE];
            write(&self.buffers[COUNTS], &reset)?;
        }
        self.vertex_count = v as u32;
        let buffers = &self.buffers;
        Snapshot::read(v, t, adjacency, fault, |buffer, words| {
            let index = match buffer {
                StateBuffer::Positions => POSITIONS,
                StateBuffer::Deficit => DEFICIT,
                StateBuffer::Corners => CORNERS,
                StateBuffer::Opposite => OPPOSITE,
                StateBuffer::VertexCorner => VERTEX_CORNER,
            };
            read(&buffers[index], words)
        })
    }

    /// Waits until every enqueued round has run.
    pub fn wait(&self) -> Result<(), RefineError> {
        self.ctx
            .queue
            .finish()
            .map_err(|e| kernel_error("waiting for the queue", e))
    }
}

fn write(buffer: &ocl::Buffer<u32>, data: &[u32]) -> Result<(), RefineError> {
    if data.is_empty() {
        return Ok(());
    }
    buffer
        .write(data)
        .len(data.len())
        .enq()
        .map_err(|e| kernel_error("writing a buffer", e))
}

fn read(buffer: &ocl::Buffer<u32>, words: usize) -> Result<Vec<u32>, RefineError> {
    let mut out = vec![0u32; words];
    if words > 0 {
        buffer
            .read(&mut out)
            .len(words)
            .enq()
            .map_err(|e| kernel_error("reading a buffer", e))?;
    }
    Ok(out)
}
