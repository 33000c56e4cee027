//! The schedule `every-vertex` (SPEC §6.2, §7.3, §7.5; format 3.6) on real
//! devices (lavapipe, pocl), on the octahedron of kernels/tests/
//! decode_faults.rs: every vertex is a candidate, the per-vertex word is the
//! valence (a wing's grows by one, capped at 255, also when two splits share
//! it), and the deficit checks of `split-valences` do not apply. No stream
//! is needed: the rounds are written by hand, as decoder-core would read
//! them. Without a device a test prints a skip note, except under `CI`.

use super::host::{BaseMesh, RoundInput, Schedule, Snapshot};
use super::layout::{GpuRecord, KernelFault};
use crate::gpu::GpuError;

/// +x, -x, +y, -y, +z, -z; counter-clockwise seen from outside.
const OCTAHEDRON: [[u32; 3]; 8] = [
    [4, 0, 2],
    [4, 2, 1],
    [4, 1, 3],
    [4, 3, 0],
    [5, 2, 0],
    [5, 1, 2],
    [5, 3, 1],
    [5, 0, 3],
];
const POSITIONS: [[u32; 3]; 6] = [
    [200, 100, 100],
    [0, 100, 100],
    [100, 200, 100],
    [100, 0, 100],
    [100, 100, 200],
    [100, 100, 0],
];
/// Every octahedron vertex has valence 4.
const VALENCES: [u8; 6] = [4; 6];

fn available<T>(opened: Result<T, GpuError>) -> Option<T> {
    match opened {
        Ok(ctx) => Some(ctx),
        Err(e) if e.is_unavailable() && std::env::var_os("CI").is_none() => {
            eprintln!("skipping {}: {e}", e.api());
            None
        }
        Err(e) => panic!("no device under CI: {e}"),
    }
}

/// A split with o = 0, d = 2 on a ring of 4: P and C get valence 4 (SPEC
/// §7.4 under every-vertex: the record's bytes are the valences).
fn record() -> GpuRecord {
    GpuRecord {
        offset: 0,
        distance: 2,
        config: 0,
        deficit_p: 4,
        deficit_c: 4,
        position_p: [150, 150, 150],
        position_c: [50, 50, 50],
        _pad: 0,
    }
}

/// One round on the octahedron with per-vertex `bytes`, under `schedule`,
/// on every API compiled in whose device opens.
fn run(
    schedule: Schedule,
    bytes: [u8; 6],
    candidates: u32,
    flags: u32,
    records: &[GpuRecord],
) -> Vec<Snapshot> {
    // The tests run in parallel; pocl can report no device when two
    // threads enumerate at once.
    static OPENING: std::sync::Mutex<()> = std::sync::Mutex::new(());
    let _one_at_a_time = OPENING.lock().unwrap_or_else(|e| e.into_inner());
    let base = BaseMesh {
        positions: &POSITIONS,
        triangles: &OCTAHEDRON,
        deficits: &bytes,
        bits: 8,
    };
    let round = RoundInput {
        candidates,
        flags: &[flags],
        records,
        triangle_limit: 32,
    };
    let mut out = Vec::new();
    #[cfg(feature = "wgpu")]
    if let Some(ctx) = available(crate::gpu::open_wgpu()) {
        let mut refiner =
            super::refine::Refiner::with_schedule(&ctx, base, schedule, 16, 32).expect("refiner");
        refiner.round(round).expect("round");
        out.push(refiner.snapshot(true).expect("snapshot"));
    }
    #[cfg(feature = "opencl")]
    if let Some(ctx) = available(crate::gpu::open_opencl()) {
        let mut refiner =
            super::ocl_refine::OclRefiner::with_schedule(&ctx, base, schedule, 16, 32)
                .expect("refiner");
        refiner.round(round).expect("round");
        out.push(refiner.snapshot(true).expect("snapshot"));
    }
    out
}

#[test]
fn every_vertex_is_a_candidate_and_wings_gain_a_valence() {
    // Six candidates, flag of candidate 0 = vertex 0 (ring [2, 4, 3, 5],
    // wings 2 and 3). Under split-valences the same bytes hold no deficit-0
    // vertex, so the GPU's candidate count differs from the host's.
    for s in run(Schedule::EveryVertex, VALENCES, 6, 1, &[record()]) {
        assert_eq!(s.fault, None);
        assert_eq!(s.deficits, vec![4, 4, 5, 5, 4, 4, 4]);
        assert_eq!(s.positions[6], [50, 50, 50]);
        assert_eq!(s.corners.len(), 30);
    }
    for s in run(Schedule::SplitValences, VALENCES, 6, 1, &[record()]) {
        assert_eq!(s.fault, Some(KernelFault::CountMismatch));
    }
    // The candidates are the vertices below n, not the deficit-0 ones.
    for s in run(Schedule::EveryVertex, VALENCES, 5, 1, &[record()]) {
        assert_eq!(s.fault, Some(KernelFault::CountMismatch));
    }
}

#[test]
fn every_vertex_skips_the_deficit_checks() {
    // A wing (2) whose byte is 0 and a P byte that would overflow as a
    // deficit: both valence-overflow under split-valences (SPEC §7.5), not
    // checked under every-vertex, where the bytes are stored as they come.
    let mut heavy = record();
    heavy.deficit_p = 254;
    let bytes = [0, 4, 0, 4, 4, 4];
    for s in run(Schedule::EveryVertex, bytes, 6, 1, &[heavy]) {
        assert_eq!(s.fault, None);
        assert_eq!(s.deficits, vec![254, 4, 1, 5, 4, 4, 4]);
    }
    for s in run(Schedule::SplitValences, bytes, 2, 1, &[heavy]) {
        assert_eq!(s.fault.map(KernelFault::class), Some("valence-overflow"));
    }
}

#[test]
fn shared_wings_gain_one_per_split_up_to_255() {
    // Poles 4 and 5 (candidates 4 and 5) share their wings 0 and 1 (rings
    // [0, 2, 1, 3] and [0, 3, 1, 2]): each gains 2, wing 0 stops at 255
    // from 254, wing 1 stays at 255. A split-valences deficit of 255 would
    // be a leaf; here it is a valence and grows no further.
    let bytes = [254, 255, 4, 4, 4, 4];
    for s in run(Schedule::EveryVertex, bytes, 6, 0b11_0000, &[record(); 2]) {
        assert_eq!(s.fault, None);
        assert_eq!((s.positions.len(), s.corners.len() / 3), (8, 12));
        assert_eq!(s.deficits, vec![255, 255, 4, 4, 4, 4, 4, 4]);
    }
    for s in run(
        Schedule::EveryVertex,
        VALENCES,
        6,
        0b11_0000,
        &[record(); 2],
    ) {
        assert_eq!(s.deficits, vec![6, 6, 4, 4, 4, 4, 4, 4]);
    }
}
