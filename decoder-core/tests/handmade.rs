//! Hand-made streams (SPEC §6, §7): a tetrahedron with one split, a
//! triangle with a boundary split, and the errors SPEC §10 requires.

use splitstream_decoder_core::limits::LEAF;
use splitstream_decoder_core::owned::decode_all;
use splitstream_decoder_core::writer::{
    ChunkCodec, LevelPayload, SeedPayload, StreamParams, SubstreamWriter, write_stream,
};
use splitstream_decoder_core::{Error, PositionMode, context};

fn params(codec: ChunkCodec) -> StreamParams {
    StreamParams {
        position_mode: PositionMode::Optimal,
        bits: 8,
        origin: [0.0; 3],
        scale: [1.0; 3],
        codec,
        chunk_limit: 4,
    }
}

fn base(positions: &[[u32; 3]], triangles: &[[u32; 3]], deficits: &[u8]) -> LevelPayload {
    SeedPayload::new(positions, triangles, deficits).into_level(1.0)
}

/// One optimal-mode split record: o, d, deficits, and the residuals of P and C.
struct Rec {
    o: u8,
    d: u8,
    dp: u8,
    dc: u8,
    e: [i32; 3],
    m: [i32; 3],
}

fn level(flags: &[bool], rounds: Vec<u32>, recs: &[Rec], v: u32, t: u32) -> LevelPayload {
    // Every split here has a ring of 3: the rANS contexts follow (SPEC §5.5).
    let mut s = vec![SubstreamWriter::default(); 7];
    for &f in flags {
        s[0].bit(f);
    }
    for r in recs {
        s[1].byte(r.o);
        s[2].byte_in(context::wing_distance(3), r.d);
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

fn tetrahedron() -> LevelPayload {
    base(
        &[[0, 0, 0], [10, 0, 0], [0, 10, 0], [0, 0, 10]],
        &[[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]],
        &[0, LEAF, LEAF, LEAF],
    )
}

/// Splits vertex 0 (ring 1, 3, 2) with wings 1 and 3, P keeping wedge (0,1,3).
fn tetra_split() -> Rec {
    // Predictions (SPEC §7.4): P̂ = mean(R, 1, 3) = (3, 0, 3), so P = (0, 0, 0)
    // takes e = (-3, 0, -3); Ĉ = mean(R, 3, 2, 1) = (2, 2, 2), refined with
    // 2R - P = (0, 0, 0) to (1, 1, 1), so C = (2, 2, 2) takes m = (1, 1, 1).
    Rec {
        o: 0,
        d: 1,
        dp: LEAF,
        dc: LEAF,
        e: [-3, 0, -3],
        m: [1; 3],
    }
}

/// Every directed edge has exactly one reverse: a closed or bordered 2-manifold.
fn assert_oriented_manifold(triangles: &[[u32; 3]]) {
    let mut directed: Vec<(u32, u32)> = triangles
        .iter()
        .flat_map(|t| [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])])
        .collect();
    directed.sort_unstable();
    assert!(
        directed.windows(2).all(|w| w[0] != w[1]),
        "a directed edge twice"
    );
}

#[test]
fn tetrahedron_one_split() {
    for codec in [
        ChunkCodec::Stored,
        ChunkCodec::Deflate(9),
        ChunkCodec::RansAlways { lanes: 1 },
        ChunkCodec::RansAlways { lanes: 32 },
    ] {
        let stream = write_stream(
            &params(codec),
            &[
                tetrahedron(),
                level(&[true], vec![1], &[tetra_split()], 5, 6),
            ],
        );
        let mesh = decode_all(&stream, true).unwrap();
        assert_eq!(
            mesh.triangles,
            vec![
                [4, 2, 1],
                [0, 1, 3],
                [4, 3, 2],
                [1, 2, 3],
                [0, 4, 1],
                [4, 0, 3]
            ]
        );
        assert_eq!(mesh.positions[0], [0, 0, 0]);
        assert_eq!(mesh.positions[4], [2, 2, 2]);
        assert_eq!(mesh.deficits, vec![LEAF; 5]);
        assert_eq!(mesh.round_hashes.len(), 2);
        assert_oriented_manifold(&mesh.triangles);
        let edges = mesh.triangles.len() * 3 / 2;
        assert_eq!(5 + 6 - edges as i64, 2, "Euler characteristic of a sphere");
    }
}

#[test]
fn boundary_split_with_a_ghost_wing() {
    // One triangle; vertex 0's ring is (ghost, 1, 2). Wings: ghost and 1.
    let b = base(
        &[[0, 0, 0], [10, 0, 0], [0, 10, 0]],
        &[[0, 1, 2]],
        &[0, LEAF, LEAF],
    );
    let rec = Rec {
        o: 0,
        d: 1,
        dp: LEAF,
        dc: LEAF,
        // P̂ = mean(R, 1) = (5, 0, 0); Ĉ = mean(R, 1, 2) = (3, 3, 0), refined
        // with 2R - P = (0, 0, 0) to (1, 1, 0): P = (0, 0, 0), C = (0, 4, 0).
        e: [-5, 0, 0],
        m: [-1, 3, 0],
    };
    let stream = write_stream(
        &params(ChunkCodec::Stored),
        &[b, level(&[true], vec![1], &[rec], 4, 2)],
    );
    let mesh = decode_all(&stream, false).unwrap();
    assert_eq!(mesh.triangles, vec![[3, 1, 2], [3, 0, 1]]);
    assert_eq!(mesh.positions[3], [0, 4, 0]);
    assert_eq!(mesh.positions[0], [0, 0, 0]);
    assert_oriented_manifold(&mesh.triangles);
}

fn decode_err(levels: &[LevelPayload]) -> Error {
    let stream = write_stream(&params(ChunkCodec::Deflate(6)), levels);
    decode_all(&stream, false).unwrap_err()
}

#[test]
fn ring_offset_out_of_range() {
    let mut rec = tetra_split();
    rec.o = 2; // o + d = 3 = ring length
    let err = decode_err(&[tetrahedron(), level(&[true], vec![1], &[rec], 5, 6)]);
    assert_eq!(err, Error::RingOffsetOutOfRange);
}

#[test]
fn flag_count_mismatch() {
    let err = decode_err(&[
        tetrahedron(),
        level(&[false], vec![1], &[tetra_split()], 5, 6),
    ]);
    assert_eq!(err.class(), "count-mismatch");
}

#[test]
fn flag_of_a_neighbour_of_a_flagged_vertex_is_inferred() {
    // Vertices 0 and 1 are adjacent candidates. Once 0 is flagged, 1's flag
    // is not read (SPEC §7.2): a second flag bit is left over as padding
    // that is not zero, and the round has one split where two are declared.
    let b = base(
        &[[0, 0, 0], [10, 0, 0], [0, 10, 0], [0, 0, 10]],
        &[[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]],
        &[0, 0, LEAF, LEAF],
    );
    let err = decode_err(&[
        b,
        level(
            &[true, true],
            vec![2],
            &[tetra_split(), tetra_split()],
            6,
            8,
        ),
    ]);
    assert_eq!(err.class(), "count-mismatch");
}

#[test]
fn inferred_flag_leaves_the_neighbour_a_candidate() {
    // Vertices 0 and 2 are adjacent candidates; 0 splits (wings 1 and 3) and
    // 2's flag is inferred 0, so one flag bit codes the whole round.
    let b = base(
        &[[0, 0, 0], [10, 0, 0], [0, 10, 0], [0, 0, 10]],
        &[[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]],
        &[0, LEAF, 0, LEAF],
    );
    for codec in [ChunkCodec::Stored, ChunkCodec::RansAlways { lanes: 2 }] {
        let stream = write_stream(
            &params(codec),
            &[b.clone(), level(&[true], vec![1], &[tetra_split()], 5, 6)],
        );
        let mesh = decode_all(&stream, true).unwrap();
        assert_eq!(mesh.positions.len(), 5);
        assert_eq!(mesh.positions[4], [2, 2, 2]);
    }
}

#[test]
fn valence_overflow_on_a_wing() {
    // Vertex 1 is a pending candidate that is not split but is a wing.
    let b = base(
        &[[0, 0, 0], [10, 0, 0], [0, 10, 0], [0, 0, 10]],
        &[[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]],
        &[0, 0, LEAF, LEAF],
    );
    let err = decode_err(&[b, level(&[true], vec![1], &[tetra_split()], 5, 6)]);
    assert_eq!(err, Error::ValenceOverflow);
}

#[test]
fn corrupt_bytes_are_caught_by_checksums() {
    let stream = write_stream(
        &params(ChunkCodec::Deflate(6)),
        &[
            tetrahedron(),
            level(&[true], vec![1], &[tetra_split()], 5, 6),
        ],
    );
    for at in 0..stream.len() {
        let mut bad = stream.clone();
        bad[at] ^= 0x10;
        let err = decode_all(&bad, false).unwrap_err();
        assert!(
            matches!(
                err.class(),
                "checksum-mismatch"
                    | "bad-magic"
                    | "unsupported-version"
                    | "malformed"
                    | "truncated"
            ),
            "byte {at}: {err:?}"
        );
    }
    for len in 0..stream.len() {
        assert!(decode_all(&stream[..len], false).is_err());
    }
}

#[test]
fn non_manifold_base_is_rejected() {
    // Two tetrahedra sharing vertex 0 only: a bowtie vertex.
    let b = base(
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
    );
    let stream = write_stream(&params(ChunkCodec::Stored), &[b]);
    assert_eq!(
        decode_all(&stream, false).unwrap_err().class(),
        "non-manifold"
    );
}
