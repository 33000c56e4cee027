//! Criterion benchmark of decoder-core on the 1M-vertex synthetic terrain:
//! single-thread decoding of every level, in vertex splits per second
//! (the goal of decoder-core's README). The stream is encoded once and kept
//! in target/bench-data/ (encoding takes a while); delete it to re-encode.

use std::path::PathBuf;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use splitstream_decoder_core::owned::OwnedWorkspace;
use splitstream_encoder::emit::{EncodeOptions, encode};
use splitstream_encoder::input::fractal_terrain;

const SIDE: usize = 1000;

fn terrain_stream() -> Vec<u8> {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../target/bench-data");
    let path = dir.join(format!("terrain-{SIDE}.sps"));
    if let Ok(bytes) = std::fs::read(&path) {
        return bytes;
    }
    let mesh = fractal_terrain(SIDE, 2012);
    let encoded = encode(&mesh, &EncodeOptions::default(), |_| {}).expect("encode the terrain");
    std::fs::create_dir_all(&dir).expect("create target/bench-data");
    std::fs::write(&path, &encoded.stream).expect("cache the stream");
    encoded.stream
}

fn decode(c: &mut Criterion) {
    let stream = terrain_stream();
    let mut ws = OwnedWorkspace::for_stream(&stream).expect("valid stream");
    let (splits, seed) = {
        let mut decoder = ws.decoder(&stream).expect("valid stream");
        decoder.decode_available(&stream).expect("decodes");
        let head = splitstream_decoder_core::Header::parse(&stream).expect("header");
        let table = splitstream_decoder_core::LevelTable::parse(&stream, &head).expect("table");
        let level0 = table.get(0);
        let bytes =
            &stream[level0.offset as usize..(level0.offset + level0.length as u64) as usize];
        let lh = splitstream_decoder_core::LevelHeader::parse(bytes, true, head.max_chunk_len)
            .expect("level 0");
        (decoder.positions().len() as u64, lh.seed_vertices as u64)
    };
    let mut group = c.benchmark_group("decode");
    group.sample_size(10);
    group.throughput(Throughput::Elements(splits - seed.min(splits)));
    group.bench_function(
        format!("terrain {SIDE}x{SIDE}, all levels, one thread"),
        |b| {
            b.iter(|| {
                let mut decoder = ws.decoder(&stream).expect("valid stream");
                decoder.decode_available(&stream).expect("decodes");
                decoder.triangles().len()
            })
        },
    );
    group.finish();
}

criterion_group!(benches, decode);
criterion_main!(benches);
