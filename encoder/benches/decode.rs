//! Criterion benchmark of decoder-core on the 1M-vertex synthetic terrain:
//! decoding of every level on one thread and on two (sdk-native
//! `threaded`), in vertex splits per second (the goal of decoder-core's
//! README), for both entropy codecs in one run, and for rANS with and
//! without adaptive tables (format 3.9).
//! Each stream is encoded once and kept in target/bench-data/ (encoding
//! takes a while); the file name carries the format version and the codec.

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use splitstream_decoder_core::PositionMode;
use splitstream_decoder_core::owned::OwnedWorkspace;
use splitstream_decoder_core::writer::ChunkCodec;
use splitstream_encoder::emit::EncodeOptions;
use splitstream_sdk_native::threaded::{self, TwoThreadMemory};

const SIDE: usize = 1000;

mod common;

fn terrain_stream(name: &str, codec: ChunkCodec, adaptive_tables: bool) -> Vec<u8> {
    // Optimal mode, as in every figure recorded with this benchmark (the
    // encoder's default until 2026-12-03; `splitstream demo` writes the
    // terrain in constrained mode).
    let options = EncodeOptions {
        codec,
        position_mode: PositionMode::Optimal,
        adaptive_tables,
        ..EncodeOptions::default()
    };
    common::terrain_stream(SIDE, name, &options)
}

/// Splits in `stream`: every vertex but the seed's.
fn splits(stream: &[u8]) -> u64 {
    let head = splitstream_decoder_core::Header::parse(stream).expect("header");
    let table = splitstream_decoder_core::LevelTable::parse(stream, &head).expect("table");
    let level0 = table.get(0);
    let bytes = &stream[level0.offset as usize..(level0.offset + level0.length as u64) as usize];
    let lh = splitstream_decoder_core::LevelHeader::parse(bytes, true, head.level_rules())
        .expect("level 0");
    (head.vertex_capacity - lh.seed_vertices) as u64
}

fn decode(c: &mut Criterion) {
    let mut group = c.benchmark_group("decode");
    group.sample_size(10);
    for (name, codec, adaptive) in [
        ("rans", ChunkCodec::Rans { lanes: 4 }, true),
        ("rans-static-tables", ChunkCodec::Rans { lanes: 4 }, false),
        ("deflate", ChunkCodec::Deflate(9), false),
    ] {
        let stream = terrain_stream(name, codec, adaptive);
        let mut ws = OwnedWorkspace::for_stream(&stream).expect("valid stream");
        group.throughput(Throughput::Elements(splits(&stream)));
        group.bench_function(
            format!("terrain {SIDE}x{SIDE}, {name}, all levels, one thread"),
            |b| {
                b.iter(|| {
                    let mut decoder = ws.decoder(&stream).expect("valid stream");
                    decoder.decode_available(&stream).expect("decodes");
                    decoder.triangles().len()
                })
            },
        );
        // The same with each level's records read on a second thread
        // (sdk-native `threaded`): the ratio of the two is the figure.
        let capacity = ws
            .decoder(&stream)
            .expect("valid stream")
            .state()
            .vertex_capacity();
        let mut memory = TwoThreadMemory::new(capacity);
        group.bench_function(
            format!("terrain {SIDE}x{SIDE}, {name}, all levels, two threads"),
            |b| {
                b.iter(|| {
                    let mut decoder = ws.decoder(&stream).expect("valid stream");
                    while let Some(k) = decoder.next_level() {
                        let bytes = decoder.level_bytes(k, &stream).expect("level");
                        threaded::decode_level(&mut decoder, k, bytes, &mut memory)
                            .expect("decodes");
                    }
                    decoder.triangles().len()
                })
            },
        );
    }
    group.finish();
}

criterion_group!(benches, decode);
criterion_main!(benches);
