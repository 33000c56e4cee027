//! Host glue for the OpenCL C port of the decoder kernels (feature
//! `opencl`): the same buffers, dispatch schedule ([`super::schedule`]) and
//! read-back as the wgpu host (`refine`), through `ocl`. Tested on
//! pocl (kernels/tests/decode_faults.rs).

use super::device_state::{DeviceBuffer, DeviceState, Rounds};
pub use super::host::{BaseMesh, RefineError, RoundInput, Schedule, Snapshot};
use super::layout::*;
use super::schedule::Entry;
use super::sources::opencl_program;
use crate::gpu::{Api, OclContext};

fn kernel_error(what: &str, e: impl core::fmt::Display) -> RefineError {
    super::host::kernel_error(Api::OpenCl, format!("{what}: {e}"))
}

/// Words per parameter slot (`Params`, 48 bytes).
const PARAM_WORDS: usize = core::mem::size_of::<Params>() / 4;

/// The decoder's refinement on an OpenCL device.
pub struct OclRefiner<'c> {
    ctx: &'c OclContext,
    params: ocl::Buffer<u32>,
    /// Indexed by [`DeviceBuffer`], in kernel argument order after
    /// (params, slot).
    buffers: Vec<ocl::Buffer<u32>>,
    /// One kernel per entry point, indexed like [`Entry::ALL`].
    kernels: Vec<ocl::Kernel>,
    rounds: Rounds,
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
        let state = DeviceState::new(base, schedule, vertex_capacity, triangle_capacity)?;
        let buffer = |len: usize| {
            ocl::Buffer::<u32>::builder()
                .queue(ctx.queue.clone())
                .len(len.max(16))
                .fill_val(0)
                .build()
                .map_err(|e| kernel_error("allocating a buffer", e))
        };
        let buffers = state
            .words
            .iter()
            .map(|&w| buffer(w as usize))
            .collect::<Result<Vec<_>, _>>()?;
        let params = buffer(super::device_state::PARAM_SLOTS * PARAM_WORDS)?;
        for (b, data) in &state.uploads {
            write(&buffers[*b as usize], data)?;
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
            rounds: state.rounds,
        })
    }

    fn buffer(&self, b: DeviceBuffer) -> &ocl::Buffer<u32> {
        &self.buffers[b as usize]
    }

    /// Enqueues one round (the queue is in order; nothing waits).
    pub fn round(&mut self, input: RoundInput<'_>) -> Result<(), RefineError> {
        let plan = self.rounds.plan(&input)?;
        write(
            self.buffer(DeviceBuffer::Records),
            bytemuck::cast_slice(input.records),
        )?;
        let flag_words = input.candidates.div_ceil(32) as usize;
        write(self.buffer(DeviceBuffer::Flags), &input.flags[..flag_words])?;
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
        self.rounds.submitted(&input);
        Ok(())
    }

    /// Waits for the queue and reads the state back (as the wgpu
    /// `Refiner::snapshot`: the fault word is reset after a fault).
    pub fn snapshot(&mut self, adjacency: bool) -> Result<Snapshot, RefineError> {
        let counts = read(self.buffer(DeviceBuffer::Counts), COUNT_WORDS)?;
        let (v, t) = (counts[COUNT_V] as usize, counts[COUNT_T] as usize);
        let fault = KernelFault::from_key(counts[COUNT_ERROR]);
        if fault.is_some() {
            let reset = [v as u32, t as u32, counts[COUNT_CANDIDATES], NONE];
            write(self.buffer(DeviceBuffer::Counts), &reset)?;
        }
        self.rounds.read_back(v as u32);
        Snapshot::read(v, t, adjacency, fault, |buffer, words| {
            read(self.buffer(buffer.into()), words)
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
