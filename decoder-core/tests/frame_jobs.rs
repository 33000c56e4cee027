//! `writer::frame_level_with`: however the chunk jobs are run (here in
//! reverse order, as a thread pool might finish them), the framed level is
//! byte for byte `frame_level`'s.

use splitstream_decoder_core::writer::{
    Chunk, ChunkCodec, LevelPayload, SeedPayload, StreamParams, SubstreamWriter, frame_level,
    frame_level_with,
};
use splitstream_decoder_core::{DeficitContexts, PlanePolicy, WingPolicy};

fn params(codec: ChunkCodec) -> StreamParams {
    StreamParams {
        codec,
        // Small chunks: every substream below has several.
        chunk_limit: 64,
        rans_chunk_limit: 64,
        ..StreamParams::default()
    }
}

/// A level whose substreams hold pseudo-random values of every kind.
fn level() -> LevelPayload {
    let mut x = 0x9E37_79B9_7F4A_7C15u64;
    let mut next = move || {
        x ^= x << 13;
        x ^= x >> 7;
        x ^= x << 17;
        x
    };
    let mut substreams = vec![SubstreamWriter::default(); 7];
    for _ in 0..400 {
        substreams[0].bit_in(0, next() % 3 == 0);
        substreams[1].byte_in((next() % 8) as u8, (next() % 5) as u8);
        substreams[2].byte_in((next() % 8) as u8, 1 + (next() % 4) as u8);
        substreams[3].byte_in(0, (next() % 7) as u8);
        substreams[4].byte_in((next() % 5) as u8, (next() % 7) as u8);
        for axis in 0..3u8 {
            substreams[5].signed_in(axis, (next() % 200) as i32 - 100);
            substreams[6].signed_in(axis, (next() % 90) as i32 - 45);
        }
    }
    LevelPayload {
        round_splits: vec![150, 250],
        plane: PlanePolicy::Dominant,
        wings: WingPolicy::Ranks,
        deficits: DeficitContexts::Plain,
        records: splitstream_decoder_core::RecordOrder::WingsFirst,
        ties: splitstream_decoder_core::Ties::Ring,
        substreams,
        vertex_count: 420,
        triangle_count: 836,
        geometric_error: 0.5,
    }
}

fn reversed(n: usize, job: &(dyn Fn(usize) -> Chunk + Sync)) -> Vec<Chunk> {
    let mut chunks: Vec<Chunk> = (0..n).rev().map(job).collect();
    chunks.reverse();
    chunks
}

#[test]
fn any_order_of_chunk_jobs_frames_the_same_bytes() {
    let level = level();
    let seed = SeedPayload::new(&[[1, 2, 3], [4, 5, 6], [7, 8, 9]], &[[0, 1, 2]], &[0, 1, 2]);
    for codec in [
        ChunkCodec::Stored,
        ChunkCodec::Deflate(6),
        ChunkCodec::Rans { lanes: 4 },
        ChunkCodec::RansAlways { lanes: 3 },
    ] {
        let p = params(codec);
        for seed in [None, Some(&seed)] {
            let one_by_one = frame_level(&level, seed, &p);
            let any_order = frame_level_with(&level, seed, &p, &reversed);
            assert_eq!(one_by_one, any_order, "{codec:?}");
        }
    }
}
