//! Streams built record by record with decoder-core's `writer`, as in
//! decoder-core/tests/handmade.rs and SPEC Appendix A: the smallest legal
//! streams, and faults that no encoder would write.

use splitstream_decoder_core::limits::LEAF;
use splitstream_decoder_core::owned::decode_all;
use splitstream_decoder_core::writer::{
    ChunkCodec, LevelPayload, SeedPayload, StreamParams, SubstreamWriter, write_stream,
};
use splitstream_decoder_core::{PositionMode, context};

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

/// A base level holding only a seed mesh (ids 8..=10); `write_stream`
/// frames it as level 0.
pub fn base(positions: &[[u32; 3]], triangles: &[[u32; 3]], deficits: &[u8]) -> LevelPayload {
    SeedPayload::new(positions, triangles, deficits).into_level(1.0)
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

/// One optimal-mode split record: o, d, deficits, and the two position
/// residuals as coded: `e` in the edge substream (P minus its prediction)
/// and `m` in the placement substream (C minus its prediction), SPEC §7.4.
/// `k` is the split vertex's ring length, which only selects the rANS
/// context of `d` (SPEC §5.5). Records built here start with zero
/// residuals; [`solve`] sets them for wanted positions of P and C.
#[derive(Clone, Copy)]
pub struct Rec {
    pub k: u8,
    pub o: u8,
    pub d: u8,
    pub dp: u8,
    pub dc: u8,
    pub e: [i32; 3],
    pub m: [i32; 3],
}

/// Sets the residuals of `rec` so that its split (of vertex `r`, creating
/// vertex `c`) places P at `p` and C at `cpos`: the stream `build` makes is
/// first decoded with zero residuals, which yields P's prediction; then with
/// P's residual set, which yields C's (it may depend on P), whatever
/// predictor SPEC §7.4 uses, as long as residuals are added to it.
pub fn solve(
    rec: Rec,
    r: usize,
    c: usize,
    p: [i32; 3],
    cpos: [i32; 3],
    build: &dyn Fn(Rec) -> Vec<u8>,
) -> Rec {
    // C's probe residual is biased so that C stays inside the 8-bit grid
    // whatever P is during the probes.
    const BIAS: i32 = 64;
    let zero = Rec {
        e: [0; 3],
        m: [BIAS; 3],
        ..rec
    };
    let probe = decode_all(&build(zero), false).expect("the zero-residual probe decodes");
    let ph = probe.positions[r];
    let half = Rec {
        e: std::array::from_fn(|k| p[k] - ph[k] as i32),
        ..zero
    };
    let probe = decode_all(&build(half), false).expect("the P-residual probe decodes");
    let ch = probe.positions[c];
    let solved = Rec {
        m: std::array::from_fn(|k| cpos[k] - (ch[k] as i32 - BIAS)),
        ..half
    };
    if let Ok(mesh) = decode_all(&build(solved), false) {
        let want = (p.map(|x| x as u32), cpos.map(|x| x as u32));
        assert_eq!(
            (mesh.positions[r], mesh.positions[c]),
            want,
            "residuals do not add to the prediction (SPEC §7.4 changed?)"
        );
    }
    solved
}

/// A refinement level (ids 1..=7) in optimal mode, values in the contexts
/// SPEC §5.5 gives them.
pub fn level(flags: &[bool], rounds: Vec<u32>, recs: &[Rec], v: u32, t: u32) -> LevelPayload {
    let mut s = vec![SubstreamWriter::default(); 7];
    for &f in flags {
        s[0].bit(f);
    }
    for r in recs {
        s[1].byte(r.o);
        s[2].byte_in(context::wing_distance(r.k as usize), r.d);
        s[3].byte(r.dp);
        s[4].byte_in(context::deficit_c(r.dp), r.dc);
        for k in 0..3 {
            s[5].signed_in(context::axis(k), r.e[k]);
        }
        for k in 0..3 {
            s[6].signed_in(context::axis(k), r.m[k]);
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

pub const TETRA_POSITIONS: [[u32; 3]; 4] = [[0, 0, 0], [10, 0, 0], [0, 10, 0], [0, 0, 10]];
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

/// Splits vertex 0 (ring 1, 3, 2) with wings 1 and 3, P keeping wedge
/// (0,1,3); P at its prediction (3, 0, 3), C at its prediction (-1, -1, -1)
/// plus (2, 2, 2), inside the grid.
pub fn tetra_split() -> Rec {
    Rec {
        k: 3,
        o: 0,
        d: 1,
        dp: LEAF,
        dc: LEAF,
        e: [0; 3],
        m: [2; 3],
    }
}

/// The one-split tetrahedron of SPEC Appendix A (5 vertices, 6 triangles):
/// P = (0,0,0), C = (2,2,2).
pub fn tetra_stream(codec: ChunkCodec) -> Vec<u8> {
    let build = |rec: Rec| {
        write_stream(
            &params(codec),
            &[tetrahedron(), level(&[true], vec![1], &[rec], 5, 6)],
        )
    };
    build(solve(tetra_split(), 0, 4, [0, 0, 0], [2, 2, 2], &build))
}

/// One triangle; vertex 0 (ring: ghost, 1, 2) splits with the ghost as a
/// wing: P = (0,0,0), C = (0,4,0).
pub fn boundary_ghost_wing_stream() -> Vec<u8> {
    let b = base(
        &[[0, 0, 0], [10, 0, 0], [0, 10, 0]],
        &[[0, 1, 2]],
        &[0, LEAF, LEAF],
    );
    let build = |rec: Rec| {
        write_stream(
            &params(ChunkCodec::Stored),
            &[b.clone(), level(&[true], vec![1], &[rec], 4, 2)],
        )
    };
    build(solve(tetra_split(), 0, 3, [0, 0, 0], [0, 4, 0], &build))
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
