//! Decoding time is bounded, but not linear in the stream size: every round
//! scans the deficits of all current vertices (SPEC §7.3 step 1), so a level
//! of R one-split rounds over a mesh of V vertices costs O(R × V) while its
//! bytes grow only by about 4 bytes per round (the split count in the level
//! header; the records compress to almost nothing). This measures it on a
//! small scale; run with
//! `cargo test --release -p splitstream-decoder-core --test no_panic_rounds -- --ignored --nocapture`.

use std::time::Instant;

use splitstream_decoder_core::limits::LEAF;
use splitstream_decoder_core::owned::decode_all;
use splitstream_decoder_core::writer::{
    ChunkCodec, LevelPayload, StreamParams, SubstreamWriter, write_stream,
};
use splitstream_decoder_core::{DeficitContexts, PositionMode, WingPolicy};

/// A `w` x `w` grid whose centre vertex splits once per round, `rounds` times.
fn many_rounds(w: u32, rounds: u32) -> Vec<u8> {
    let mut subs = vec![SubstreamWriter::default(); 3];
    let mut prev = [0i32; 3];
    for j in 0..w {
        for i in 0..w {
            let p = [i as i32, j as i32, 0];
            for k in 0..3 {
                subs[0].signed(p[k] - prev[k]);
            }
            prev = p;
        }
    }
    let mut nt = 0;
    for j in 0..w - 1 {
        for i in 0..w - 1 {
            let v00 = j * w + i;
            let (v10, v01, v11) = (v00 + 1, v00 + w, v00 + w + 1);
            for v in [v00, v10, v11, v00, v11, v01] {
                subs[1].varint(v);
            }
            nt += 2;
        }
    }
    let centre = (w / 2) * w + w / 2;
    for v in 0..w * w {
        subs[2].byte(if v == centre { 0 } else { LEAF });
    }
    let nv = w * w;
    let base = LevelPayload {
        round_splits: vec![],
        plane: Default::default(),
        wings: WingPolicy::Ranks,
        deficits: DeficitContexts::Plain,
        records: splitstream_decoder_core::RecordOrder::WingsFirst,
        ties: splitstream_decoder_core::Ties::Ring,
        substreams: subs,
        vertex_count: nv,
        triangle_count: nt,
        geometric_error: 1.0,
    };
    // Each round: the centre is the only candidate; it splits with wings
    // r_0, r_1 (every ring entry is a leaf, so ranks are ring positions),
    // keeps one wedge (valence 3) and deficit 0; C is a leaf.
    let mut s = vec![SubstreamWriter::default(); 7];
    for _ in 0..rounds {
        s[0].bit(true);
        s[1].byte(0);
        s[2].byte(1);
        s[3].byte(1); // split valence 3: deficit 0 at valence 3 (SPEC §7.4)
        s[4].byte(0); // a leaf
        for _ in 0..3 {
            s[5].signed(0);
        }
        for _ in 0..3 {
            s[6].signed(0);
        }
    }
    let level = LevelPayload {
        round_splits: vec![1; rounds as usize],
        plane: Default::default(),
        wings: WingPolicy::Ranks,
        deficits: DeficitContexts::Plain,
        records: splitstream_decoder_core::RecordOrder::WingsFirst,
        ties: splitstream_decoder_core::Ties::Ring,
        substreams: s,
        vertex_count: nv + rounds,
        triangle_count: nt + 2 * rounds,
        geometric_error: 0.0,
    };
    let params = StreamParams {
        framing: splitstream_decoder_core::Framing::Compact,
        position_mode: PositionMode::Optimal,
        bits: 16,
        origin: [0.0; 3],
        scale: [1.0; 3],
        codec: ChunkCodec::Deflate(9),
        chunk_limit: 1 << 16,
        rans_chunk_limit: 1 << 16,
        schedule: splitstream_decoder_core::Schedule::SplitValences,
        adaptive_tables: true,
    };
    write_stream(&params, &[base, level])
}

#[test]
fn small_many_rounds_stream_decodes() {
    let stream = many_rounds(8, 50);
    let mesh = decode_all(&stream, false).unwrap();
    assert_eq!(mesh.positions.len(), 64 + 50);
}

#[test]
#[ignore = "perf: O(rounds x vertices) decode time, see the module docs"]
fn rounds_times_vertices() {
    for (w, rounds) in [(250u32, 2_000u32), (250, 8_000), (500, 8_000)] {
        let stream = many_rounds(w, rounds);
        let t = Instant::now();
        let mesh = decode_all(&stream, false).unwrap();
        let dt = t.elapsed().as_secs_f64();
        assert_eq!(mesh.positions.len() as u32, w * w + rounds);
        println!(
            "V = {:>7}, rounds = {:>6}: {:>9} bytes, {:.3} s, {:.1} ns per vertex-round",
            w * w,
            rounds,
            stream.len(),
            dt,
            dt * 1e9 / (w as f64 * w as f64 * rounds as f64)
        );
    }
}
