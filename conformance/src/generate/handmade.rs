//! Streams built record by record with decoder-core's `writer`, as in
//! decoder-core/tests/handmade.rs and SPEC Appendix A: the smallest legal
//! streams, and faults that no encoder would write.

use splitstream_decoder_core::PositionMode;
use splitstream_decoder_core::limits::LEAF;
use splitstream_decoder_core::writer::{
    ChunkCodec, LevelPayload, StreamParams, SubstreamWriter, write_stream,
};

/// 8 bits per axis, unit scale, 4-byte chunks: every substream spans chunks.
pub fn params(codec: ChunkCodec) -> StreamParams {
    StreamParams {
        position_mode: PositionMode::Optimal,
        bits: 8,
        origin: [0.0; 3],
        scale: [1.0; 3],
        codec,
        chunk_limit: 4,
    }
}

/// A base level (ids 9..=11): delta-coded positions, triangles, deficits.
pub fn base(positions: &[[i32; 3]], triangles: &[[u32; 3]], deficits: &[u8]) -> LevelPayload {
    let mut subs = vec![SubstreamWriter::default(); 3];
    let mut prev = [0i32; 3];
    for p in positions {
        for k in 0..3 {
            subs[0].signed(p[k] - prev[k]);
        }
        prev = *p;
    }
    for t in triangles {
        for &v in t {
            subs[1].varint(v);
        }
    }
    for &d in deficits {
        subs[2].byte(d);
    }
    LevelPayload {
        round_splits: vec![],
        substreams: subs,
        vertex_count: positions.len() as u32,
        triangle_count: triangles.len() as u32,
        geometric_error: 1.0,
    }
}

/// Replaces substream `index` of `level` by raw bytes.
pub fn with_raw_substream(mut level: LevelPayload, index: usize, bytes: &[u8]) -> LevelPayload {
    let mut s = SubstreamWriter::default();
    for &b in bytes {
        s.byte(b);
    }
    level.substreams[index] = s;
    level
}

/// One optimal-mode split record: o, d, q, deficits, edge vector, midpoint offset.
#[derive(Clone, Copy)]
pub struct Rec {
    pub o: u8,
    pub d: u8,
    pub q: bool,
    pub dp: u8,
    pub dc: u8,
    pub e: [i32; 3],
    pub m: [i32; 3],
}

/// A refinement level (ids 1..=8) in optimal mode.
pub fn level(flags: &[bool], rounds: Vec<u32>, recs: &[Rec], v: u32, t: u32) -> LevelPayload {
    let mut s = vec![SubstreamWriter::default(); 8];
    for &f in flags {
        s[0].bit(f);
    }
    for r in recs {
        s[1].byte(r.o);
        s[2].byte(r.d);
        s[3].bit(r.q);
        s[4].byte(r.dp);
        s[5].byte(r.dc);
        for k in 0..3 {
            s[6].signed(r.e[k]);
            s[7].signed(r.m[k]);
        }
    }
    LevelPayload {
        round_splits: rounds,
        substreams: s,
        vertex_count: v,
        triangle_count: t,
        geometric_error: 0.0,
    }
}

pub const TETRA_POSITIONS: [[i32; 3]; 4] = [[0, 0, 0], [10, 0, 0], [0, 10, 0], [0, 0, 10]];
pub const TETRA_TRIANGLES: [[u32; 3]; 4] = [[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]];

/// The tetrahedron of SPEC Appendix A, vertex 0 a candidate.
pub fn tetrahedron() -> LevelPayload {
    base(&TETRA_POSITIONS, &TETRA_TRIANGLES, &[0, LEAF, LEAF, LEAF])
}

/// A tetrahedron whose vertices all are leaves: a complete 1-level stream.
pub fn tetrahedron_leaves() -> LevelPayload {
    base(&TETRA_POSITIONS, &TETRA_TRIANGLES, &[LEAF; 4])
}

/// A tetrahedron with vertices 0 and 1 both candidates.
pub fn tetrahedron_two_candidates() -> LevelPayload {
    base(&TETRA_POSITIONS, &TETRA_TRIANGLES, &[0, 0, LEAF, LEAF])
}

/// Splits vertex 0 (ring 1, 3, 2) with wings 1 and 3, P keeping wedge (0,1,3):
/// P = (0,0,0), C = (2,2,2).
pub fn tetra_split() -> Rec {
    Rec {
        o: 0,
        d: 1,
        q: false,
        dp: LEAF,
        dc: LEAF,
        e: [2; 3],
        m: [-1; 3],
    }
}

/// The one-split tetrahedron stream (5 vertices, 6 triangles).
pub fn tetra_stream(codec: ChunkCodec) -> Vec<u8> {
    write_stream(
        &params(codec),
        &[
            tetrahedron(),
            level(&[true], vec![1], &[tetra_split()], 5, 6),
        ],
    )
}

/// One triangle; vertex 0 (ring: ghost, 1, 2) splits with the ghost as a wing.
pub fn boundary_ghost_wing_stream() -> Vec<u8> {
    let b = base(
        &[[0, 0, 0], [10, 0, 0], [0, 10, 0]],
        &[[0, 1, 2]],
        &[0, LEAF, LEAF],
    );
    let rec = Rec {
        o: 0,
        d: 1,
        q: false,
        dp: LEAF,
        dc: LEAF,
        e: [0, 4, 0],
        m: [0, -2, 0],
    };
    write_stream(
        &params(ChunkCodec::Stored),
        &[b, level(&[true], vec![1], &[rec], 4, 2)],
    )
}

/// A single triangle, base only: the smallest legal stream.
pub fn single_triangle_stream() -> Vec<u8> {
    write_stream(
        &params(ChunkCodec::Stored),
        &[base(
            &[[0, 0, 0], [10, 0, 0], [0, 10, 0]],
            &[[0, 1, 2]],
            &[LEAF; 3],
        )],
    )
}

pub fn stored() -> StreamParams {
    params(ChunkCodec::Stored)
}

pub fn deflated() -> StreamParams {
    params(ChunkCodec::Deflate(6))
}
