//! The encoder's simplification kernels (Cellier et al. 2012, §2) and the
//! engine that drives them on either API.
//!
//! What runs on the device, per step: best edge per vertex (step a, with
//! the validity checks), reciprocity and local minimum with index priority
//! (steps b and c, three passes with re-picks as on the CPU), and once at
//! the start the quadric init. What stays on the host (the encoder): the
//! corner-table surgery of the collapses, the threshold S (a quantile of
//! the live vertices' errors, which `live_errors` packs for the read-back,
//! so no device sort is needed), and the 2-ring
//! bookkeeping; the host uploads the triangles and vertices it changed with
//! the two `update_*` kernels.
//!
//! Positions are the quantized grid coordinates (u32) and every float
//! computation happens in a frame local to one vertex, so f32 suffices on
//! meshes far from the origin.

pub mod layout;
pub mod sources;

#[cfg(feature = "opencl")]
mod ocl_host;
#[cfg(feature = "wgpu")]
mod wgpu_host;

use std::time::{Duration, Instant};

use crate::gpu::{Api, DeviceInfo, GpuError};
use layout::{MODE_ALL, MODE_REPICK, Params, TriangleUpdate, VertexUpdate, Winner};
pub use sources::{Kernel, Slot, WgslModule};

/// Device buffers, by role (`Slot::List` binds `Dirty` or `Live`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Buffer {
    Params,
    Corners,
    CornerOf,
    Vertices,
    Quadrics,
    Best,
    Blocked,
    Keys,
    Dirty,
    Live,
    Winners,
    Counter,
    Updates,
    Errors,
}

impl Buffer {
    pub const ALL: [Buffer; 14] = [
        Buffer::Params,
        Buffer::Corners,
        Buffer::CornerOf,
        Buffer::Vertices,
        Buffer::Quadrics,
        Buffer::Best,
        Buffer::Blocked,
        Buffer::Keys,
        Buffer::Dirty,
        Buffer::Live,
        Buffer::Winners,
        Buffer::Counter,
        Buffer::Updates,
        Buffer::Errors,
    ];

    /// Initial size in u32 words for a mesh of `n` vertices and `corners` corners.
    pub fn words(self, n: usize, corners: usize) -> usize {
        let n = n.max(1);
        match self {
            Buffer::Params => size_of::<Params>() / 4,
            Buffer::Corners => 2 * corners.max(1),
            Buffer::CornerOf | Buffer::Blocked | Buffer::Dirty | Buffer::Live | Buffer::Errors => n,
            Buffer::Vertices => 4 * n,
            Buffer::Quadrics => 10 * n,
            Buffer::Best => 6 * n,
            Buffer::Keys => 2 * n,
            // Winners of one step are disjoint pairs.
            Buffer::Winners => 7 * (n / 2 + 1),
            Buffer::Counter => 1,
            // Grows on demand.
            Buffer::Updates => 1024,
        }
    }

    /// The buffer bound at `slot` (`list` for [`Slot::List`]).
    pub fn for_slot(slot: Slot, list: Buffer) -> Buffer {
        match slot {
            Slot::Params => Buffer::Params,
            Slot::Corners => Buffer::Corners,
            Slot::CornerOf => Buffer::CornerOf,
            Slot::Vertices => Buffer::Vertices,
            Slot::Quadrics => Buffer::Quadrics,
            Slot::Best => Buffer::Best,
            Slot::Blocked => Buffer::Blocked,
            Slot::Keys => Buffer::Keys,
            Slot::List => list,
            Slot::Winners => Buffer::Winners,
            Slot::Counter => Buffer::Counter,
            Slot::Updates => Buffer::Updates,
            Slot::Errors => Buffer::Errors,
        }
    }
}

/// The primitive operations a compute API offers the engine.
pub trait Device {
    fn info(&self) -> &DeviceInfo;
    /// How long opening took, by part (see [`OpenTimes`]).
    fn open_times(&self) -> OpenTimes;
    /// Writes `words` at the start of `buffer`, growing it when needed.
    fn write(&mut self, buffer: Buffer, words: &[u32]) -> Result<(), GpuError>;
    /// Reads the first `out.len()` words of `buffer` into `out` (waits for
    /// queued work).
    fn read_into(&mut self, buffer: Buffer, out: &mut [u32]) -> Result<(), GpuError>;
    /// Reads the first `words` words of `buffer` (waits for queued work).
    fn read(&mut self, buffer: Buffer, words: usize) -> Result<Vec<u32>, GpuError> {
        let mut out = vec![0u32; words];
        self.read_into(buffer, &mut out)?;
        Ok(out)
    }
    fn zero(&mut self, buffer: Buffer) -> Result<(), GpuError>;
    /// Runs `kernel` on `items` threads with `params`, `list` bound as the list.
    fn run(
        &mut self,
        kernel: Kernel,
        params: &Params,
        items: u32,
        list: Buffer,
    ) -> Result<(), GpuError>;
}

/// The triangles and vertices the host changed in one step, laid out as the
/// update kernels read them (the triangles' words, then the vertices'),
/// filled in place and kept from step to step: building them as vectors and
/// concatenating those copied up to 85 MB twice a step on a 1M-vertex
/// terrain.
#[derive(Default)]
pub struct Updates {
    words: Vec<u32>,
    triangles: usize,
    vertices: usize,
}

impl Updates {
    /// Room for `triangles` and `vertices` updates, to be filled whole.
    pub fn fill(
        &mut self,
        triangles: usize,
        vertices: usize,
    ) -> (&mut [TriangleUpdate], &mut [VertexUpdate]) {
        let triangle_words = triangles * size_of::<TriangleUpdate>() / 4;
        let vertex_words = vertices * size_of::<VertexUpdate>() / 4;
        self.words.resize(triangle_words + vertex_words, 0);
        self.triangles = triangles;
        self.vertices = vertices;
        let (t, v) = self.words.split_at_mut(triangle_words);
        (bytemuck::cast_slice_mut(t), bytemuck::cast_slice_mut(v))
    }
}

/// The mesh as the kernels see it.
pub struct MeshData<'a> {
    /// Per corner: (vertex, opposite corner).
    pub corners: &'a [[u32; 2]],
    pub corner_of: &'a [u32],
    /// Per vertex: quantized x, y, z and flags (`layout::ALIVE | BOUNDARY`).
    pub vertices: &'a [[u32; 4]],
}

/// Opens an OpenCL device and builds the encoder's program on it (the
/// build check of the `.cl` sources).
#[cfg(feature = "opencl")]
pub fn build_opencl_program() -> Result<DeviceInfo, GpuError> {
    let ctx = crate::gpu::open_opencl()?;
    ocl_host::build_program(&ctx)?;
    Ok(ctx.info)
}

/// Drives the kernels through one [`Device`].
pub struct Engine {
    device: Box<dyn Device>,
    vertex_count: usize,
    live_len: u32,
    upload: Duration,
}

/// Where the time of [`Engine::open`] went (printed by the encoder under
/// `SPLITSTREAM_DEBUG`): opening the API's context on the device, compiling
/// the kernels (WGSL modules and pipelines, or the OpenCL program), creating
/// the buffers, and handing the mesh to the queue (wgpu may finish the copy
/// later, with the first dispatch).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct OpenTimes {
    pub context: Duration,
    pub compile: Duration,
    pub buffers: Duration,
    pub upload: Duration,
}

impl std::fmt::Display for OpenTimes {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let ms = |d: Duration| d.as_secs_f64() * 1e3;
        write!(
            f,
            "context {:.0} ms, compile {:.0} ms, buffers {:.0} ms, upload {:.0} ms",
            ms(self.context),
            ms(self.compile),
            ms(self.buffers),
            ms(self.upload)
        )
    }
}

impl Engine {
    /// Opens a device of `api` and uploads the mesh.
    // Built without a GPU API, every `api` fails before the upload.
    #[cfg_attr(
        not(any(feature = "wgpu", feature = "opencl")),
        allow(unreachable_code, unused_variables, unused_mut)
    )]
    pub fn open(api: Api, mesh: &MeshData<'_>) -> Result<Engine, GpuError> {
        let n = mesh.vertices.len();
        let corners = mesh.corners.len();
        let mut device: Box<dyn Device> = match api {
            #[cfg(feature = "wgpu")]
            Api::Wgpu => Box::new(wgpu_host::WgpuDevice::new(n, corners)?),
            #[cfg(feature = "opencl")]
            Api::OpenCl => Box::new(ocl_host::OclDevice::new(n, corners)?),
            #[allow(unreachable_patterns)]
            api => return Err(GpuError::NotCompiled { api }),
        };
        let upload = Instant::now();
        device.write(Buffer::Corners, bytemuck::cast_slice(mesh.corners))?;
        device.write(Buffer::CornerOf, mesh.corner_of)?;
        device.write(Buffer::Vertices, bytemuck::cast_slice(mesh.vertices))?;
        // Never read before written, but keys must start "no request".
        device.write(Buffer::Keys, &vec![u32::MAX; 2 * n.max(1)])?;
        Ok(Engine {
            device,
            vertex_count: n,
            live_len: 0,
            upload: upload.elapsed(),
        })
    }

    pub fn info(&self) -> &DeviceInfo {
        self.device.info()
    }

    /// How long [`Engine::open`] took, by part.
    pub fn open_times(&self) -> OpenTimes {
        OpenTimes {
            upload: self.upload,
            ..self.device.open_times()
        }
    }

    /// Quadric init: every vertex's quadric in its own frame, left on the
    /// device and returned (a2 ab ac ad b2 bc bd c2 cd d2).
    pub fn quadric_init(&mut self, params: &Params) -> Result<Vec<[f32; 10]>, GpuError> {
        let n = self.vertex_count as u32;
        self.device
            .run(Kernel::QuadricInit, params, n, Buffer::Dirty)?;
        let mut quadrics = vec![[0f32; 10]; self.vertex_count];
        self.device
            .read_into(Buffer::Quadrics, bytemuck::cast_slice_mut(&mut quadrics))?;
        Ok(quadrics)
    }

    /// Uploads what the host changed.
    pub fn update(&mut self, params: &Params, updates: &Updates) -> Result<(), GpuError> {
        if updates.words.is_empty() {
            return Ok(());
        }
        self.device.write(Buffer::Updates, &updates.words)?;
        let vertex_offset = (updates.triangles * size_of::<TriangleUpdate>() / 4) as u32;
        let p = Params {
            list_len: updates.triangles as u32,
            mode: 0,
            ..*params
        };
        self.device
            .run(Kernel::UpdateTriangles, &p, p.list_len, Buffer::Dirty)?;
        let p = Params {
            list_len: updates.vertices as u32,
            mode: vertex_offset,
            ..*params
        };
        self.device
            .run(Kernel::UpdateVertices, &p, p.list_len, Buffer::Dirty)
    }

    /// Step a for the `dirty` vertices: their best edges, left on the
    /// device.
    pub fn best_edges(&mut self, params: &Params, dirty: &[u32]) -> Result<(), GpuError> {
        if dirty.is_empty() {
            return Ok(());
        }
        self.device.write(Buffer::Dirty, dirty)?;
        let p = Params {
            list_len: dirty.len() as u32,
            mode: MODE_ALL,
            ..*params
        };
        self.device
            .run(Kernel::BestEdge, &p, p.list_len, Buffer::Dirty)
    }

    /// The live vertices the selection walks.
    pub fn set_live(&mut self, live: &[u32]) -> Result<(), GpuError> {
        self.device.write(Buffer::Live, live)?;
        self.live_len = live.len() as u32;
        Ok(())
    }

    /// The errors of the live vertices' best edges, those that have one
    /// (for the threshold S; in live order).
    ///
    /// Read as 4 bytes a live vertex: reading every vertex's whole best edge
    /// instead was 24 MB a step on a 1M-vertex terrain however few were
    /// left alive.
    pub fn live_errors(&mut self, params: &Params) -> Result<Vec<f64>, GpuError> {
        let p = Params {
            list_len: self.live_len,
            ..*params
        };
        self.device
            .run(Kernel::LiveErrors, &p, p.list_len, Buffer::Live)?;
        let words = self.device.read(Buffer::Errors, self.live_len as usize)?;
        Ok(words
            .into_iter()
            .filter(|&w| w != layout::NONE)
            .map(|w| f32::from_bits(w) as f64)
            .collect())
    }

    /// Steps b and c under `params.threshold`, `passes` times with re-picks
    /// in between (see the encoder's `step_winners`). Winners in ascending
    /// lower id.
    pub fn select(&mut self, params: &Params, passes: usize) -> Result<Vec<Winner>, GpuError> {
        let live = self.live_len;
        self.device.zero(Buffer::Blocked)?;
        self.device.zero(Buffer::Counter)?;
        let walk = Params {
            list_len: live,
            mode: MODE_ALL,
            ..*params
        };
        let mut done = 0u32;
        for pass in 0..passes {
            if pass > 0 {
                let repick = Params {
                    mode: MODE_REPICK,
                    ..walk
                };
                self.device
                    .run(Kernel::BestEdge, &repick, live, Buffer::Live)?;
            }
            self.device.run(Kernel::Admit, &walk, live, Buffer::Live)?;
            self.device
                .run(Kernel::LocalMin, &walk, live, Buffer::Live)?;
            let count = self.device.read(Buffer::Counter, 1)?[0];
            // A step's winners are disjoint pairs: more than the buffer
            // holds (or fewer than before) is a device fault, not a result
            // to read past the buffer's end.
            let capacity = Buffer::Winners.words(self.vertex_count, 0) / 7;
            if count < done || count as usize > capacity {
                return Err(GpuError::Kernel {
                    api: self.device.info().api,
                    detail: format!(
                        "the device counted {count} winners after {done}, a step holds at most {capacity}"
                    ),
                });
            }
            if count == done {
                break;
            }
            let block = Params {
                list_len: count - done,
                mode: done,
                ..*params
            };
            self.device
                .run(Kernel::Block, &block, block.list_len, Buffer::Live)?;
            done = count;
        }
        let words = self.device.read(Buffer::Winners, 7 * done as usize)?;
        let mut winners: Vec<Winner> = bytemuck::cast_slice(&words).to_vec();
        winners.sort_unstable_by_key(|w| w.v);
        Ok(winners)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A device whose kernels do nothing and whose winner counter reads
    /// `counter`.
    struct FaultyCounter {
        info: DeviceInfo,
        counter: u32,
    }

    impl Device for FaultyCounter {
        fn info(&self) -> &DeviceInfo {
            &self.info
        }
        fn open_times(&self) -> OpenTimes {
            OpenTimes::default()
        }
        fn write(&mut self, _: Buffer, _: &[u32]) -> Result<(), GpuError> {
            Ok(())
        }
        fn read_into(&mut self, buffer: Buffer, out: &mut [u32]) -> Result<(), GpuError> {
            out.fill(0);
            if buffer == Buffer::Counter {
                out[0] = self.counter;
            }
            Ok(())
        }
        fn zero(&mut self, _: Buffer) -> Result<(), GpuError> {
            Ok(())
        }
        fn run(&mut self, _: Kernel, _: &Params, _: u32, _: Buffer) -> Result<(), GpuError> {
            Ok(())
        }
    }

    fn engine(counter: u32) -> Engine {
        Engine {
            device: Box::new(FaultyCounter {
                info: DeviceInfo {
                    api: Api::Wgpu,
                    name: "faulty".into(),
                    detail: String::new(),
                },
                counter,
            }),
            vertex_count: 100,
            live_len: 100,
            upload: Duration::ZERO,
        }
    }

    #[test]
    fn a_winner_count_past_the_buffer_is_a_device_fault() {
        // 100 vertices: at most 51 winners fit the buffer.
        let err = engine(1_000_000).select(&Params::default(), 3).unwrap_err();
        assert!(
            matches!(err, GpuError::Kernel { api: Api::Wgpu, .. }),
            "{err:?}"
        );
        assert!(err.to_string().contains("1000000 winners"), "{err}");
        // A count the buffer holds is read back as that many winners.
        assert_eq!(engine(51).select(&Params::default(), 1).unwrap().len(), 51);
    }
}
