//! Property tests of the split logic (SPEC §7): random records on fixed base
//! meshes.
//!
//! * Streams generated from random choices (valid by construction, the way
//!   the encoder replays rounds) decode round by round to exactly the replay's
//!   state hashes; the result is an oriented 2-manifold with boundary whose
//!   vertex count is base + splits and whose Euler characteristic is the
//!   base's.
//! * With injected faults (raw wing offsets, raw deficits, flagged
//!   neighbours) the decoder reports exactly the replay's error.
//! * Completely random record substreams and split counts on a fixed base
//!   give either a valid mesh (same invariants) or a typed error.

#[path = "../fuzz/src/mesh_check.rs"]
mod mesh_check;
#[path = "../fuzz/src/streams.rs"]
mod streams;

use mesh_check::check_oriented_manifold;
use proptest::prelude::*;
use splitstream_decoder_core::limits::LEAF;
use splitstream_decoder_core::owned::decode_all;
use splitstream_decoder_core::writer::{
    ChunkCodec, LevelPayload, StreamParams, SubstreamWriter, write_stream,
};
use splitstream_decoder_core::{DeficitContexts, PlanePolicy, PositionMode, WingPolicy};
use streams::{Choices, bases};

fn base_euler(base: &str) -> i64 {
    let b = bases().into_iter().find(|b| b.name == base).unwrap();
    check_oriented_manifold(b.positions.len(), &b.triangles).unwrap()
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 256, ..ProptestConfig::default() })]

    #[test]
    fn generated_streams_decode_to_the_replay(choices in proptest::collection::vec(any::<u8>(), 0..2048)) {
        let g = streams::generate(&mut Choices::new(&choices), false);
        prop_assert_eq!(g.error, None);
        let d = streams::decode_full(&g.stream);
        prop_assert_eq!(d.error, None);
        if let Err(msg) = streams::check_against(&g, &d) {
            return Err(TestCaseError::fail(msg));
        }
        streams::check_fans_ahead(&g.stream, &d).map_err(TestCaseError::fail)?;
        streams::check_piped(&g.stream, &d).map_err(TestCaseError::fail)?;
        prop_assert_eq!(d.positions.len() as u32, g.base_vertices + g.splits);
        let chi = check_oriented_manifold(d.positions.len(), &d.triangles)
            .map_err(TestCaseError::fail)?;
        prop_assert_eq!(chi, base_euler(g.base), "splits keep the topology");
        // The owned convenience agrees with the no-alloc path.
        let owned = decode_all(&g.stream, true).unwrap();
        prop_assert_eq!(owned.round_hashes, g.hashes);
        prop_assert_eq!(owned.triangles, d.triangles);
    }

    #[test]
    fn injected_faults_give_the_replays_error(choices in proptest::collection::vec(any::<u8>(), 0..2048)) {
        let g = streams::generate(&mut Choices::new(&choices), true);
        let d = streams::decode_full(&g.stream);
        streams::check_fans_ahead(&g.stream, &d).map_err(TestCaseError::fail)?;
        streams::check_piped(&g.stream, &d).map_err(TestCaseError::fail)?;
        if let Err(msg) = streams::check_against(&g, &d) {
            return Err(TestCaseError::fail(msg));
        }
        if d.error.is_none() {
            let chi = check_oriented_manifold(d.positions.len(), &d.triangles)
                .map_err(TestCaseError::fail)?;
            prop_assert_eq!(chi, base_euler(g.base));
        }
    }

    #[test]
    fn random_records_on_a_fixed_base(
        base in 0usize..6,
        deficits in proptest::collection::vec(prop_oneof![Just(0u8), Just(1), Just(2), Just(LEAF), any::<u8>()], 16),
        rounds in proptest::collection::vec(1u32..4, 1..4),
        subs in proptest::collection::vec(proptest::collection::vec(any::<u8>(), 0..24), 8),
        constrained in any::<bool>(),
        extra_triangles in 0u32..8,
        plane in 0u8..splitstream_decoder_core::limits::plane::COUNT,
    ) {
        let b = &bases()[base];
        let nv = b.positions.len();
        let base_level = streams::base_level(b, &deficits[..nv]);
        let splits: u32 = rounds.iter().sum();
        let level = LevelPayload {
            round_splits: rounds,
            plane: PlanePolicy::from_byte(plane).unwrap(),
            wings: WingPolicy::Ranks,
            deficits: DeficitContexts::Plain,
            records: splitstream_decoder_core::RecordOrder::WingsFirst,
            ties: splitstream_decoder_core::Ties::Ring,
            substreams: subs
                .iter()
                .map(|s| {
                    let mut w = SubstreamWriter::default();
                    for &x in s {
                        w.byte(x);
                    }
                    w
                })
                .collect(),
            vertex_count: nv as u32 + splits,
            triangle_count: b.triangles.len() as u32 + splits + extra_triangles.min(splits),
            geometric_error: 0.0,
        };
        let params = StreamParams {
        framing: splitstream_decoder_core::Framing::Compact,
            position_mode: if constrained { PositionMode::Constrained } else { PositionMode::Optimal },
            bits: 8,
            origin: [0.0; 3],
            scale: [1.0; 3],
            codec: ChunkCodec::Stored,
            chunk_limit: 5,
            rans_chunk_limit: 5,
            schedule: splitstream_decoder_core::Schedule::SplitValences,
            adaptive_tables: true,
        };
        let stream = write_stream(&params, &[base_level, level]);
        let d = streams::decode_full(&stream);
        streams::check_piped(&stream, &d).map_err(TestCaseError::fail)?;
        match decode_all(&stream, true) {
            Ok(mesh) => {
                prop_assert_eq!(mesh.positions.len(), nv + splits as usize);
                let chi = check_oriented_manifold(mesh.positions.len(), &mesh.triangles)
                    .map_err(TestCaseError::fail)?;
                prop_assert_eq!(chi, base_euler(b.name));
            }
            Err(e) => {
                prop_assert!(!e.class().is_empty());
            }
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 256, ..ProptestConfig::default() })]

    /// The `decode_mutated` fuzz target's edits (records, split counts,
    /// level counts, stream parameters of deep seed streams, reframed with
    /// valid checksums): the records read through a pipe decode exactly as
    /// the one-thread rounds, errors included.
    #[test]
    fn piped_records_decode_mutated_streams_alike(
        pick in any::<u8>(),
        ops in proptest::collection::vec(any::<u8>(), 1..96),
    ) {
        let seeds = seeds();
        let seed = &seeds[pick as usize % seeds.len()];
        let (params, levels) = streams::mutate_levels(seed, &mut Choices::new(&ops));
        let stream = streams::frame(&params, &levels, seed.seeded);
        let d = streams::decode_full(&stream);
        streams::check_piped(&stream, &d).map_err(TestCaseError::fail)?;
    }
}

fn seeds() -> &'static [streams::Generated] {
    static SEEDS: std::sync::OnceLock<Vec<streams::Generated>> = std::sync::OnceLock::new();
    SEEDS.get_or_init(streams::seed_generated)
}

/// The seed streams of the fuzz targets all decode and keep the invariants.
#[test]
fn seed_streams_are_valid_manifolds() {
    for g in streams::seed_generated() {
        let d = streams::decode_full(&g.stream);
        streams::check_against(&g, &d).unwrap();
        let chi = check_oriented_manifold(d.positions.len(), &d.triangles).unwrap();
        assert_eq!(chi, base_euler(g.base), "{}", g.base);
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 256, ..ProptestConfig::default() })]

    /// `RecordsHalf::read` (decoder-core's `pipe`) asked for records with
    /// any vertex ids, ring entries and C indices: a record or a typed
    /// error, never a panic; and after an error, that error again.
    #[test]
    fn records_half_answers_garbage_with_errors(
        pick in any::<u8>(),
        asks in proptest::collection::vec(
            (any::<u32>(), any::<u32>(), proptest::collection::vec(any::<u32>(), 0..300)),
            1..8,
        ),
    ) {
        use splitstream_decoder_core::Inflater;
        use splitstream_decoder_core::owned::OwnedWorkspace;
        let seeds = seeds();
        let stream = &seeds[pick as usize % seeds.len()].stream;
        let mut ws = OwnedWorkspace::for_stream(stream).unwrap();
        let mut decoder = ws.decoder(stream).unwrap();
        let mut mirror = vec![[0u32; 3]; decoder.state().vertex_capacity() as usize];
        let mut inflater = Box::new(Inflater::new());
        let bytes = decoder.level_bytes(0, stream).unwrap();
        let mut level = decoder.begin_level(0, bytes).unwrap();
        let n = level.state().vertex_count();
        let mut half = level.split_records(&mut inflater, &mut mirror).unwrap();
        let mut failed = None;
        for (r, c, vertices) in &asks {
            // Some asks name real vertices, so that records are read too.
            let r = if r % 2 == 0 { r % n.max(1) } else { *r };
            let mut ring = splitstream_decoder_core::Ring::default();
            let eligible = if ring.set_vertices(&vertices[..vertices.len().min(255)]) {
                level.state().wing_candidates(&ring)
            } else {
                Default::default()
            };
            let got = half.read(r, *c, vertices, &eligible);
            if let Some(e) = failed {
                prop_assert_eq!(got, Err(e));
            } else if let Err(e) = got {
                prop_assert!(!e.class().is_empty());
                failed = Some(e);
            }
        }
        level.join_records(half);
    }
}

/// The generator reads records positions first (format 3.7) on some of its
/// constrained `height` levels, and those levels split vertices: the
/// property tests above then cover that record order too.
#[test]
fn generated_streams_read_positions_first_records() {
    use splitstream_decoder_core::RecordOrder;
    let mut levels = 0;
    let mut splits = 0u32;
    for seed in 1..=400u64 {
        let bytes = streams::pseudo_random_bytes(seed, 4096);
        let g = streams::generate(&mut Choices::new(&bytes), false);
        assert_eq!(g.error, None, "seed {seed}");
        let d = streams::decode_full(&g.stream);
        streams::check_against(&g, &d).unwrap_or_else(|e| panic!("seed {seed}: {e}"));
        for l in g
            .levels
            .iter()
            .filter(|l| l.records == RecordOrder::PositionsFirst)
        {
            levels += 1;
            splits += l.round_splits.iter().sum::<u32>();
        }
    }
    assert!(
        levels >= 5 && splits >= 50,
        "{levels} levels, {splits} splits"
    );
}
