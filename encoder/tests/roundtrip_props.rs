//! Property-generated meshes: decode(encode(M)) == M exactly for terrains
//! with flat patches (ties everywhere), holes from missing samples, closed
//! noisy spheres, both position modes, any level count, both codecs and
//! both record orders (format 3.7).

mod common;
mod roundtrip_check;

use proptest::prelude::*;
use splitstream_decoder_core::writer::ChunkCodec;
use splitstream_decoder_core::{PositionMode, RecordOrder};
use splitstream_encoder::emit::EncodeOptions;
use splitstream_encoder::input::{Grid, check_mesh, grid_to_mesh};

/// The codecs a generated case may use: rANS in 1..=32 lanes (forced on
/// every substream) or deflate.
fn codec() -> impl Strategy<Value = ChunkCodec> {
    prop_oneof![
        (1u8..=32).prop_map(|lanes| ChunkCodec::RansAlways { lanes }),
        Just(ChunkCodec::Rans { lanes: 4 }),
        Just(ChunkCodec::Deflate(6)),
    ]
}

/// The record order a case asks for (format 3.7): chosen per level, or
/// forced either way (positions first needs constrained mode).
fn records() -> impl Strategy<Value = Option<RecordOrder>> {
    prop_oneof![
        Just(None),
        Just(Some(RecordOrder::PositionsFirst)),
        Just(Some(RecordOrder::WingsFirst)),
    ]
}

fn options(
    constrained: bool,
    levels: usize,
    admit: f64,
    lock: bool,
    codec: ChunkCodec,
    records: Option<RecordOrder>,
) -> EncodeOptions {
    EncodeOptions {
        codec,
        position_mode: if constrained {
            PositionMode::Constrained
        } else {
            PositionMode::Optimal
        },
        levels,
        records: records.filter(|_| constrained),
        admit_quantile: admit,
        lock_boundary: lock,
        chunk_limit: 61,
        // rANS chunks as short as the byte-codec ones, or longer than
        // max_chunk_len (format 3.4), by the level count's parity.
        rans_chunk_limit: if levels.is_multiple_of(2) {
            61
        } else {
            1 << 14
        },
        ..EncodeOptions::default()
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 48, ..ProptestConfig::default() })]

    #[test]
    fn terrains_with_flats_and_holes(
        rows in 3usize..22,
        cols in 3usize..22,
        heights in proptest::collection::vec(0u8..4, 484),
        holes in proptest::collection::vec(0usize..484, 0..6),
        constrained: bool,
        lock: bool,
        levels in 1usize..8,
        admit in prop_oneof![Just(0.3), Just(1.0)],
        codec in codec(),
        records in records(),
    ) {
        let mut elevations: Vec<f64> = (0..rows * cols).map(|i| heights[i % heights.len()] as f64 * 5.0).collect();
        for h in holes {
            elevations[h % (rows * cols)] = f64::NAN;
        }
        let grid = Grid { rows, cols, elevations, origin: [0.0, 0.0], spacing: [10.0, 10.0], nodata: None, coordinates: None };
        let mesh = grid_to_mesh(&grid);
        prop_assume!(mesh.triangles.len() >= 2 && check_mesh(&mesh).is_ok());
        roundtrip_check::assert_roundtrip(&mesh, &options(constrained, levels, admit, lock, codec, records));
    }

    #[test]
    fn noisy_closed_spheres(
        subdivisions in 0usize..3,
        seed in any::<u64>(),
        constrained: bool,
        levels in 1usize..8,
        admit in prop_oneof![Just(0.3), Just(1.0)],
        codec in codec(),
        records in records(),
    ) {
        // Forced positions first on a closed surface: its fans fold over
        // in xy, and most records escape.
        let mut mesh = common::icosphere(subdivisions);
        let mut state = seed | 1;
        for p in &mut mesh.positions {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            let scale = 1.0 + ((state % 1000) as f64 / 1000.0 - 0.5) * 0.2;
            *p = p.map(|x| x * scale);
        }
        roundtrip_check::assert_roundtrip(&mesh, &options(constrained, levels, admit, false, codec, records));
    }
}
