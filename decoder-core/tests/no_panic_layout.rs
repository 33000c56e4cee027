//! No panic from the workspace layout arithmetic (SPEC §9) on any target.
//!
//! `Layout::new` sizes the workspace regions with `usize` arithmetic
//! (`12 * vertex_capacity`, `4 * opposite_len`, ...). On a 32-bit target
//! (thumbv7em, i686, wasm32) counts allowed by the header (up to
//! `MAX_VERTICES` / `MAX_TRIANGLES`) overflow `usize`: debug builds panic
//! with "attempt to multiply with overflow" inside `workspace_len` /
//! `Decoder::new`; release builds wrap, and a stream can declare the wrapped
//! `workspace_bytes` (here 0), so that the layout "fits" any buffer and
//! `Layout::carve` panics in `split_at_mut` ("mid > len").
//!
//! Reproduce on a 32-bit host target:
//! `cargo test -p splitstream-decoder-core --target i686-unknown-linux-gnu --test no_panic_layout -- --include-ignored`

use splitstream_decoder_core::limits::{HEADER_LEN, LEAF};
use splitstream_decoder_core::writer::{ChunkCodec, LevelPayload, StreamParams, SubstreamWriter, frame_level};
use splitstream_decoder_core::{
    Decoder, Error, Header, Inflater, Layout, LevelInfo, PositionMode, head_len, workspace_len,
    write_level_table,
};

/// 536 870 920 vertices and 690 662 050 triangles after level 1: within the
/// header limits, consistent growth, and on a 32-bit target the reference
/// layout total wraps to exactly 0 bytes.
const V: u32 = 536_870_920;
const T: u32 = 690_662_050;

/// A tetrahedron base plus one level that claims `V` / `T`. Built field by
/// field: `write_stream` itself computes the layout and would overflow too.
fn huge_stream() -> Vec<u8> {
    let params = StreamParams {
        position_mode: PositionMode::Optimal,
        bits: 8,
        origin: [0.0; 3],
        scale: [1.0; 3],
        codec: ChunkCodec::Stored,
        chunk_limit: 4,
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
        substreams: base,
        vertex_count: 4,
        triangle_count: 4,
        geometric_error: 1.0,
    };
    let mut flags = SubstreamWriter::default();
    flags.bit(true);
    let level = LevelPayload {
        round_splits: vec![1],
        substreams: vec![flags],
        vertex_count: V,
        triangle_count: T,
        geometric_error: 0.0,
    };
    let (b0, c0) = frame_level(&base, 9, &params);
    let (b1, c1) = frame_level(&level, 1, &params);
    let max_chunk = c0.max(c1);
    let head = head_len(2);
    let entries = [
        LevelInfo {
            offset: head as u64,
            length: b0.len() as u32,
            vertex_count: 4,
            triangle_count: 4,
            round_count: 0,
            geometric_error: 1.0,
        },
        LevelInfo {
            offset: (head + b0.len()) as u64,
            length: b1.len() as u32,
            vertex_count: V,
            triangle_count: T,
            round_count: 1,
            geometric_error: 0.0,
        },
    ];
    // What this target's own layout arithmetic says (wrapping in release on
    // 32-bit targets: 0; on 64-bit targets about 41 GB).
    let total = Layout::new(V, T, 4, 4, max_chunk).total as u64;
    let header = Header {
        version_minor: 0,
        position_mode: PositionMode::Optimal,
        bits: 8,
        level_count: 2,
        vertex_capacity: V,
        triangle_capacity: T,
        max_chunk_len: max_chunk,
        origin: [0.0; 3],
        scale: [1.0; 3],
        workspace_bytes: total,
    };
    let mut out = vec![0u8; head];
    let mut h = [0u8; HEADER_LEN];
    header.write(&mut h);
    out[..HEADER_LEN].copy_from_slice(&h);
    write_level_table(&entries, &mut out[HEADER_LEN..]);
    out.extend_from_slice(&b0);
    out.extend_from_slice(&b1);
    out
}

#[test]
#[cfg_attr(
    target_pointer_width = "32",
    ignore = "bug: Layout::new overflows usize on 32-bit targets (panic in workspace_len / Decoder::new / Layout::carve)"
)]
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
