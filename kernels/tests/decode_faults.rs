//! The decoder kernels on real devices (lavapipe for WGSL, pocl for OpenCL
//! C in CI): one valid split on an octahedron, every fault the kernels
//! detect, each with the SPEC §10.1 class the reference decoder gives it,
//! and the schedule `every-vertex` (SPEC §6.2, §7.3, §7.5; format 3.6).
//! Each API compiled in (features `wgpu`, `opencl`) is tested; without its
//! device a test prints a skip note, except under `CI`, where it fails.
#![cfg(any(feature = "wgpu", feature = "opencl"))]

use splitstream_kernels::decode::adjacency::check_adjacency;
use splitstream_kernels::decode::host::{BaseMesh, RoundInput, Schedule, Snapshot};
use splitstream_kernels::decode::layout::LEAF;
use splitstream_kernels::decode::{GpuRecord, KernelFault};
use splitstream_kernels::gpu::GpuError;

/// An opened device of one API.
enum Device {
    #[cfg(feature = "wgpu")]
    Wgpu(Box<splitstream_kernels::gpu::WgpuContext>),
    #[cfg(feature = "opencl")]
    OpenCl(splitstream_kernels::gpu::OclContext),
}

fn available<T>(opened: Result<T, GpuError>) -> Option<T> {
    match opened {
        Ok(ctx) => Some(ctx),
        Err(e) if e.is_unavailable() && std::env::var_os("CI").is_none() => {
            eprintln!(
                "skipping {}: {e} (lavapipe: WGPU_BACKEND=vulkan; pocl: pocl-opencl-icd)",
                e.api()
            );
            None
        }
        Err(e) => panic!("no device under CI: {e}"),
    }
}

/// Every API compiled in whose device opens.
fn devices() -> Vec<Device> {
    // The tests run in parallel threads; the OpenCL ICD loader (pocl) can
    // report no device when two threads enumerate at once.
    static OPENING: std::sync::Mutex<()> = std::sync::Mutex::new(());
    let _one_at_a_time = OPENING.lock().unwrap_or_else(|e| e.into_inner());
    let mut out = Vec::new();
    #[cfg(feature = "wgpu")]
    out.extend(available(splitstream_kernels::gpu::open_wgpu()).map(|c| Device::Wgpu(Box::new(c))));
    #[cfg(feature = "opencl")]
    out.extend(available(splitstream_kernels::gpu::open_opencl()).map(Device::OpenCl));
    out
}

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

fn record(offset: u32, distance: u32) -> GpuRecord {
    GpuRecord {
        offset,
        distance,
        config: 0,
        deficit_p: LEAF,
        deficit_c: LEAF,
        position_p: [190, 110, 100],
        position_c: [190, 90, 100],
        _pad: 0,
    }
}

/// Runs one round on the octahedron with `deficits` and returns the state.
fn run(
    device: &Device,
    deficits: [u8; 6],
    candidates: u32,
    flags: u32,
    records: &[GpuRecord],
    triangle_limit: u32,
) -> Snapshot {
    run_in(
        Schedule::SplitValences,
        device,
        deficits,
        candidates,
        flags,
        records,
        triangle_limit,
    )
}

/// [`run`] under `schedule`: under `every-vertex` the per-vertex bytes are
/// valences and every vertex below n is a candidate.
fn run_in(
    schedule: Schedule,
    device: &Device,
    deficits: [u8; 6],
    candidates: u32,
    flags: u32,
    records: &[GpuRecord],
    triangle_limit: u32,
) -> Snapshot {
    let base = BaseMesh {
        positions: &POSITIONS,
        triangles: &OCTAHEDRON,
        deficits: &deficits,
        bits: 8,
    };
    let round = RoundInput {
        candidates,
        flags: &[flags],
        records,
        triangle_limit,
    };
    match device {
        #[cfg(feature = "wgpu")]
        Device::Wgpu(ctx) => {
            use splitstream_kernels::decode::refine::Refiner;
            let mut refiner = Refiner::with_schedule(ctx, base, schedule, 16, 32).expect("refiner");
            refiner.round(round).expect("round");
            refiner.snapshot(true).expect("snapshot")
        }
        #[cfg(feature = "opencl")]
        Device::OpenCl(ctx) => {
            use splitstream_kernels::decode::ocl_refine::OclRefiner;
            let mut refiner =
                OclRefiner::with_schedule(ctx, base, schedule, 16, 32).expect("refiner");
            refiner.round(round).expect("round");
            refiner.snapshot(true).expect("snapshot")
        }
    }
}

#[test]
fn one_split_on_an_octahedron() {
    for ctx in devices() {
        one_split(&ctx);
    }
}

fn one_split(ctx: &Device) {
    // Vertex 0 (+x) is the only candidate; ring [2, 4, 3, 5] from its
    // smallest neighbour; wings r_0 = 2 and r_2 = 3.
    let s = run(ctx, [0, 1, 1, 1, 1, 1], 1, 1, &[record(0, 2)], 32);
    assert_eq!(s.fault, None);
    assert_eq!(s.positions.len(), 7);
    assert_eq!(s.corners.len(), 30);
    assert_eq!(s.positions[0], [190, 110, 100]);
    assert_eq!(s.positions[6], [190, 90, 100]);
    assert_eq!(s.deficits, vec![LEAF as u8, 1, 0, 0, 1, 1, LEAF as u8]);
    // Both new triangles hold P (0) and C (6) and one wing each.
    let new: Vec<&[u32]> = s.corners[24..].chunks(3).collect();
    assert_eq!(new, vec![&[0, 6, 2][..], &[6, 0, 3][..]]);
    check_adjacency(&s.corners, &s.opposite, &s.vertex_corner).expect("adjacency");
    // Every triangle still has three distinct corners and each directed
    // edge is used once (a consistently oriented 2-manifold).
    let mut edges = std::collections::HashSet::new();
    for t in s.corners.chunks(3) {
        for i in 0..3 {
            assert!(
                edges.insert((t[i], t[(i + 1) % 3])),
                "edge used twice in {t:?}"
            );
        }
    }
}

#[test]
fn kernel_faults_have_the_reference_classes() {
    for ctx in devices() {
        faults(&ctx);
    }
}

fn faults(ctx: &Device) {
    let lone = [0, 1, 1, 1, 1, 1];
    let fault = |s: Snapshot| s.fault.map(KernelFault::class);
    assert_eq!(
        fault(run(ctx, lone, 1, 1, &[record(0, 0)], 32)),
        Some("ring-offset-out-of-range")
    );
    assert_eq!(
        fault(run(ctx, lone, 1, 1, &[record(2, 2)], 32)),
        Some("ring-offset-out-of-range")
    );
    let mut far = record(0, 2);
    far.position_c = [256, 0, 0];
    assert_eq!(
        fault(run(ctx, lone, 1, 1, &[far], 32)),
        Some("position-out-of-range")
    );
    let mut heavy = record(0, 2);
    heavy.deficit_p = 254;
    assert_eq!(
        fault(run(ctx, lone, 1, 1, &[heavy], 32)),
        Some("valence-overflow")
    );
    // A wing (2) with deficit 0.
    assert_eq!(
        run(ctx, [0, 1, 0, 1, 1, 1], 2, 0b01, &[record(0, 2)], 32).fault,
        Some(KernelFault::ValenceOverflow { split: 0 })
    );
    // The host says 2 candidates, the GPU finds 1; or 2 flags for 1 record.
    assert_eq!(
        run(ctx, lone, 2, 1, &[record(0, 2)], 32).fault,
        Some(KernelFault::CountMismatch)
    );
    assert_eq!(
        run(ctx, [0, 1, 0, 1, 1, 1], 2, 0b11, &[record(0, 2)], 32).fault,
        Some(KernelFault::CountMismatch)
    );
    // Two new triangles would pass a level limit of 9.
    assert_eq!(
        run(ctx, lone, 1, 1, &[record(0, 2)], 9).fault,
        Some(KernelFault::TriangleLimit { split: 0 })
    );
    // Adjacent flagged vertices 0 and 2 (flags no stream can give, SPEC
    // §7.2): the first of them fails.
    assert_eq!(
        run(
            ctx,
            [0, 1, 0, 1, 1, 1],
            2,
            0b11,
            &[record(0, 2), record(0, 2)],
            32
        )
        .fault,
        Some(KernelFault::AdjacentFlags { split: 0 })
    );
    // Poles 4 and 5 are independent but share their wings 0 and 1 (ring
    // [0, 2, 1, 3] and [0, 3, 1, 2]), which can each lose one more neighbour.
    assert_eq!(
        fault(run(
            ctx,
            [1, 1, 1, 1, 0, 0],
            2,
            0b11,
            &[record(0, 2), record(0, 2)],
            32
        )),
        Some("valence-overflow")
    );
    // The same with room for both: no fault, 8 vertices, 12 triangles.
    let s = run(
        ctx,
        [2, 2, 1, 1, 0, 0],
        2,
        0b11,
        &[record(0, 2), record(0, 2)],
        32,
    );
    assert_eq!(s.fault, None);
    assert_eq!((s.positions.len(), s.corners.len() / 3), (8, 12));
    assert_eq!(&s.deficits[..2], &[0, 0]);
    check_adjacency(&s.corners, &s.opposite, &s.vertex_corner).expect("adjacency");
}

/// A stream too large for the device's buffer limits gets a typed
/// `TooLarge` error naming the buffer, not a validation panic (a 4M-vertex
/// terrain's split records exceed lavapipe's 128 MiB binding limit).
#[cfg(feature = "wgpu")]
#[test]
fn buffers_over_the_device_limits_are_a_typed_error() {
    use splitstream_kernels::decode::host::RefineError;
    use splitstream_kernels::decode::refine::Refiner;
    for device in devices() {
        #[allow(irrefutable_let_patterns)]
        let Device::Wgpu(ctx) = device else { continue };
        let deficits = [LEAF as u8; 6];
        let base = BaseMesh {
            positions: &POSITIONS,
            triangles: &OCTAHEDRON,
            deficits: &deficits,
            bits: 8,
        };
        // 16 M vertices (the most one dispatch grid takes): 768 MB of split
        // records, over lavapipe's 128 MiB; a device that binds that much
        // creates the buffers instead.
        let vertices = 16_000_000u32;
        let needed = 48 * vertices as u64;
        let limit = ctx
            .limits
            .max_storage_buffer_binding_size
            .min(ctx.limits.max_buffer_size);
        match Refiner::new(&ctx, base, vertices, 2 * vertices) {
            Err(RefineError::Gpu(GpuError::TooLarge {
                what, bytes, limit, ..
            })) => {
                assert!(bytes > limit, "{what}: {bytes} <= {limit}");
            }
            Err(e) => panic!("expected TooLarge, got {e}"),
            Ok(_) => assert!(needed <= limit, "{needed} bytes of records over {limit}"),
        }
    }
}

/// Every octahedron vertex has valence 4.
const VALENCES: [u8; 6] = [4; 6];

/// A split with o = 0, d = 2 on a ring of 4: P and C get valence 4 (SPEC
/// §7.4 under `every-vertex`: the record's bytes are the valences).
fn every_vertex_record() -> GpuRecord {
    GpuRecord {
        deficit_p: 4,
        deficit_c: 4,
        position_p: [150, 150, 150],
        position_c: [50, 50, 50],
        ..record(0, 2)
    }
}

/// One round of `records` on the octahedron with per-vertex `bytes`
/// under `schedule`, on every device.
fn every_device(
    schedule: Schedule,
    bytes: [u8; 6],
    candidates: u32,
    flags: u32,
    records: &[GpuRecord],
) -> Vec<Snapshot> {
    devices()
        .iter()
        .map(|d| run_in(schedule, d, bytes, candidates, flags, records, 32))
        .collect()
}

#[test]
fn every_vertex_is_a_candidate_and_wings_gain_a_valence() {
    // Six candidates, flag of candidate 0 = vertex 0 (ring [2, 4, 3, 5],
    // wings 2 and 3). Under split-valences the same bytes hold no deficit-0
    // vertex, so the GPU's candidate count differs from the host's.
    let one = [every_vertex_record()];
    for s in every_device(Schedule::EveryVertex, VALENCES, 6, 1, &one) {
        assert_eq!(s.fault, None);
        assert_eq!(s.deficits, vec![4, 4, 5, 5, 4, 4, 4]);
        assert_eq!(s.positions[6], [50, 50, 50]);
        assert_eq!(s.corners.len(), 30);
    }
    for s in every_device(Schedule::SplitValences, VALENCES, 6, 1, &one) {
        assert_eq!(s.fault, Some(KernelFault::CountMismatch));
    }
    // The candidates are the vertices below n, not the deficit-0 ones.
    for s in every_device(Schedule::EveryVertex, VALENCES, 5, 1, &one) {
        assert_eq!(s.fault, Some(KernelFault::CountMismatch));
    }
}

#[test]
fn every_vertex_skips_the_deficit_checks() {
    // A wing (2) whose byte is 0 and a P byte that would overflow as a
    // deficit: both valence-overflow under split-valences (SPEC §7.5), not
    // checked under every-vertex, where the bytes are stored as they come.
    let heavy = [GpuRecord {
        deficit_p: 254,
        ..every_vertex_record()
    }];
    let bytes = [0, 4, 0, 4, 4, 4];
    for s in every_device(Schedule::EveryVertex, bytes, 6, 1, &heavy) {
        assert_eq!(s.fault, None);
        assert_eq!(s.deficits, vec![254, 4, 1, 5, 4, 4, 4]);
    }
    for s in every_device(Schedule::SplitValences, bytes, 2, 1, &heavy) {
        assert_eq!(s.fault.map(KernelFault::class), Some("valence-overflow"));
    }
}

#[test]
fn shared_wings_gain_one_per_split_up_to_255() {
    // Poles 4 and 5 (candidates 4 and 5) share their wings 0 and 1 (rings
    // [0, 2, 1, 3] and [0, 3, 1, 2]): each gains 2, wing 0 stops at 255
    // from 254, wing 1 stays at 255. A split-valences deficit of 255 would
    // be a leaf; here it is a valence and grows no further.
    let two = [every_vertex_record(); 2];
    let bytes = [254, 255, 4, 4, 4, 4];
    for s in every_device(Schedule::EveryVertex, bytes, 6, 0b11_0000, &two) {
        assert_eq!(s.fault, None);
        assert_eq!((s.positions.len(), s.corners.len() / 3), (8, 12));
        assert_eq!(s.deficits, vec![255, 255, 4, 4, 4, 4, 4, 4]);
    }
    for s in every_device(Schedule::EveryVertex, VALENCES, 6, 0b11_0000, &two) {
        assert_eq!(s.deficits, vec![6, 6, 4, 4, 4, 4, 4, 4]);
    }
}
