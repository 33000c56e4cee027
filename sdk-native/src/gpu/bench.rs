//! Decoder splits per second: the GPU's refinement against decoder-core on
//! one thread, on the same stream.

use std::time::Instant;

use super::device::GpuDevice;
use super::error::GpuDecodeError;
use super::refiner::GpuRefiner;
use super::stream::{CapturedStream, capture_stream, capture_stream_two_threads};
use crate::threaded::TWO_THREADS_FROM_SPLITS;

/// Timings of one stream, best of the repeats, in seconds.
#[derive(Clone, Debug, PartialEq)]
pub struct BenchReport {
    /// The device, as wgpu names it.
    pub device: String,
    pub vertices: u32,
    pub triangles: u32,
    pub rounds: usize,
    pub splits: u64,
    /// decoder-core decoding the whole stream (entropy decoding, records,
    /// splits), one thread.
    pub cpu_decode: f64,
    /// The same with the capture of every round for the GPU (phase 1: the
    /// CPU still reads the records), one thread.
    pub cpu_capture: f64,
    /// The capture with a large level's records read on a second thread
    /// (what [`super::decode`] does).
    pub cpu_capture_two_threads: f64,
    /// Pipelines, base upload, every round's upload and kernels, up to the
    /// device being idle.
    pub gpu_total: f64,
    /// Of which the rounds: record and flag uploads plus kernels.
    pub gpu_rounds: f64,
}

impl BenchReport {
    pub fn cpu_splits_per_second(&self) -> f64 {
        self.splits as f64 / self.cpu_decode
    }

    /// Splits per second of the GPU refinement, uploads included.
    pub fn gpu_splits_per_second(&self) -> f64 {
        self.splits as f64 / self.gpu_total
    }

    /// Splits per second of the GPU's rounds alone (base upload and
    /// pipeline creation excluded).
    pub fn gpu_round_splits_per_second(&self) -> f64 {
        self.splits as f64 / self.gpu_rounds
    }
}

impl core::fmt::Display for BenchReport {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        writeln!(f, "device: {}", self.device)?;
        writeln!(
            f,
            "stream: {} vertices, {} triangles, {} rounds, {} splits",
            self.vertices, self.triangles, self.rounds, self.splits
        )?;
        let ms = |s: f64| s * 1e3;
        writeln!(
            f,
            "decoder-core, 1 thread:        {:9.1} ms  {:12.0} splits/s",
            ms(self.cpu_decode),
            self.cpu_splits_per_second()
        )?;
        writeln!(
            f,
            "CPU capture (phase-1 reading): {:9.1} ms",
            ms(self.cpu_capture)
        )?;
        writeln!(
            f,
            "CPU capture, 2 threads:        {:9.1} ms",
            ms(self.cpu_capture_two_threads)
        )?;
        writeln!(
            f,
            "GPU refinement, all uploads:   {:9.1} ms  {:12.0} splits/s",
            ms(self.gpu_total),
            self.gpu_splits_per_second()
        )?;
        write!(
            f,
            "GPU rounds only:               {:9.1} ms  {:12.0} splits/s",
            ms(self.gpu_rounds),
            self.gpu_round_splits_per_second()
        )
    }
}

/// Measures `stream` `repeats` times (at least once) and keeps the best of
/// each timing. The stream must decode without faults.
pub fn bench(
    device: &GpuDevice,
    stream: &[u8],
    repeats: usize,
) -> Result<BenchReport, GpuDecodeError> {
    let best = |a: &mut f64, s: f64| *a = a.min(s);
    let mut cpu_decode = f64::INFINITY;
    let mut cpu_capture = f64::INFINITY;
    let mut cpu_capture_two_threads = f64::INFINITY;
    let mut gpu_total = f64::INFINITY;
    let mut gpu_rounds = f64::INFINITY;
    let mut captured = CapturedStream::default();
    let mut counts = (0, 0);
    for _ in 0..repeats.max(1) {
        let t = Instant::now();
        let mesh = splitstream_decoder_core::owned::decode_all(stream, false)
            .map_err(GpuDecodeError::Stream)?;
        best(&mut cpu_decode, t.elapsed().as_secs_f64());
        counts = (mesh.positions.len() as u32, mesh.triangles.len() as u32);

        let t = Instant::now();
        captured = capture_stream(stream, false);
        best(&mut cpu_capture, t.elapsed().as_secs_f64());
        if let Some(e) = captured.error {
            return Err(e.into());
        }
        let t = Instant::now();
        captured = capture_stream_two_threads(stream, false, TWO_THREADS_FROM_SPLITS);
        best(&mut cpu_capture_two_threads, t.elapsed().as_secs_f64());
        if let Some(e) = captured.error {
            return Err(e.into());
        }
        let base = captured.base.as_ref().ok_or(GpuDecodeError::Capture)?;

        let t = Instant::now();
        let mut gpu = GpuRefiner::new(
            device,
            base,
            captured.vertex_capacity,
            captured.triangle_capacity,
        )?;
        gpu.wait()?;
        let rounds_start = Instant::now();
        for level in &captured.levels {
            for round in &level.rounds {
                gpu.apply_round(round, level.triangle_limit)?;
            }
        }
        gpu.wait()?;
        best(&mut gpu_rounds, rounds_start.elapsed().as_secs_f64());
        best(&mut gpu_total, t.elapsed().as_secs_f64());
        // Not timed: the result must be decoder-core's.
        let snapshot = gpu.snapshot(false)?;
        let gpu_counts = (
            snapshot.positions.len() as u32,
            (snapshot.corners.len() / 3) as u32,
        );
        if gpu_counts != counts {
            return Err(GpuDecodeError::HashMismatch {
                round: captured.rounds(),
                gpu: 0,
                cpu: 0,
            });
        }
    }
    Ok(BenchReport {
        device: device.info().to_string(),
        vertices: counts.0,
        triangles: counts.1,
        rounds: captured.rounds(),
        splits: captured.splits(),
        cpu_decode,
        cpu_capture,
        cpu_capture_two_threads,
        gpu_total,
        gpu_rounds,
    })
}
