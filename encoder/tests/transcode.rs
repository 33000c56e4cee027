//! `transcode`: a stream written again from its own refinement. The new
//! stream must reach the same state after every round, and writing a
//! stream again with the options of another encoding of the same mesh must
//! give that encoding byte for byte (the replay sees the same refinement).

mod common;

use proptest::prelude::*;
use splitstream_decoder_core::owned::decode_all;
use splitstream_decoder_core::writer::ChunkCodec;
use splitstream_decoder_core::{
    DeficitContexts, Error, Header, PlanePolicy, PositionMode, WingPolicy,
};
use splitstream_encoder::Mesh;
use splitstream_encoder::emit::{
    EncodeOptions, TranscodeError, TranscodeOptions, encode, transcode,
};

fn encode_with(mesh: &Mesh, mode: PositionMode, codec: ChunkCodec, chunk_limit: u32) -> Vec<u8> {
    let options = EncodeOptions {
        position_mode: mode,
        codec,
        chunk_limit,
        ..EncodeOptions::default()
    };
    encode(mesh, &options, |_| {}).expect("encode").stream
}

fn to(codec: ChunkCodec, chunk_limit: u32) -> TranscodeOptions {
    TranscodeOptions {
        codec,
        chunk_limit,
        ..TranscodeOptions::default()
    }
}

/// The state hash after the seed and after every round.
fn round_hashes(stream: &[u8]) -> Vec<u64> {
    decode_all(stream, true).expect("decode").round_hashes
}

fn meshes() -> Vec<(&'static str, Mesh)> {
    vec![
        ("bumpy grid", common::bumpy_grid(23, 17, 3)),
        ("icosphere", common::icosphere(3)),
    ]
}

#[test]
fn another_codec_gives_that_codecs_encoding_byte_for_byte() {
    let codecs = [
        ChunkCodec::Rans { lanes: 4 },
        ChunkCodec::Deflate(9),
        ChunkCodec::Stored,
        ChunkCodec::RansAlways { lanes: 3 },
    ];
    for (name, mesh) in meshes() {
        for mode in [PositionMode::Constrained, PositionMode::Optimal] {
            let streams: Vec<Vec<u8>> = codecs
                .iter()
                .map(|&codec| encode_with(&mesh, mode, codec, 200))
                .collect();
            for (from, stream) in streams.iter().enumerate() {
                for (into, want) in streams.iter().enumerate() {
                    let got = transcode(stream, &to(codecs[into], 200)).expect("transcode");
                    assert!(
                        got.stream == *want,
                        "{name}, {mode:?}: {:?} -> {:?}",
                        codecs[from],
                        codecs[into]
                    );
                }
            }
        }
    }
}

/// Chunk buffers take `7 × max(M, RANS_SLOT_BYTES)` of the decoder's
/// memory (SPEC §9), M bounding stored and deflate chunks only (format 3.4):
/// a stream cut in small byte-codec chunks needs less memory, and keeping
/// its rANS chunks long keeps its size.
#[test]
fn smaller_chunks_lower_the_workspace_and_keep_every_round() {
    for (name, mesh) in [
        ("bumpy grid", common::bumpy_grid(80, 60, 5)),
        ("icosphere", common::icosphere(5)),
    ] {
        let stream = encode_with(
            &mesh,
            PositionMode::Constrained,
            ChunkCodec::Deflate(9),
            16 * 1024,
        );
        let before = Header::parse(&stream).unwrap();
        assert!(
            before.max_chunk_len > 4096,
            "{name}: {}",
            before.max_chunk_len
        );
        // Deflate in 1 KiB chunks: less memory, every round kept.
        let small = transcode(&stream, &to(ChunkCodec::Deflate(9), 1024)).expect("transcode");
        let after = Header::parse(&small.stream).unwrap();
        assert!(after.max_chunk_len <= 1024, "{name}");
        assert!(
            after.workspace_bytes + 7 * 2048 <= before.workspace_bytes,
            "{name}: {} against {}",
            after.workspace_bytes,
            before.workspace_bytes
        );
        let hashes = round_hashes(&stream);
        assert_eq!(round_hashes(&small.stream), hashes, "{name}");
        assert_eq!(Some(&small.final_hash), hashes.last(), "{name}");
        // rANS: chunks of 1 KiB and 1,024 values (as format 3.3 had to cut
        // them) against 1 KiB and long rANS chunks (3.4): the same memory,
        // fewer bytes.
        let short = TranscodeOptions {
            rans_chunk_limit: 1024,
            ..to(ChunkCodec::Rans { lanes: 4 }, 1024)
        };
        let short = transcode(&stream, &short).expect("transcode");
        // The fixed framing: the minor version is the features' below (the
        // compact framing, 3.11, would mark 11).
        let long = TranscodeOptions {
            framing: splitstream_decoder_core::Framing::Fixed,
            ..to(ChunkCodec::Rans { lanes: 4 }, 1024)
        };
        let long = transcode(&stream, &long).expect("transcode");
        let (short_header, long_header) = (
            Header::parse(&short.stream).unwrap(),
            Header::parse(&long.stream).unwrap(),
        );
        assert_eq!(
            short_header.workspace_bytes, long_header.workspace_bytes,
            "{name}"
        );
        assert!(long.stream.len() < short.stream.len(), "{name}");
        // Minor 6: the schedule every-vertex (the default, 3.6), a later
        // feature than 3.4's long rANS chunks; 7 where a level of the
        // grid reads its records positions first (3.7, chosen by size), 8
        // where one also breaks its ties by a diagonal (3.8), 9 where a
        // chunk has an adaptive table (3.9, chosen by size), 10 where a
        // level's flags use the contexts split-history (3.10, chosen by
        // size).
        let positions_first = matches!(long_header.version_minor, 7 | 8);
        assert!(
            matches!(long_header.version_minor, 6 | 9 | 10)
                || (positions_first && name == "bumpy grid"),
            "{name}: minor {}",
            long_header.version_minor
        );
        assert_eq!(round_hashes(&long.stream), hashes, "{name}");
    }
}

#[test]
fn an_older_coding_is_upgraded_and_the_upgrade_is_undone_by_forcing_it_back() {
    let mesh = common::bumpy_grid(31, 29, 7);
    let old = EncodeOptions {
        position_mode: PositionMode::Constrained,
        plane: Some(PlanePolicy::Dominant),
        wings: Some(WingPolicy::Ranks),
        deficits: Some(DeficitContexts::Plain),
        ..EncodeOptions::default()
    };
    let old_stream = encode(&mesh, &old, |_| {}).expect("encode").stream;
    let newest = transcode(&old_stream, &TranscodeOptions::default()).expect("transcode");
    assert!(newest.stream.len() < old_stream.len());
    assert_eq!(round_hashes(&newest.stream), round_hashes(&old_stream));
    let back = TranscodeOptions {
        plane: old.plane,
        wings: old.wings,
        deficits: old.deficits,
        ..TranscodeOptions::default()
    };
    assert_eq!(
        transcode(&newest.stream, &back).expect("transcode").stream,
        old_stream
    );
}

#[test]
fn a_stream_that_does_not_decode_is_a_decode_error() {
    let stream = encode_with(
        &common::icosphere(2),
        PositionMode::Optimal,
        ChunkCodec::Rans { lanes: 4 },
        16 * 1024,
    );
    let options = TranscodeOptions::default();
    assert!(matches!(
        transcode(b"not a stream", &options),
        Err(TranscodeError::Decode(Error::Truncated | Error::BadMagic))
    ));
    assert!(matches!(
        transcode(&stream[..stream.len() - 1], &options),
        Err(TranscodeError::Decode(_))
    ));
    let mut flipped = stream.clone();
    let last = flipped.len() - 5;
    flipped[last] ^= 0x10;
    assert!(matches!(
        transcode(&flipped, &options),
        Err(TranscodeError::Decode(_))
    ));
}

#[test]
fn bad_options_are_refused() {
    let stream = encode_with(
        &common::icosphere(1),
        PositionMode::Optimal,
        ChunkCodec::Rans { lanes: 4 },
        16 * 1024,
    );
    for options in [
        to(ChunkCodec::Rans { lanes: 4 }, 0),
        to(ChunkCodec::Rans { lanes: 0 }, 100),
        to(ChunkCodec::Rans { lanes: 33 }, 100),
    ] {
        assert!(matches!(
            transcode(&stream, &options),
            Err(TranscodeError::BadOption(_))
        ));
    }
}

fn codec() -> impl Strategy<Value = ChunkCodec> {
    prop_oneof![
        (1u8..=32).prop_map(|lanes| ChunkCodec::RansAlways { lanes }),
        (1u8..=8).prop_map(|lanes| ChunkCodec::Rans { lanes }),
        Just(ChunkCodec::Deflate(6)),
        Just(ChunkCodec::Stored),
    ]
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 24, ..ProptestConfig::default() })]

    /// Any stream the encoder writes, transcoded under any options, keeps
    /// its state after every round; transcoding it back gives it again.
    #[test]
    fn transcoding_keeps_every_round_and_is_undone(
        rows in 3usize..16,
        cols in 3usize..16,
        seed in 0u64..100,
        constrained: bool,
        levels in 1usize..7,
        codec_a in codec(),
        codec_b in codec(),
        chunk_a in 1u32..300,
        chunk_b in 1u32..300,
        rans_a in prop_oneof![1u32..300, Just(1 << 14)],
        rans_b in prop_oneof![1u32..300, Just(1 << 14)],
    ) {
        let mesh = common::bumpy_grid(cols, rows, seed);
        let options = EncodeOptions {
            position_mode: if constrained { PositionMode::Constrained } else { PositionMode::Optimal },
            levels,
            codec: codec_a,
            chunk_limit: chunk_a,
            rans_chunk_limit: rans_a,
            ..EncodeOptions::default()
        };
        let stream = encode(&mesh, &options, |_| {}).expect("encode").stream;
        let b = TranscodeOptions { rans_chunk_limit: rans_b, ..to(codec_b, chunk_b) };
        let other = transcode(&stream, &b).expect("transcode");
        prop_assert_eq!(round_hashes(&other.stream), round_hashes(&stream));
        let a = TranscodeOptions { rans_chunk_limit: rans_a, ..to(codec_a, chunk_a) };
        let back = transcode(&other.stream, &a).expect("transcode back");
        prop_assert!(back.stream == stream);
    }
}

/// Real data (fetched by encoder/data/fetch.sh; skipped without it): a
/// scanned mesh and the DEM, cut into small chunks with deflate and back.
#[test]
fn real_streams_transcode_and_back() {
    use splitstream_encoder::input::{ReadOptions, read_mesh};
    use splitstream_encoder::quantize::Units;
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("data/real");
    for (file, units) in [
        ("armadillo.off", Units::Linear),
        ("jacksboro_fault_dem.npz", Units::Geographic),
    ] {
        let path = dir.join(file);
        if !path.exists() {
            eprintln!("skipped {file}: run encoder/data/fetch.sh");
            continue;
        }
        let mesh = read_mesh(&path, &ReadOptions::default()).unwrap();
        let options = EncodeOptions {
            position_mode: PositionMode::Constrained,
            units,
            ..EncodeOptions::default()
        };
        let stream = encode(&mesh, &options, |_| {}).expect("encode").stream;
        let small = transcode(&stream, &to(ChunkCodec::Deflate(9), 2048)).expect("transcode");
        assert_eq!(round_hashes(&small.stream), round_hashes(&stream), "{file}");
        let back = transcode(&small.stream, &TranscodeOptions::default()).expect("back");
        assert!(back.stream == stream, "{file}");
    }
}

/// Every conformance vector (hand-made streams, 31-bit grids, boundaries,
/// every policy and codec): a valid one transcodes to a stream with the
/// same state after every round, an invalid one is refused as a decode
/// error, neither panics. `split-valence-255` (the largest split valence
/// the format allows) transcodes too: the encoder marks a vertex that never
/// splits with split valence 0, not 255.
#[test]
fn conformance_vectors_transcode_or_are_refused() {
    // The current set: the highest format version.
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../conformance/vectors");
    let dir = std::fs::read_dir(&root)
        .unwrap()
        .map(|e| e.unwrap().path())
        .max_by_key(|p| {
            let name = p.file_name().unwrap().to_string_lossy().to_string();
            let (major, minor) = name.split_once('.').unwrap_or((&name, "0"));
            (
                major.parse::<u32>().unwrap_or(0),
                minor.parse::<u32>().unwrap_or(0),
            )
        })
        .unwrap();
    let mut seen = 0;
    for (kind, valid) in [("valid", true), ("invalid", false)] {
        let mut paths: Vec<_> = std::fs::read_dir(dir.join(kind))
            .unwrap()
            .map(|e| e.unwrap().path())
            .collect();
        paths.sort();
        for path in paths {
            let stream = std::fs::read(&path).unwrap();
            let name = path.file_name().unwrap().to_string_lossy().to_string();
            // In the input's schedule: the per-vertex byte of the hashes
            // follows it (SPEC §6.2, §8).
            let schedule = Header::parse(&stream)
                .map(|h| h.schedule)
                .unwrap_or_default();
            let keep = |o: TranscodeOptions| TranscodeOptions { schedule, ..o };
            for options in [
                keep(TranscodeOptions::default()),
                keep(to(ChunkCodec::Deflate(9), 37)),
            ] {
                match transcode(&stream, &options) {
                    Ok(t) => {
                        assert!(valid, "{name} is invalid but transcoded");
                        assert_eq!(round_hashes(&t.stream), round_hashes(&stream), "{name}");
                    }
                    Err(TranscodeError::Decode(_)) => assert!(!valid, "{name}"),
                    Err(e) => panic!("{name}: {e}"),
                }
            }
            seen += 1;
        }
    }
    assert!(seen > 100, "{seen} vectors");
}

/// `EncodeOptions` and `TranscodeOptions` share one coding: the defaults
/// are the same, and `with_coding` and `coding` carry every field across.
#[test]
fn encode_and_transcode_options_share_their_coding() {
    let same = |a: &TranscodeOptions, b: &TranscodeOptions| format!("{a:?}") == format!("{b:?}");
    assert!(same(
        &EncodeOptions::default().coding(),
        &TranscodeOptions::default()
    ));
    let coding = TranscodeOptions {
        codec: ChunkCodec::Deflate(6),
        chunk_limit: 4096,
        rans_chunk_limit: 8192,
        plane: Some(PlanePolicy::Height),
        wings: Some(WingPolicy::Ranks),
        deficits: Some(DeficitContexts::Valence),
        records: Some(splitstream_decoder_core::RecordOrder::WingsFirst),
        ties: Some(splitstream_decoder_core::Ties::Falling),
        schedule: splitstream_decoder_core::Schedule::SplitValences,
        adaptive_tables: false,
        framing: splitstream_decoder_core::Framing::Fixed,
    };
    let options = EncodeOptions {
        bits: 11,
        ..EncodeOptions::default()
    }
    .with_coding(coding);
    assert!(same(&options.coding(), &coding));
    assert_eq!(options.bits, 11, "with_coding keeps what is not coding");
}
