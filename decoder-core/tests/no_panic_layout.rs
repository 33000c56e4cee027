//! No panic from the workspace layout arithmetic (SPEC §9) on any target.
//!
//! Regression test: `Layout::new` used to size the workspace regions with
//! `usize` arithmetic (`12 * vertex_capacity`, `4 * opposite_len`, ...). On a
//! 32-bit target (thumbv7em, i686, wasm32) counts allowed by the header (up
//! to `MAX_VERTICES` / `MAX_TRIANGLES`) overflowed `usize`: debug builds
//! panicked with "attempt to multiply with overflow" inside `workspace_len` /
//! `Decoder::new`; release builds wrapped, and a stream could declare the
//! wrapped `workspace_bytes` (0 for the counts below), so that the layout
//! "fit" any buffer and `Layout::carve` panicked in `split_at_mut`. Fixed by
//! the 64-bit layout arithmetic of commit c8a13af.
//!
//! Run it where it matters, on a 32-bit host target (needs gcc-multilib):
//! `cargo test -p splitstream-decoder-core --target i686-unknown-linux-gnu --test no_panic_layout`
//! (debug and `--release`).

use splitstream_decoder_core::limits::LEAF;
use splitstream_decoder_core::writer::{
    ChunkCodec, LevelPayload, StreamParams, SubstreamWriter, write_stream,
};
use splitstream_decoder_core::{
    Decoder, DeficitContexts, Error, Inflater, PositionMode, WingPolicy, workspace_len,
};

/// 536 870 920 vertices and 690 662 050 triangles after level 1: within the
/// header limits, consistent growth, and with 32-bit wrapping arithmetic the
/// reference layout total is exactly 0 bytes (about 41 GB without wrapping).
const V: u32 = 536_870_920;
const T: u32 = 690_662_050;

/// A tetrahedron base plus one level that claims `V` / `T` (its records are
/// never reached: only the base fits in the test's workspace).
fn huge_stream() -> Vec<u8> {
    let params = StreamParams {
        framing: splitstream_decoder_core::Framing::Compact,
        position_mode: PositionMode::Optimal,
        bits: 8,
        origin: [0.0; 3],
        scale: [1.0; 3],
        codec: ChunkCodec::Stored,
        chunk_limit: 4,
        rans_chunk_limit: 4,
        schedule: splitstream_decoder_core::Schedule::SplitValences,
        adaptive_tables: true,
    };
    let mut base = vec![SubstreamWriter::default(); 3];
    let mut prev = [0i32; 3];
    for p in [[0, 0, 0], [10, 0, 0], [0, 10, 0], [0, 0, 10]] {
        for k in 0..3 {
            base[0].signed(p[k] - prev[k]);
        }
        prev = p;
    }
    for t in [[0u32, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]] {
        for v in t {
            base[1].varint(v);
        }
    }
    for d in [0, LEAF, LEAF, LEAF] {
        base[2].byte(d);
    }
    let base = LevelPayload {
        round_splits: vec![],
        plane: Default::default(),
        wings: WingPolicy::Ranks,
        deficits: DeficitContexts::Plain,
        records: splitstream_decoder_core::RecordOrder::WingsFirst,
        ties: splitstream_decoder_core::Ties::Ring,
        substreams: base,
        vertex_count: 4,
        triangle_count: 4,
        geometric_error: 1.0,
    };
    let mut flags = SubstreamWriter::default();
    flags.bit(true);
    let level = LevelPayload {
        round_splits: vec![1],
        plane: Default::default(),
        wings: WingPolicy::Ranks,
        deficits: DeficitContexts::Plain,
        records: splitstream_decoder_core::RecordOrder::WingsFirst,
        ties: splitstream_decoder_core::Ties::Ring,
        substreams: vec![flags],
        vertex_count: V,
        triangle_count: T,
        geometric_error: 0.0,
    };
    // The writer sizes `workspace_bytes` with the same layout arithmetic.
    write_stream(&params, &[base, level])
}

#[test]
fn huge_declared_counts_do_not_panic() {
    let stream = huge_stream();
    // The needed size is either reported (64-bit) or refused with a typed error.
    match workspace_len(&stream) {
        Ok(n) => assert!(n as u64 > 12 * V as u64, "needed {n}"),
        Err(e) => assert_eq!(e.class(), "capacity-exceeded"),
    }
    let mut inflater = Box::new(Inflater::new());
    let mut workspace = vec![0u8; 64 * 1024];
    match Decoder::new(&stream, &mut workspace, &mut inflater) {
        Ok(mut d) => {
            // Only the base fits; it decodes.
            assert_eq!(d.levels_that_fit(), 1);
            assert_eq!(d.decode_available(&stream), Ok(1));
            assert_eq!(d.triangles().len(), 4);
        }
        Err(e) => assert!(
            matches!(e, Error::CapacityExceeded | Error::InvalidHeader(_)),
            "{e:?}"
        ),
    }
}
