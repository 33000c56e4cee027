//! The GPU side of phase 1: a captured stream's rounds replayed on the
//! device, with the state hash after the seed and after every round.

use super::device::GpuDevice;
use super::error::GpuDecodeError;
use super::refiner::GpuRefiner;
use super::stream::CapturedStream;

/// What to check while replaying.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ReplayOptions {
    /// Compare every GPU hash with decoder-core's (the capture must have
    /// been made with `hash_rounds`).
    pub compare: bool,
    /// Also read back and check the corner-table adjacency every round.
    pub check_adjacency: bool,
}

/// The GPU's hashes (after the seed and after every round it applied) and
/// how decoding ended.
#[derive(Debug)]
pub struct GpuRun {
    pub hashes: Vec<u64>,
    pub result: Result<(), GpuDecodeError>,
}

/// Replays `captured` on the device, reading the state back after the seed
/// and every round; ends with the capture's own fault if it had one.
pub fn replay(device: &GpuDevice, captured: &CapturedStream, options: ReplayOptions) -> GpuRun {
    let mut hashes = Vec::new();
    let result = replay_into(device, captured, options, &mut hashes);
    GpuRun { hashes, result }
}

fn replay_into(
    device: &GpuDevice,
    captured: &CapturedStream,
    options: ReplayOptions,
    hashes: &mut Vec<u64>,
) -> Result<(), GpuDecodeError> {
    let Some(base) = &captured.base else {
        return captured.error.map_or(Ok(()), |e| Err(e.into()));
    };
    let mut gpu = GpuRefiner::new(
        device,
        base,
        captured.vertex_capacity,
        captured.triangle_capacity,
    )?;
    let check = |gpu: &mut GpuRefiner<'_>, hashes: &mut Vec<u64>| {
        let round = hashes.len();
        let snapshot = gpu.snapshot(options.check_adjacency)?;
        let hash = super::refiner::snapshot_hash(&snapshot);
        if options.compare {
            let cpu = captured.cpu_hashes.get(round).copied();
            if cpu != Some(hash) {
                return Err(GpuDecodeError::HashMismatch {
                    round,
                    gpu: hash,
                    cpu: cpu.unwrap_or(0),
                });
            }
        }
        hashes.push(hash);
        Ok(())
    };
    check(&mut gpu, hashes)?;
    for level in &captured.levels {
        for round in &level.rounds {
            gpu.apply_round(round, level.triangle_limit)?;
            check(&mut gpu, hashes)?;
        }
    }
    captured.error.map_or(Ok(()), |e| Err(e.into()))
}
