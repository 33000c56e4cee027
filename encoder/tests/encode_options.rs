//! `EncodeOptions::check`: what the option types allow but the format or
//! the encoder does not is refused with one message, by the library as by
//! the command line, instead of a stream that no decoder accepts.

mod common;

use splitstream_decoder_core::owned::decode_all;
use splitstream_decoder_core::writer::ChunkCodec;
use splitstream_decoder_core::{PlanePolicy, PositionMode, RecordOrder, WingPolicy};
use splitstream_encoder::emit::{
    EncodeError, EncodeOptions, encode, encode_quantized, quantize_for,
};

fn refused(options: EncodeOptions, says: &str) {
    let mesh = common::icosphere(1);
    let quantized = quantize_for(&mesh, &EncodeOptions::default());
    for result in [
        encode(&mesh, &options, |_| {}).map(|_| ()),
        encode_quantized(&quantized, &options, |_| {}).map(|_| ()),
    ] {
        match result {
            Err(EncodeError::BadOption(message)) => {
                assert!(message.contains(says), "{message:?} names {says}");
                assert!(!message.contains('\n'), "one line: {message:?}");
            }
            Err(e) => panic!("{says}: another error: {e}"),
            Ok(()) => panic!("{says}: encoded"),
        }
    }
}

/// One lane below 65,536 vertices, four from there (`lanes_for`, what
/// `splitstream encode` writes without `--lanes`).
#[test]
fn lanes_by_mesh_size() {
    use splitstream_encoder::emit::{ONE_LANE_BELOW_VERTICES, lanes_for};
    assert_eq!(lanes_for(0), 1);
    assert_eq!(lanes_for(ONE_LANE_BELOW_VERTICES - 1), 1);
    assert_eq!(lanes_for(ONE_LANE_BELOW_VERTICES), 4);
    assert_eq!(lanes_for(usize::MAX), 4);
}

#[test]
fn lane_counts_outside_the_format_are_refused() {
    // Before the check these wrote streams whose header every decoder
    // refuses (SPEC §5.5.3: 1 to 32 lanes).
    for codec in [
        ChunkCodec::Rans { lanes: 0 },
        ChunkCodec::Rans { lanes: 33 },
        ChunkCodec::RansAlways { lanes: 200 },
    ] {
        refused(
            EncodeOptions {
                codec,
                ..Default::default()
            },
            "--lanes",
        );
    }
}

/// Positions first needs what a positions-first level declares (SPEC
/// §5.1, format 3.7): constrained mode, the plane policy `height`, the
/// wing policy `ranks`.
#[test]
fn positions_first_is_refused_where_a_level_could_not_declare_it() {
    let pf = || EncodeOptions {
        records: Some(RecordOrder::PositionsFirst),
        ..Default::default()
    };
    refused(
        EncodeOptions {
            position_mode: PositionMode::Optimal,
            ..pf()
        },
        "--records",
    );
    refused(
        EncodeOptions {
            plane: Some(PlanePolicy::Dominant),
            ..pf()
        },
        "--records",
    );
    refused(
        EncodeOptions {
            wings: Some(WingPolicy::NearXy),
            ..pf()
        },
        "--records",
    );
}

#[test]
fn every_other_bad_option_is_refused() {
    let d = EncodeOptions::default;
    refused(EncodeOptions { bits: 0, ..d() }, "--bits");
    refused(EncodeOptions { bits: 32, ..d() }, "--bits");
    // `encode_quantized` used to compute `levels - 1` unchecked.
    refused(EncodeOptions { levels: 0, ..d() }, "--levels");
    refused(EncodeOptions { levels: 65, ..d() }, "--levels");
    for admit in [0.0, -1.0, 1.5, f64::NAN] {
        refused(
            EncodeOptions {
                admit_quantile: admit,
                ..d()
            },
            "--admit",
        );
    }
    for e in [-1.0, f64::NAN, f64::INFINITY] {
        refused(
            EncodeOptions {
                max_error: Some(e),
                ..d()
            },
            "--max-error",
        );
    }
    refused(
        EncodeOptions {
            chunk_limit: 0,
            ..d()
        },
        "--chunk-size",
    );
    refused(
        EncodeOptions {
            rans_chunk_limit: 0,
            ..d()
        },
        "--rans-chunk",
    );
}

#[test]
fn the_edges_of_each_range_encode() {
    let mesh = common::icosphere(1);
    for options in [
        EncodeOptions {
            codec: ChunkCodec::Rans { lanes: 1 },
            admit_quantile: 1.0,
            max_error: Some(0.0),
            ..Default::default()
        },
        EncodeOptions {
            codec: ChunkCodec::RansAlways { lanes: 32 },
            levels: 64,
            chunk_limit: 1,
            rans_chunk_limit: 1,
            ..Default::default()
        },
    ] {
        let encoded = encode(&mesh, &options, |_| {}).expect("encodes");
        decode_all(&encoded.stream, false).expect("decodes");
    }
}

/// Found by the `encode_generated` fuzz target (2026-12-03): one level
/// with a base size below the mesh (an icosphere of 162 vertices, `levels:
/// 1`, `base_vertices: Some(86)`) planned level 0 to end at the base, and
/// the replay failed with "replay ended with 80 vertices, the input has
/// 162". The last level always ends at the whole mesh; with one level the
/// base size has no effect.
#[test]
fn one_level_with_a_base_size_holds_the_whole_mesh() {
    let mesh = common::icosphere(2);
    for base in [0, 4, 86, 161, 162, 1000] {
        let options = EncodeOptions {
            levels: 1,
            base_vertices: Some(base),
            ..EncodeOptions::default()
        };
        let encoded = encode(&mesh, &options, |_| {}).expect("one level encodes");
        assert_eq!(
            encoded.level_vertex_counts,
            [mesh.positions.len() as u32],
            "base {base}"
        );
        let decoded = decode_all(&encoded.stream, false).expect("decodes");
        assert_eq!(decoded.triangles.len(), mesh.triangles.len());
    }
}
