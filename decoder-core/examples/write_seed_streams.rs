//! Writes the seed corpora of the fuzz targets (decoder-core/fuzz) and the
//! tetrahedron stream of the embedded size demo.
//!
//! ```text
//! cargo run -p splitstream-decoder-core --example write_seed_streams -- decoder-core/fuzz/corpus
//! ```
//!
//! Writes `<dir>/decode_bytes/*.sps` (complete valid streams: the hand-made
//! ones of tests/handmade.rs and generated deep ones), `<dir>/decode_mutated/*`
//! (one byte per seed stream: no mutation), `<dir>/round_records/*` (choice
//! strings of the generator) and `<dir>/tetrahedron.sps` (the stream of
//! `embedded-size/`, deflate chunks).

#[path = "../fuzz/src/streams.rs"]
mod streams;

use std::path::PathBuf;

use splitstream_decoder_core::handmade::{Rec, level, params, tetra_split};
use splitstream_decoder_core::limits::LEAF;
use splitstream_decoder_core::writer::{ChunkCodec, LevelPayload, write_stream};
use streams::{BaseMesh, Choices};

/// A level of one split record of [`tetra_split`]'s shape (wing ranks `o`,
/// `d` among 3 eligible ring entries, P and C leaves, C of valence 4) with
/// residuals `e` and `m` under the plane policy `off`.
fn one_split(o: u8, d: u8, e: [i32; 3], m: [i32; 3], v: u32, t: u32) -> LevelPayload {
    let rec = Rec {
        o,
        d,
        e,
        t: m,
        ..tetra_split()
    };
    level(&[true], vec![1], &[rec], v, t)
}

/// The hand-made streams: tetrahedron with one split (stored and deflate),
/// triangle with a boundary split (the record bytes of tests/handmade.rs,
/// read as residuals from the SPEC §7.4 prediction), and a base-only
/// octahedron.
pub fn handmade() -> Vec<(&'static str, Vec<u8>)> {
    let tetra = streams::base_level(&streams::tetrahedron(), &[0, LEAF, LEAF, LEAF]);
    let tri = streams::base_level(&streams::triangle(), &[0, LEAF, LEAF]);
    let octa: BaseMesh = streams::octahedron();
    let streams = vec![
        (
            "tetrahedron_stored",
            write_stream(
                &params(ChunkCodec::Stored),
                &[tetra.clone(), one_split(0, 1, [2; 3], [4; 3], 5, 6)],
            ),
        ),
        (
            "tetrahedron_deflate",
            write_stream(
                &params(ChunkCodec::Deflate(9)),
                &[tetra.clone(), one_split(0, 1, [2; 3], [4; 3], 5, 6)],
            ),
        ),
        (
            "tetrahedron_rans",
            write_stream(
                &params(ChunkCodec::RansAlways { lanes: 2 }),
                &[tetra, one_split(0, 1, [2; 3], [4; 3], 5, 6)],
            ),
        ),
        (
            "triangle_boundary",
            write_stream(
                &params(ChunkCodec::Stored),
                &[tri, one_split(0, 1, [0, 4, 0], [3, 5, 0], 4, 2)],
            ),
        ),
        (
            "octahedron_base",
            write_stream(
                &params(ChunkCodec::Stored),
                &[streams::base_level(&octa, &[LEAF; 6])],
            ),
        ),
    ];
    for (name, stream) in &streams {
        if let Err(e) = splitstream_decoder_core::owned::decode_all(stream, false) {
            panic!("hand-made seed {name} does not decode: {e}");
        }
    }
    streams
}

fn main() {
    let dir: PathBuf = std::env::args_os()
        .nth(1)
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from("decoder-core/fuzz/corpus"));
    for sub in ["decode_bytes", "decode_mutated", "round_records"] {
        std::fs::create_dir_all(dir.join(sub)).unwrap();
    }
    let mut n = 0;
    for (name, bytes) in handmade() {
        if let Some(e) = streams::decode_full(&bytes).error {
            panic!("{name}: {e}");
        }
        std::fs::write(dir.join("decode_bytes").join(format!("{name}.sps")), &bytes).unwrap();
        n += 1;
    }
    // The embedded-size demo stream (deflate chunks).
    std::fs::write(dir.join("tetrahedron.sps"), &handmade()[1].1).unwrap();
    for (i, g) in streams::seed_generated().iter().enumerate() {
        streams::check_against(g, &streams::decode_full(&g.stream)).unwrap();
        std::fs::write(
            dir.join("decode_bytes")
                .join(format!("gen_{i:02}_{}.sps", g.base)),
            &g.stream,
        )
        .unwrap();
        std::fs::write(
            dir.join("decode_mutated").join(format!("seed_{i:02}")),
            [i as u8],
        )
        .unwrap();
        println!(
            "seed {i:2}: {:<12} {:>5} bytes, {} levels{}, {} rounds, {} splits",
            g.base,
            g.stream.len(),
            g.levels.len() - g.seeded as usize,
            if g.seeded { " (rounds in level 0)" } else { "" },
            g.hashes.len() - 1,
            g.splits
        );
        n += 2;
    }
    for b in 0..streams::bases().len() as u8 {
        std::fs::write(dir.join("round_records").join(format!("zeros_{b}")), [b, 0]).unwrap();
        n += 1;
    }
    for seed in 1..=10u64 {
        let bytes = streams::pseudo_random_bytes(seed, 512);
        let g = streams::generate(&mut Choices::new(&bytes), false);
        assert!(g.error.is_none());
        std::fs::write(
            dir.join("round_records").join(format!("random_{seed:02}")),
            &bytes,
        )
        .unwrap();
        n += 1;
    }
    println!("wrote {n} files under {}", dir.display());
}
