//! Streams built record by record with [`crate::writer`] (SPEC Appendix A):
//! the smallest legal streams, and faults that no encoder would write. The
//! conformance generator, this crate's tests and the fuzz seed corpus build
//! their hand-made streams here, so a record means the same bytes in all
//! three; another implementation's test suite can use it the same way.
//! Needs the `alloc` feature.
//!
//! Every stream here has 8 bits per axis, unit scale, optimal position mode
//! and 4-byte chunks ([`params`]), so that every substream spans chunks.

use alloc::vec;
use alloc::vec::Vec;

use crate::Error;
use crate::context::{self, DeficitContexts};
use crate::header::{Framing, PositionMode, Schedule};
use crate::limits::LEAF;
use crate::owned::decode_all;
use crate::predict::PlanePolicy;
use crate::wing_order::WingPolicy;
use crate::writer::{
    ChunkCodec, LevelPayload, SeedPayload, StreamParams, SubstreamWriter, write_stream,
};

/// Why [`solve`] cannot fail on this module's own records.
const DECODES: &str = "a hand-made record of this module decodes";

/// 8 bits per axis, unit scale, 4-byte chunks: every substream spans chunks.
pub fn params(codec: ChunkCodec) -> StreamParams {
    StreamParams {
        position_mode: PositionMode::Optimal,
        bits: 8,
        origin: [0.0; 3],
        scale: [1.0; 3],
        codec,
        chunk_limit: 4,
        rans_chunk_limit: 4,
        schedule: Schedule::SplitValences,
        adaptive_tables: false,
        // The hand-made vectors keep the framing they were made with
        // (3.0's); the encoder's vectors cover the compact one.
        framing: Framing::Fixed,
    }
}

/// [`params`] with stored chunks.
pub fn stored() -> StreamParams {
    params(ChunkCodec::Stored)
}

/// [`params`] with deflate chunks (level 6).
pub fn deflated() -> StreamParams {
    params(ChunkCodec::Deflate(6))
}

/// A base level holding only a seed mesh (substream ids 8..=10);
/// [`write_stream`] frames it as level 0.
pub fn base(positions: &[[u32; 3]], triangles: &[[u32; 3]], deficits: &[u8]) -> LevelPayload {
    SeedPayload::new(positions, triangles, deficits).into_level(1.0)
}

/// Replaces substream `index` of `level` by raw bytes; `None` when the
/// level has no substream `index`.
pub fn with_raw_substream(
    mut level: LevelPayload,
    index: usize,
    bytes: &[u8],
) -> Option<LevelPayload> {
    let mut s = SubstreamWriter::default();
    for &b in bytes {
        s.byte(b);
    }
    *level.substreams.get_mut(index)? = s;
    Some(level)
}

/// One optimal-mode split record as coded (SPEC §7.4): the wing ranks `o`
/// and `d` among the `m` ring entries that may be wings, the split-valence
/// symbols `sp` and `sc` of P and C (0: a leaf), and the two position
/// residual vectors per axis: `e` in the edge substream (P's) and `t` in the
/// placement substream (C's). `valence_c` (C's valence right after the
/// split) and `axis` (the plane's predicted axis, `None` under the policy
/// `off`) only select the order and rANS contexts of the values (SPEC
/// §5.5.5). [`solve`] sets the residuals for wanted positions of P and C.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Rec {
    pub m: u8,
    pub o: u8,
    pub d: u8,
    pub sp: u8,
    pub sc: u8,
    pub valence_c: u8,
    pub axis: Option<usize>,
    pub e: [i32; 3],
    pub t: [i32; 3],
}

/// Sets the residuals of `rec` so that its split (of vertex `r`, creating
/// vertex `c`) places P at `p` and C at `cpos`: the stream `build` makes is
/// decoded with trial residuals and corrected by what each axis missed,
/// until both land (at most four probes: under a plane policy the predicted
/// axis also moves with the other two, SPEC §7.4), whatever the
/// prediction, as long as the residuals are added to it. A wanted position
/// outside the grid keeps the last correction.
///
/// # Errors
/// The error of the first probe when it does not decode (the record is
/// wrong in more than its residuals); [`Error::NoSuchVertex`] when the
/// decoded mesh has no vertex `r` or `c`.
pub fn solve(
    rec: Rec,
    r: usize,
    c: usize,
    p: [i32; 3],
    cpos: [i32; 3],
    build: &dyn Fn(Rec) -> Vec<u8>,
) -> Result<Rec, Error> {
    // The first probe is biased so that P and C stay inside the 8-bit grid
    // whatever the predictions are.
    const BIAS: i32 = 64;
    let mut trial = Rec {
        e: [BIAS; 3],
        t: [BIAS; 3],
        ..rec
    };
    for probe_index in 0..4 {
        let probe = match decode_all(&build(trial), false) {
            Ok(probe) => probe,
            Err(_) if probe_index > 0 => return Ok(trial),
            Err(e) => return Err(e),
        };
        let (Some(&gp), Some(&gc)) = (probe.positions.get(r), probe.positions.get(c)) else {
            return Err(Error::NoSuchVertex);
        };
        if (gp, gc) == (p.map(|x| x as u32), cpos.map(|x| x as u32)) {
            return Ok(trial);
        }
        for k in 0..3 {
            trial.e[k] += p[k] - gp[k] as i32;
            trial.t[k] += cpos[k] - gc[k] as i32;
        }
    }
    Ok(trial)
}

/// A refinement level (substream ids 1..=7) in optimal mode under `plane`,
/// values in the order and contexts SPEC §5.5 and §7.4 give them.
pub fn level_with(
    plane: PlanePolicy,
    flags: &[bool],
    rounds: Vec<u32>,
    recs: &[Rec],
    v: u32,
    t: u32,
) -> LevelPayload {
    let mut s = vec![SubstreamWriter::default(); 7];
    for &f in flags {
        s[0].bit(f);
    }
    for r in recs {
        let wing = context::wing(r.m as usize);
        s[1].byte_in(wing, r.o);
        s[2].byte_in(wing, r.d);
        s[3].byte(r.sp);
        let deficit_p = if r.sp == 0 { LEAF } else { 0 };
        s[4].byte_in(
            context::deficit_c(DeficitContexts::Plain, deficit_p, r.valence_c as usize),
            r.sc,
        );
        let order = match r.axis {
            None => [0, 1, 2],
            Some(j) => [(j + 1) % 3, (j + 2) % 3, j],
        };
        for k in order {
            s[5].signed_in(context::residual(plane, k, r.axis), r.e[k]);
        }
        for k in order {
            s[6].signed_in(context::residual(plane, k, r.axis), r.t[k]);
        }
    }
    LevelPayload {
        round_splits: rounds,
        plane,
        wings: WingPolicy::Ranks,
        deficits: DeficitContexts::Plain,
        records: crate::RecordOrder::WingsFirst,
        ties: crate::Ties::Ring,
        substreams: s,
        vertex_count: v,
        triangle_count: t,
        geometric_error: 0.0,
    }
}

/// [`level_with`] under the plane policy `off`.
pub fn level(flags: &[bool], rounds: Vec<u32>, recs: &[Rec], v: u32, t: u32) -> LevelPayload {
    level_with(PlanePolicy::Off, flags, rounds, recs, v, t)
}

/// The tetrahedron of SPEC Appendix A.
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

/// A tetrahedron with the candidates given by `deficits`.
pub fn tetrahedron_with(deficits: &[u8]) -> LevelPayload {
    base(&TETRA_POSITIONS, &TETRA_TRIANGLES, deficits)
}

/// Splits vertex 0 (ring 1, 3, 2, every entry a leaf: m = 3) with wings 1
/// and 3, P keeping wedge (0,1,3); both halves leaves; zero residuals.
pub fn tetra_split() -> Rec {
    Rec {
        m: 3,
        o: 0,
        d: 1,
        sp: 0,
        sc: 0,
        valence_c: 4,
        axis: None,
        e: [0; 3],
        t: [0; 3],
    }
}

/// The level of one round of one split `rec` on a tetrahedron base: 5
/// vertices and 6 triangles after it, plane policy `off`.
pub fn tetra_split_level(rec: Rec) -> LevelPayload {
    level(&[true], vec![1], &[rec], 5, 6)
}

/// The one-split tetrahedron of SPEC Appendix A (5 vertices, 6 triangles):
/// plane policy `dominant` (the predicted axis is x), P = (0,0,0),
/// C = (2,2,2).
pub fn tetra_stream(codec: ChunkCodec) -> Vec<u8> {
    tetra_stream_under(&params(codec))
}

/// [`tetra_stream`] framed under `params` (for rANS with adaptive tables,
/// `params(..)` with `adaptive_tables` set).
pub fn tetra_stream_under(params: &StreamParams) -> Vec<u8> {
    let build = |rec: Rec| {
        write_stream(
            params,
            &[
                tetrahedron(),
                level_with(PlanePolicy::Dominant, &[true], vec![1], &[rec], 5, 6),
            ],
        )
    };
    let rec = Rec {
        axis: Some(0),
        ..tetra_split()
    };
    let rec = solve(rec, 0, 4, [0, 0, 0], [2, 2, 2], &build).expect(DECODES);
    build(rec)
}

/// The octahedron: 0 = +x, 1 = -x, 2 = +y, 3 = -y, 4 = +z, 5 = -z.
pub const OCTA_POSITIONS: [[u32; 3]; 6] = [
    [20, 10, 10],
    [0, 10, 10],
    [10, 20, 10],
    [10, 0, 10],
    [10, 10, 20],
    [10, 10, 0],
];
pub const OCTA_TRIANGLES: [[u32; 3]; 8] = [
    [0, 2, 4],
    [2, 1, 4],
    [1, 3, 4],
    [3, 0, 4],
    [2, 0, 5],
    [1, 2, 5],
    [3, 1, 5],
    [0, 3, 5],
];

/// The octahedron with `deficits`.
pub fn octahedron(deficits: &[u8]) -> LevelPayload {
    base(&OCTA_POSITIONS, &OCTA_TRIANGLES, deficits)
}

/// One triangle: vertex 0's ring is (ghost, 1, 2).
pub const TRIANGLE_POSITIONS: [[u32; 3]; 3] = [[0, 0, 0], [10, 0, 0], [0, 10, 0]];

/// One triangle (0, 1, 2) with `deficits`.
pub fn triangle(deficits: &[u8]) -> LevelPayload {
    base(&TRIANGLE_POSITIONS, &[[0, 1, 2]], deficits)
}

/// Two tetrahedra sharing vertex 0 only (a bowtie vertex: two fans), all
/// leaves: a base mesh SPEC §6 rejects as non-manifold.
pub fn bowtie() -> LevelPayload {
    base(
        &[
            [0, 0, 0],
            [1, 0, 0],
            [0, 1, 0],
            [0, 0, 1],
            [9, 0, 0],
            [0, 9, 0],
            [0, 0, 9],
        ],
        &[
            [0, 2, 1],
            [0, 1, 3],
            [0, 3, 2],
            [1, 2, 3],
            [0, 5, 4],
            [0, 4, 6],
            [0, 6, 5],
            [4, 5, 6],
        ],
        &[LEAF; 7],
    )
}

/// One triangle; vertex 0 (ring: ghost, 1, 2) splits with the ghost as a
/// wing: P = (0,0,0), C = (0,4,0).
pub fn boundary_ghost_wing_stream() -> Vec<u8> {
    let b = triangle(&[0, LEAF, LEAF]);
    let build = |rec: Rec| {
        write_stream(
            &stored(),
            &[b.clone(), level(&[true], vec![1], &[rec], 4, 2)],
        )
    };
    let rec = solve(tetra_split(), 0, 3, [0, 0, 0], [0, 4, 0], &build).expect(DECODES);
    build(rec)
}

/// A single triangle, base only: the smallest legal stream.
pub fn single_triangle_stream() -> Vec<u8> {
    write_stream(&stored(), &[triangle(&[LEAF; 3])])
}

#[cfg(test)]
mod tests {
    use super::*;

    fn build(rec: Rec) -> Vec<u8> {
        write_stream(&stored(), &[tetrahedron(), tetra_split_level(rec)])
    }

    #[test]
    fn solve_places_p_and_c() {
        let rec = solve(tetra_split(), 0, 4, [1, 2, 3], [7, 5, 9], &build).unwrap();
        let mesh = decode_all(&build(rec), true).unwrap();
        assert_eq!(mesh.positions[0], [1, 2, 3]);
        assert_eq!(mesh.positions[4], [7, 5, 9]);
        let mesh = decode_all(&tetra_stream(ChunkCodec::Deflate(6)), true).unwrap();
        assert_eq!((mesh.positions[0], mesh.positions[4]), ([0; 3], [2; 3]));
    }

    #[test]
    fn solve_reports_what_it_cannot_do() {
        let bad = Rec {
            o: 2,
            ..tetra_split()
        };
        assert_eq!(
            solve(bad, 0, 4, [0; 3], [2; 3], &build),
            Err(Error::RingOffsetOutOfRange)
        );
        assert_eq!(
            solve(tetra_split(), 0, 5, [0; 3], [2; 3], &build),
            Err(Error::NoSuchVertex)
        );
    }

    #[test]
    fn raw_substreams_replace_only_existing_ones() {
        let level = with_raw_substream(triangle(&[LEAF; 3]), 1, &[0, 1, 2]).unwrap();
        assert_eq!(level.substreams[1].as_bytes(), &[0, 1, 2]);
        assert!(with_raw_substream(triangle(&[LEAF; 3]), 3, &[0]).is_none());
    }
}
