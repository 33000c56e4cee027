//! decode(encode(M)) gives M back exactly: the same oriented triangles after
//! mapping decoded vertices to input ids, and the quantized positions.

mod common;
mod roundtrip_check;

use roundtrip_check::assert_roundtrip;

use splitstream_decoder_core::writer::ChunkCodec;
use splitstream_decoder_core::{
    DeficitContexts, Header, LevelHeader, LevelTable, PlanePolicy, PositionMode, RecordOrder,
    Schedule, Ties, WingPolicy,
};
use splitstream_encoder::emit::{EncodeOptions, encode};
use splitstream_encoder::quantize::{Lattice, Quantization, Units};

#[test]
fn closed_sphere_roundtrips() {
    let mesh = common::icosphere(3);
    assert_roundtrip(&mesh, &EncodeOptions::default());
}

#[test]
fn grid_with_boundary_roundtrips() {
    let mesh = common::bumpy_grid(23, 17, 1);
    assert_roundtrip(&mesh, &EncodeOptions::default());
}

/// The default is constrained mode (since 2026-12-03): the same meshes
/// in optimal mode.
#[test]
fn optimal_mode_roundtrips() {
    let options = EncodeOptions {
        position_mode: PositionMode::Optimal,
        ..EncodeOptions::default()
    };
    assert_roundtrip(&common::icosphere(3), &options);
    assert_roundtrip(&common::bumpy_grid(23, 17, 1), &options);
    assert_roundtrip(&common::icosphere(2), &options);
    assert_roundtrip(&common::bumpy_grid(15, 12, 2), &options);
}

#[test]
fn locked_boundary_and_one_level() {
    let mesh = common::bumpy_grid(12, 12, 3);
    let options = EncodeOptions {
        lock_boundary: true,
        levels: 1,
        ..EncodeOptions::default()
    };
    assert_roundtrip(&mesh, &options);
    let options = EncodeOptions {
        lock_boundary: true,
        levels: 7,
        ..EncodeOptions::default()
    };
    assert_roundtrip(&mesh, &options);
}

#[test]
fn uniform_quantization_roundtrips() {
    // One step for all axes; the stream's per-axis origin and scale say so.
    for units in [Units::Linear, Units::Geographic] {
        let options = EncodeOptions {
            quantization: Quantization::Uniform,
            units,
            ..EncodeOptions::default()
        };
        assert_roundtrip(&common::bumpy_grid(19, 13, 2), &options);
    }
}

#[test]
fn every_plane_policy_roundtrips_at_31_bits() {
    for (i, plane) in PlanePolicy::ALL.into_iter().enumerate() {
        let options = EncodeOptions {
            bits: if i % 2 == 0 { 31 } else { 14 },
            plane: Some(plane),
            position_mode: if i % 2 == 0 {
                PositionMode::Constrained
            } else {
                PositionMode::Optimal
            },
            ..EncodeOptions::default()
        };
        assert_roundtrip(&common::icosphere(2), &options);
    }
    for mode in [PositionMode::Constrained, PositionMode::Optimal] {
        let options = EncodeOptions {
            bits: 31,
            position_mode: mode,
            ..EncodeOptions::default()
        };
        assert_roundtrip(&common::bumpy_grid(21, 17, 1), &options);
    }
}

/// Format 3.1's plane policy `height` on terrain, in both position modes,
/// at 14 and 31 bits; a stream that uses it (and no 3.2 wing policy) says
/// minor version 1, one that uses neither stays 3.0 (SPEC §1).
#[test]
fn height_policy_roundtrips_and_sets_the_minor_version() {
    let terrain = common::bumpy_grid(21, 17, 3);
    for mode in [PositionMode::Constrained, PositionMode::Optimal] {
        for bits in [14, 31] {
            for (plane, minor) in [(PlanePolicy::Height, 1), (PlanePolicy::Axis(2), 0)] {
                let options = EncodeOptions {
                    // Static tables: the minor version is the feature's (3.9 adds none here).
                    adaptive_tables: false,
                    // The fixed framing: the compact one (3.11) would raise it to 11.
                    framing: splitstream_decoder_core::Framing::Fixed,
                    bits,
                    plane: Some(plane),
                    wings: Some(WingPolicy::Ranks),
                    deficits: Some(DeficitContexts::Plain),
                    position_mode: mode,
                    schedule: Schedule::SplitValences,
                    // Wings first: the minor version of the feature under test
                    // (positions first, 3.7, would raise it to 7).
                    records: Some(RecordOrder::WingsFirst),
                    ..EncodeOptions::default()
                };
                assert_roundtrip(&terrain, &options);
                let encoded = encode(&terrain, &options, |_| {}).expect("encode");
                assert_eq!(encoded.stream[9], minor, "{mode:?} {bits} {plane:?}");
            }
        }
    }
}

/// Format 3.2's wing policies, forced in every level, on a closed mesh and
/// on terrain with a boundary (the ghost is eligible), in both position
/// modes, at 14 and 31 bits; `near` and `near-xy` set minor version 2,
/// `ranks` leaves it at 0 (SPEC §1, §7.4).
#[test]
fn every_wing_policy_roundtrips_and_sets_the_minor_version() {
    let meshes = [common::icosphere(2), common::bumpy_grid(21, 17, 3)];
    for mesh in &meshes {
        for mode in [PositionMode::Constrained, PositionMode::Optimal] {
            for bits in [14, 31] {
                for (wings, minor) in [
                    (WingPolicy::Ranks, 0),
                    (WingPolicy::Near, 2),
                    (WingPolicy::NearXy, 2),
                ] {
                    let options = EncodeOptions {
                        // Static tables: the minor version is the feature's (3.9 adds none here).
                        adaptive_tables: false,
                        // The fixed framing: the compact one (3.11) would raise it to 11.
                        framing: splitstream_decoder_core::Framing::Fixed,
                        bits,
                        plane: Some(PlanePolicy::Dominant),
                        wings: Some(wings),
                        deficits: Some(DeficitContexts::Plain),
                        position_mode: mode,
                        schedule: Schedule::SplitValences,
                        ..EncodeOptions::default()
                    };
                    assert_roundtrip(mesh, &options);
                    let encoded = encode(mesh, &options, |_| {}).expect("encode");
                    assert_eq!(encoded.stream[9], minor, "{mode:?} {bits} {wings:?}");
                }
            }
        }
    }
}

/// The default picks the wing policy per level by size: not larger than
/// `ranks` everywhere (on a tie `ranks` is kept). The choice ranks the two
/// wing substreams as rANS codes them, and the framing may still pick
/// deflate for a chunk, so a few bytes of slack are allowed.
#[test]
fn the_chosen_wing_policy_is_never_larger_than_ranks() {
    for mesh in [common::icosphere(3), common::bumpy_grid(31, 23, 2)] {
        let auto = encode(&mesh, &EncodeOptions::default(), |_| {}).expect("encode");
        let ranks = EncodeOptions {
            wings: Some(WingPolicy::Ranks),
            ..EncodeOptions::default()
        };
        let ranks = encode(&mesh, &ranks, |_| {}).expect("encode");
        assert!(auto.stream.len() <= ranks.stream.len() + 64);
    }
}

/// Format 3.3's deficit contexts, forced in every level, on a closed mesh
/// and on terrain with a boundary, in both position modes, at 14 and 31
/// bits; `valence` sets minor version 3, `plain` (with `ranks` wings) leaves
/// it at 0 (SPEC §1, §5.5.5).
#[test]
fn both_deficit_contexts_roundtrip_and_set_the_minor_version() {
    let meshes = [common::icosphere(2), common::bumpy_grid(21, 17, 3)];
    for mesh in &meshes {
        for mode in [PositionMode::Constrained, PositionMode::Optimal] {
            for bits in [14, 31] {
                for (deficits, minor) in
                    [(DeficitContexts::Plain, 0), (DeficitContexts::Valence, 3)]
                {
                    let options = EncodeOptions {
                        // Static tables: the minor version is the feature's (3.9 adds none here).
                        adaptive_tables: false,
                        // The fixed framing: the compact one (3.11) would raise it to 11.
                        framing: splitstream_decoder_core::Framing::Fixed,
                        bits,
                        plane: Some(PlanePolicy::Dominant),
                        wings: Some(WingPolicy::Ranks),
                        deficits: Some(deficits),
                        position_mode: mode,
                        schedule: Schedule::SplitValences,
                        ..EncodeOptions::default()
                    };
                    assert_roundtrip(mesh, &options);
                    let encoded = encode(mesh, &options, |_| {}).expect("encode");
                    assert_eq!(encoded.stream[9], minor, "{mode:?} {bits} {deficits:?}");
                }
            }
        }
    }
}

/// The default picks the deficit contexts per level by size: not larger
/// than `plain` everywhere (a few bytes of slack, as for the wings).
#[test]
fn the_chosen_deficit_contexts_are_never_larger_than_plain() {
    for mesh in [common::icosphere(3), common::bumpy_grid(31, 23, 2)] {
        let auto = encode(&mesh, &EncodeOptions::default(), |_| {}).expect("encode");
        let plain = EncodeOptions {
            deficits: Some(DeficitContexts::Plain),
            schedule: Schedule::SplitValences,
            ..EncodeOptions::default()
        };
        let plain = encode(&mesh, &plain, |_| {}).expect("encode");
        assert!(auto.stream.len() <= plain.stream.len() + 64);
    }
}

/// Format 3.10's flag contexts under `every-vertex`, forced in every
/// level, on a closed mesh and on terrain with a boundary, in both position
/// modes, at 14 and 31 bits: both round-trip, `split-history` sets minor
/// version 10 and says byte 2 in every level header, `valence` leaves the
/// stream at 6 (with static tables and wings-first records) (SPEC §1, §5.1,
/// §5.5.5). The split-history bits are cleared at each level's start and
/// set by every split (SPEC §6.1, §7.5): the decoder's state hash after
/// every round is the encoder's, which is what `assert_roundtrip` checks.
#[test]
fn both_flag_contexts_roundtrip_and_set_the_minor_version() {
    let meshes = [common::icosphere(2), common::bumpy_grid(21, 17, 3)];
    for mesh in &meshes {
        for mode in [PositionMode::Constrained, PositionMode::Optimal] {
            for bits in [14, 31] {
                for (flags, minor, byte) in [
                    (DeficitContexts::Plain, 6, 0),
                    (DeficitContexts::SplitHistory, 10, 2),
                ] {
                    let options = EncodeOptions {
                        adaptive_tables: false,
                        // The fixed framing: the compact one (3.11) would mark 11.
                        framing: splitstream_decoder_core::Framing::Fixed,
                        bits,
                        deficits: Some(flags),
                        records: Some(RecordOrder::WingsFirst),
                        position_mode: mode,
                        schedule: Schedule::EveryVertex,
                        ..EncodeOptions::default()
                    };
                    assert_roundtrip(mesh, &options);
                    let stream = encode(mesh, &options, |_| {}).expect("encode").stream;
                    assert_eq!(stream[9], minor, "{mode:?} {bits} {flags:?}");
                    let header = Header::parse(&stream).unwrap();
                    let table = LevelTable::parse(&stream, &header).unwrap();
                    for k in 0..table.len() {
                        let e = table.get(k);
                        let level =
                            &stream[e.offset as usize..(e.offset + e.length as u64) as usize];
                        let lh = LevelHeader::parse(level, k == 0, header.level_rules()).unwrap();
                        assert_eq!(
                            lh.deficit_contexts.to_byte(),
                            byte,
                            "{mode:?} {bits} level {k}"
                        );
                    }
                }
            }
        }
    }
}

/// `split-history` names flag contexts, which only `every-vertex` codes:
/// asked for under `split-valences` it is refused with a message, not
/// written as a byte 10 no decoder accepts (SPEC §5.1).
#[test]
fn split_history_under_split_valences_is_refused() {
    let options = EncodeOptions {
        deficits: Some(DeficitContexts::SplitHistory),
        schedule: Schedule::SplitValences,
        ..EncodeOptions::default()
    };
    let err = match encode(&common::icosphere(2), &options, |_| {}) {
        Ok(_) => panic!("split-history under split-valences was encoded"),
        Err(e) => e.to_string(),
    };
    assert!(
        err.contains("split-history") && err.contains("every-vertex"),
        "{err}"
    );
}

/// By default a small level keeps whichever flag contexts code smaller:
/// never larger than `valence` (a few bytes of slack), and a large enough
/// refinement takes `split-history` somewhere.
#[test]
fn the_chosen_flag_contexts_are_never_larger_than_valence() {
    for mesh in [common::icosphere(3), common::bumpy_grid(61, 53, 2)] {
        let auto = encode(&mesh, &EncodeOptions::default(), |_| {}).expect("encode");
        let valence = EncodeOptions {
            deficits: Some(DeficitContexts::Plain),
            ..EncodeOptions::default()
        };
        let valence = encode(&mesh, &valence, |_| {}).expect("encode");
        assert!(auto.stream.len() <= valence.stream.len() + 16);
    }
}

#[test]
fn rasters_keep_their_lattice_exactly() {
    // Heights in whole units (as the Jacksboro DEM's metres): all three
    // axes lie on a lattice; x and y step 10 with 23 and 17 samples.
    let mut mesh = common::bumpy_grid(23, 17, 4);
    for p in &mut mesh.positions {
        p[2] = (p[2] * 10.0).round();
    }
    let constrained = EncodeOptions {
        position_mode: PositionMode::Constrained,
        ..EncodeOptions::default()
    };
    // Decoded positions are checked to be exact on every lattice axis.
    assert_roundtrip(&mesh, &constrained);
    let encoded = splitstream_encoder::emit::encode(&mesh, &constrained, |_| {}).unwrap();
    assert_eq!(encoded.on_lattice, [true; 3]);
    // Optimal mode ignores lattices unless asked; forced, it keeps them.
    let optimal = EncodeOptions {
        position_mode: PositionMode::Optimal,
        ..EncodeOptions::default()
    };
    let encoded = splitstream_encoder::emit::encode(&mesh, &optimal, |_| {}).unwrap();
    assert_eq!(encoded.on_lattice, [false; 3]);
    let forced = EncodeOptions {
        lattice: Some(Lattice::Keep),
        ..optimal.clone()
    };
    assert_roundtrip(&mesh, &forced);
    // And constrained mode can be told to ignore them.
    let ignored = EncodeOptions {
        lattice: Some(Lattice::Ignore),
        ..constrained
    };
    assert_roundtrip(&mesh, &ignored);
    let encoded = splitstream_encoder::emit::encode(&mesh, &ignored, |_| {}).unwrap();
    assert_eq!(encoded.on_lattice, [false; 3]);
}

#[test]
fn the_default_position_mode_is_constrained_and_keeps_a_lattice() {
    // A raster with whole-unit heights: x, y and z on a lattice.
    let mut raster = common::bumpy_grid(19, 13, 5);
    for p in &mut raster.positions {
        p[2] = (p[2] * 4.0).round();
    }
    let defaults = EncodeOptions::default();
    assert_eq!(defaults.position_mode, PositionMode::Constrained);
    let encoded = splitstream_encoder::emit::encode(&raster, &defaults, |_| {}).unwrap();
    assert_eq!(encoded.on_lattice, [true; 3]);
    let header = splitstream_decoder_core::Header::parse(&encoded.stream).unwrap();
    assert_eq!(header.position_mode, PositionMode::Constrained);
    assert_roundtrip(&raster, &defaults);
    // A mesh without a lattice: constrained too, and smaller than in
    // optimal mode (one vector per split instead of two).
    let sphere = common::icosphere(3);
    let constrained = splitstream_encoder::emit::encode(&sphere, &defaults, |_| {}).unwrap();
    let optimal = EncodeOptions {
        position_mode: PositionMode::Optimal,
        ..defaults
    };
    let optimal = splitstream_encoder::emit::encode(&sphere, &optimal, |_| {}).unwrap();
    assert!(
        constrained.stream.len() < optimal.stream.len(),
        "{} < {}",
        constrained.stream.len(),
        optimal.stream.len()
    );
}

/// Format 3.4: `max_chunk_len` bounds stored and deflate chunks only
/// (SPEC §5.2). A stream whose rANS chunks code more values than a
/// decoder's minimum buffer (RANS_SLOT_BYTES) declares its largest byte-codec
/// chunk and minor version 4; one whose rANS chunks fit within that buffer
/// declares the largest chunk of any codec and stays readable by 3.3.
#[test]
fn rans_chunks_beyond_max_chunk_len_set_minor_version_4() {
    use splitstream_decoder_core::Header;
    let large = common::bumpy_grid(80, 60, 5);
    for (codec, chunk_limit) in [
        (ChunkCodec::RansAlways { lanes: 4 }, 512),
        (ChunkCodec::Rans { lanes: 4 }, 512),
        (ChunkCodec::Rans { lanes: 2 }, 16 * 1024),
    ] {
        let options = EncodeOptions {
            // Static tables: the minor version is the feature's (3.9 adds none here).
            adaptive_tables: false,
            // The fixed framing: the compact one (3.11) would raise it to 11.
            framing: splitstream_decoder_core::Framing::Fixed,
            codec,
            chunk_limit,
            position_mode: PositionMode::Constrained,
            schedule: Schedule::SplitValences,
            // Wings first: the minor version of the feature under test
            // (positions first, 3.7, would raise it to 7; the compact
            // framing, 3.11, to 11).
            records: Some(RecordOrder::WingsFirst),
            ..EncodeOptions::default()
        };
        assert_roundtrip(&large, &options);
        let stream = encode(&large, &options, |_| {}).expect("encode").stream;
        let header = Header::parse(&stream).unwrap();
        assert_eq!(header.version_minor, 4, "{codec:?} {chunk_limit}");
        assert!(
            header.max_chunk_len <= chunk_limit,
            "{codec:?} {chunk_limit}"
        );
        if matches!(codec, ChunkCodec::RansAlways { .. }) {
            // No stored or deflate chunk at all.
            assert_eq!(header.max_chunk_len, 1);
        }
    }
    // Short rANS chunks: the largest chunk of any codec, 3.3 at most.
    let small = common::icosphere(2);
    let options = EncodeOptions {
        // Static tables: the minor version is the feature's (3.9 adds none here).
        adaptive_tables: false,
        // The fixed framing: the compact one (3.11) would raise it to 11.
        framing: splitstream_decoder_core::Framing::Fixed,
        codec: ChunkCodec::RansAlways { lanes: 4 },
        schedule: Schedule::SplitValences,
        ..EncodeOptions::default()
    };
    let stream = encode(&small, &options, |_| {}).expect("encode").stream;
    let header = Header::parse(&stream).unwrap();
    assert!(header.version_minor <= 3);
    assert!(header.max_chunk_len > 1 && header.max_chunk_len <= 1856);
}

/// The schedule `every-vertex` (format 3.6, the default) round-trips
/// exactly on closed meshes and on terrain with a boundary, in both
/// position modes, at 14 and 31 bits, with every codec; it marks minor
/// version 6, and the decoded mesh is the one split valences give.
#[test]
fn every_vertex_roundtrips_and_sets_the_minor_version() {
    use splitstream_decoder_core::owned::decode_all;
    let meshes = [
        common::icosphere(3),
        common::bumpy_grid(21, 17, 3),
        common::bumpy_grid(31, 23, 2),
    ];
    for mesh in &meshes {
        for mode in [PositionMode::Constrained, PositionMode::Optimal] {
            for (bits, codec) in [
                (14, ChunkCodec::Rans { lanes: 4 }),
                (31, ChunkCodec::RansAlways { lanes: 1 }),
                (14, ChunkCodec::Deflate(9)),
                (12, ChunkCodec::Stored),
            ] {
                let options = EncodeOptions {
                    // Static tables: the minor version is the feature's (3.9 adds none here).
                    adaptive_tables: false,
                    // The fixed framing: the compact one (3.11) would raise it to 11.
                    framing: splitstream_decoder_core::Framing::Fixed,
                    bits,
                    codec,
                    position_mode: mode,
                    schedule: Schedule::EveryVertex,
                    // Wings first: the minor version of the feature under test
                    // (positions first, 3.7, would raise it to 7).
                    records: Some(RecordOrder::WingsFirst),
                    ..EncodeOptions::default()
                };
                assert_roundtrip(mesh, &options);
                let every = encode(mesh, &options, |_| {}).expect("encode").stream;
                assert_eq!(every[9], 6, "{mode:?} {bits} {codec:?}");
                let split = EncodeOptions {
                    // Static tables: the minor version is the feature's (3.9 adds none here).
                    adaptive_tables: false,
                    // The fixed framing: the compact one (3.11) would raise it to 11.
                    framing: splitstream_decoder_core::Framing::Fixed,
                    schedule: Schedule::SplitValences,
                    ..options
                };
                let split = encode(mesh, &split, |_| {}).expect("encode").stream;
                assert!(split[9] < 6);
                let (a, b) = (
                    decode_all(&every, false).unwrap(),
                    decode_all(&split, false).unwrap(),
                );
                assert_eq!((a.positions, a.triangles), (b.positions, b.triangles));
            }
        }
    }
}

/// At 4 bits an icosphere of 642 vertices has coincident vertices and
/// triangles without area. A collapse is checked against each triangle's
/// old normal; a triangle without one is now held to its vertex's fan
/// normal, where before it refused every collapse of its corners: the
/// simplification stopped at 140 vertices, it now goes on to 88 (and
/// bunny00 at 8 bits from 2,613 to 2,395 vertices in level 0's 63 rounds,
/// 108,895 -> 95,821 bytes). The round trip stays exact.
#[test]
fn triangles_without_area_do_not_stop_the_simplification() {
    use splitstream_encoder::emit::quantize_for;
    use splitstream_encoder::simplify::{Checked, SimplifyOptions, simplify};

    let mesh = common::icosphere(3);
    let options = EncodeOptions {
        bits: 4,
        ..EncodeOptions::default()
    };
    let q = quantize_for(&mesh, &options);
    let checked = Checked::new(&q).expect("a closed manifold");
    let s = simplify(
        &checked,
        &SimplifyOptions {
            target_vertices: 16,
            ..SimplifyOptions::default()
        },
        |_| {},
    );
    assert!(
        s.alive_count <= 100,
        "stopped at {} vertices",
        s.alive_count
    );
    assert_roundtrip(&mesh, &options);
}

/// The encoder simplifies in its own spatial order (`spatial_order`): the
/// same mesh with its vertices and triangles listed in another order, and
/// its triangles starting at other corners, gives the same stream, and the
/// permutation names the same vertices in the file's new ids.
#[test]
fn the_stream_does_not_depend_on_the_input_order() {
    for (name, mesh) in [
        ("icosphere", common::icosphere(3)),
        ("grid", common::bumpy_grid(23, 17, 1)),
    ] {
        let n = mesh.positions.len();
        // Vertex v of `mesh` is vertex new_id[v] of `shuffled`.
        let new_id: Vec<u32> = (0..n).map(|v| ((v * 101 + 7) % n) as u32).collect();
        let mut positions = vec![[0.0; 3]; n];
        for (v, &w) in new_id.iter().enumerate() {
            positions[w as usize] = mesh.positions[v];
        }
        let mut triangles: Vec<[u32; 3]> = mesh
            .triangles
            .iter()
            .enumerate()
            .map(|(i, t)| {
                let mut t = t.map(|v| new_id[v as usize]);
                t.rotate_left(i % 3);
                t
            })
            .collect();
        triangles.reverse();
        let shuffled = splitstream_encoder::Mesh {
            positions,
            triangles,
        };
        for mode in [PositionMode::Constrained, PositionMode::Optimal] {
            let options = EncodeOptions {
                position_mode: mode,
                ..EncodeOptions::default()
            };
            let a = encode(&mesh, &options, |_| {}).unwrap();
            let b = encode(&shuffled, &options, |_| {}).unwrap();
            assert!(a.stream == b.stream, "{name}, {mode:?}: the same stream");
            let renamed: Vec<u32> = a.permutation.iter().map(|&v| new_id[v as usize]).collect();
            assert_eq!(renamed, b.permutation, "{name}, {mode:?}");
        }
    }
}

/// Format 3.7's record order `positions-first`, forced in every level, on
/// terrain with and without a boundary and on a closed mesh (whose fans
/// fold over in xy: escapes), under both schedules and both codecs: the
/// round trip is exact, the minor version is 7, or 8 where a level breaks
/// its ties by a diagonal (3.8), and the level headers say so (SPEC §1,
/// §5.1, §7.4).
#[test]
fn positions_first_roundtrips_and_sets_the_minor_version() {
    let meshes = [
        common::bumpy_grid(21, 17, 3),
        common::icosphere(2),
        splitstream_encoder::input::fractal_terrain(24, 5),
    ];
    for mesh in &meshes {
        for schedule in [Schedule::EveryVertex, Schedule::SplitValences] {
            for codec in [ChunkCodec::Rans { lanes: 4 }, ChunkCodec::Deflate(6)] {
                let options = EncodeOptions {
                    // Static tables: the minor version is the feature's (3.9 adds none here).
                    adaptive_tables: false,
                    // The fixed framing: the compact one (3.11) would raise it to 11.
                    framing: splitstream_decoder_core::Framing::Fixed,
                    records: Some(RecordOrder::PositionsFirst),
                    schedule,
                    codec,
                    ..EncodeOptions::default()
                };
                assert_roundtrip(mesh, &options);
                let encoded = encode(mesh, &options, |_| {}).expect("encode");
                let stream = &encoded.stream;
                let header = Header::parse(stream).expect("header");
                let table = LevelTable::parse(stream, &header).expect("table");
                let mut diagonal = false;
                for k in 0..table.len() {
                    let e = table.get(k);
                    let bytes = &stream[e.offset as usize..(e.offset + e.length as u64) as usize];
                    let lh = LevelHeader::parse(bytes, k == 0, header.level_rules())
                        .expect("level header");
                    assert_eq!(lh.record_order, RecordOrder::PositionsFirst);
                    assert_eq!(lh.plane_policy, PlanePolicy::Height);
                    assert_eq!(lh.wing_policy, WingPolicy::Ranks);
                    diagonal |= lh.ties != Ties::Ring;
                }
                let minor = if diagonal { 8 } else { 7 };
                assert_eq!(stream[9], minor, "{schedule:?} {codec:?}");
            }
        }
    }
}

/// Format 3.8's tie rules, each forced in every positions-first level of
/// a terrain: the round trip is exact, every level declares the rule, and
/// the minor version is 7 under `ring` (a 3.7 stream), 8 otherwise; by
/// default the encoder keeps per level the rule that codes smallest, never
/// larger than the others forced.
#[test]
fn every_tie_rule_roundtrips_and_the_default_is_the_smallest() {
    let terrain = splitstream_encoder::input::fractal_terrain(40, 3);
    let mut sizes = Vec::new();
    for ties in Ties::ALL {
        let options = EncodeOptions {
            // Static tables: the minor version is the feature's (3.9 adds none here).
            adaptive_tables: false,
            // The fixed framing: the compact one (3.11) would raise it to 11.
            framing: splitstream_decoder_core::Framing::Fixed,
            records: Some(RecordOrder::PositionsFirst),
            ties: Some(ties),
            ..EncodeOptions::default()
        };
        assert_roundtrip(&terrain, &options);
        let stream = encode(&terrain, &options, |_| {}).expect("encode").stream;
        let header = Header::parse(&stream).expect("header");
        let table = LevelTable::parse(&stream, &header).expect("table");
        for k in 0..table.len() {
            let e = table.get(k);
            let bytes = &stream[e.offset as usize..(e.offset + e.length as u64) as usize];
            let lh = LevelHeader::parse(bytes, k == 0, header.level_rules()).expect("level");
            assert_eq!(lh.ties, ties, "level {k}");
        }
        let minor = if ties == Ties::Ring { 7 } else { 8 };
        assert_eq!(stream[9], minor, "{ties:?}");
        sizes.push(stream.len());
    }
    let options = EncodeOptions {
        // Static tables: the minor version is the feature's (3.9 adds none here).
        adaptive_tables: false,
        // The fixed framing: the compact one (3.11) would raise it to 11.
        framing: splitstream_decoder_core::Framing::Fixed,
        records: Some(RecordOrder::PositionsFirst),
        ..EncodeOptions::default()
    };
    let chosen = encode(&terrain, &options, |_| {})
        .expect("encode")
        .stream
        .len();
    // A few bytes of slack: the rule is chosen by the wings' rANS sizes,
    // and framing may then pick another codec for a chunk.
    assert!(
        chosen <= sizes.iter().min().unwrap() + 16,
        "{chosen} against {sizes:?}"
    );
}

/// By default a raster's levels read their records positions first where
/// that is smaller: never larger than wings first (a few bytes of slack:
/// the choice ranks rANS sizes and framing may pick deflate), and on a
/// fractal terrain clearly smaller.
#[test]
fn the_chosen_record_order_is_never_larger_than_wings_first() {
    let terrain = splitstream_encoder::input::fractal_terrain(64, 9);
    for mesh in [common::bumpy_grid(31, 23, 2), terrain] {
        let size = |records| {
            let options = EncodeOptions {
                records,
                ..EncodeOptions::default()
            };
            encode(&mesh, &options, |_| {})
                .expect("encode")
                .stream
                .len()
        };
        let (auto, wings_first) = (size(None), size(Some(RecordOrder::WingsFirst)));
        assert!(auto <= wings_first + 16, "{auto} > {wings_first}");
    }
    let terrain = splitstream_encoder::input::fractal_terrain(64, 9);
    let size = |records| {
        let options = EncodeOptions {
            records,
            ..EncodeOptions::default()
        };
        encode(&terrain, &options, |_| {})
            .expect("encode")
            .stream
            .len()
    };
    let (auto, wings_first) = (size(None), size(Some(RecordOrder::WingsFirst)));
    assert!(auto * 20 < wings_first * 19, "{auto} against {wings_first}");
}

/// A level of 65,536 splits or more chooses its record order on its first
/// eighth where one order is clearly smaller, and writes the other's
/// records no further (`geometry::code_geometry`): a terrain whose finest
/// level has more than 65,536 splits still round-trips, reads that level
/// positions first (it is about a fifth smaller), and is smaller than the
/// same terrain read wings first. Forced, positions first and a tie rule
/// take the same early path.
#[test]
fn a_large_level_chooses_its_record_order_on_its_first_eighth() {
    let terrain = splitstream_encoder::input::fractal_terrain(400, 7);
    let finest = |options: &EncodeOptions| {
        let stream = encode(&terrain, options, |_| {}).expect("encode").stream;
        let lh = large_finest_level(&stream);
        (stream.len(), lh.record_order, lh.ties)
    };
    let auto = EncodeOptions::default();
    assert_roundtrip(&terrain, &auto);
    let (size, order, _) = finest(&auto);
    assert_eq!(order, RecordOrder::PositionsFirst);
    let wings_first = EncodeOptions {
        records: Some(RecordOrder::WingsFirst),
        ..EncodeOptions::default()
    };
    let (wings_first_size, ..) = finest(&wings_first);
    assert!(size < wings_first_size, "{size} against {wings_first_size}");
    let forced = EncodeOptions {
        records: Some(RecordOrder::PositionsFirst),
        ties: Some(Ties::Falling),
        ..EncodeOptions::default()
    };
    assert_roundtrip(&terrain, &forced);
    let (_, order, ties) = finest(&forced);
    assert_eq!((order, ties), (RecordOrder::PositionsFirst, Ties::Falling));
}

/// The other way: a sphere's fans have few free lattice points in x and
/// y, so a large level of it is clearly smaller read wings first, chooses
/// that on its first eighth, and drops its positions-first records.
#[test]
fn a_large_level_of_a_sphere_chooses_wings_first_early() {
    let sphere = splitstream_encoder::input::icosphere(7);
    let options = EncodeOptions::default();
    assert_roundtrip(&sphere, &options);
    let stream = encode(&sphere, &options, |_| {}).expect("encode").stream;
    assert_eq!(
        large_finest_level(&stream).record_order,
        RecordOrder::WingsFirst
    );
}

/// The header of `stream`'s finest level, which must add 65,536 splits
/// or more (a level that makes its choices on its first eighth).
fn large_finest_level(stream: &[u8]) -> LevelHeader<'_> {
    let header = Header::parse(stream).expect("header");
    let table = LevelTable::parse(stream, &header).expect("table");
    let k = table.len() - 1;
    let (e, previous) = (table.get(k), table.get(k - 1));
    let splits = e.vertex_count - previous.vertex_count;
    assert!(splits >= 65_536, "{splits} splits");
    let bytes = &stream[e.offset as usize..(e.offset + e.length as u64) as usize];
    LevelHeader::parse(bytes, false, header.level_rules()).expect("level")
}

/// Adaptive rANS tables (format 3.9, the default): streams round-trip
/// with and without them in 1 and 4 lanes, under both schedules; a stream
/// with one marks minor version 9, one without keeps its feature's, and
/// both decode to the same mesh, the adaptive one no larger.
#[test]
fn adaptive_tables_roundtrip_and_set_the_minor_version() {
    use splitstream_decoder_core::owned::decode_all;
    for mesh in [common::icosphere(3), common::bumpy_grid(31, 23, 2)] {
        for (lanes, schedule) in [(1, Schedule::EveryVertex), (4, Schedule::SplitValences)] {
            let adaptive = EncodeOptions {
                // The fixed framing: the compact one (3.11) would mark 11.
                framing: splitstream_decoder_core::Framing::Fixed,
                codec: ChunkCodec::Rans { lanes },
                schedule,
                ..EncodeOptions::default()
            };
            assert!(adaptive.adaptive_tables, "the default");
            let fixed = EncodeOptions {
                adaptive_tables: false,
                ..adaptive.clone()
            };
            assert_roundtrip(&mesh, &adaptive);
            assert_roundtrip(&mesh, &fixed);
            let a = encode(&mesh, &adaptive, |_| {}).expect("encode").stream;
            let f = encode(&mesh, &fixed, |_| {}).expect("encode").stream;
            assert_eq!(
                a[9], 9,
                "{lanes} lanes {schedule:?}: small substreams pay no tables"
            );
            assert!(f[9] < 9);
            assert!(a.len() <= f.len(), "{} against {}", a.len(), f.len());
            let (da, df) = (
                decode_all(&a, false).unwrap(),
                decode_all(&f, false).unwrap(),
            );
            assert_eq!((da.positions, da.triangles), (df.positions, df.triangles));
        }
    }
}
