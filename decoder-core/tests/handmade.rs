//! Hand-made streams (SPEC §6, §7): a tetrahedron with one split, a
//! triangle with a boundary split, and the errors SPEC §10 requires.

use splitstream_decoder_core::Error;
use splitstream_decoder_core::handmade::{
    Rec, bowtie, level, octahedron, params, tetra_split_level, tetrahedron, tetrahedron_with,
    triangle,
};
use splitstream_decoder_core::limits::LEAF;
use splitstream_decoder_core::owned::decode_all;
use splitstream_decoder_core::writer::{ChunkCodec, LevelPayload, write_stream};

/// [`splitstream_decoder_core::handmade::tetra_split`] with residuals
/// worked out by hand: vertex 0 (ring 1, 3, 2) splits with wings 1 and 3, P
/// keeping wedge (0,1,3).
fn tetra_split() -> Rec {
    // Predictions (SPEC §7.4), relative to R = (0, 0, 0): wing mean
    // m_W = (5, 0, 5), arc 1 has no interior entry (m_I1 = 0), arc 2 holds
    // vertex 2 (m_I2 = (0, 10, 0)). P̂ = (m_W + 4 m_I1 - m_I2) >> 4 =
    // (0, -1, 0), so P = (0, 0, 0) takes e = (0, 1, 0); Ĉ = (m_W + 4 m_I2 -
    // m_I1) >> 4 = (0, 2, 0), so C = (2, 2, 2) takes t = (2, 0, 2).
    Rec {
        e: [0, 1, 0],
        t: [2, 0, 2],
        ..splitstream_decoder_core::handmade::tetra_split()
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
            &[tetrahedron(), tetra_split_level(tetra_split())],
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
    let b = triangle(&[0, LEAF, LEAF]);
    let rec = Rec {
        // m_W = (10, 0, 0) (the ghost is no real wing), m_I1 = 0, m_I2 =
        // (0, 10, 0): P̂ = (0, -1, 0), Ĉ = (0, 2, 0); P = (0, 0, 0), C = (0, 4, 0).
        e: [0, 1, 0],
        t: [0, 2, 0],
        ..tetra_split()
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
    rec.o = 2; // o' + d' = 3 = m
    let err = decode_err(&[tetrahedron(), tetra_split_level(rec)]);
    assert_eq!(err, Error::RingOffsetOutOfRange);
    let mut rec = tetra_split();
    rec.d = 0;
    let err = decode_err(&[tetrahedron(), tetra_split_level(rec)]);
    assert_eq!(err, Error::RingOffsetOutOfRange);
}

#[test]
fn a_round_start_candidate_is_no_wing() {
    // Vertices 0 and 1 are adjacent candidates: 1's flag is inferred once 0
    // is flagged, and 1 may not be a wing (SPEC §7.4). Vertex 0's ring
    // (1, 3, 2) has m = 2 entries that may be wings: ranks 0 and 2 name none.
    let b = tetrahedron_with(&[0, 0, LEAF, LEAF]);
    let rec = Rec {
        m: 2,
        d: 2,
        ..tetra_split()
    };
    let err = decode_err(&[b.clone(), tetra_split_level(rec)]);
    assert_eq!(err, Error::RingOffsetOutOfRange);
    // Ranks 0 and 1 name vertices 3 and 2: P gets the wedge (0, 3, 2).
    // m_W = (0, 5, 5), m_I2 = (10, 0, 0): P̂ = (-1, 0, 0), Ĉ = (2, 0, 0).
    let rec = Rec {
        m: 2,
        e: [1, 0, 0],
        ..tetra_split()
    };
    let stream = write_stream(
        &params(ChunkCodec::RansAlways { lanes: 1 }),
        &[b, tetra_split_level(rec)],
    );
    let mesh = decode_all(&stream, true).unwrap();
    assert_eq!(mesh.triangles[4], [0, 4, 3]);
    assert_eq!(mesh.triangles[5], [4, 0, 2]);
    assert_eq!(mesh.deficits[1], 0, "vertex 1 is still a candidate");
}

#[test]
fn split_valences_out_of_range() {
    // C's valence after the split is 4: symbol 1 (split valence 3) is below it.
    let rec = Rec {
        sc: 1,
        ..tetra_split()
    };
    let err = decode_err(&[tetrahedron(), tetra_split_level(rec)]);
    assert_eq!(err, Error::SplitValenceOutOfRange);
    assert_eq!(err.class(), "valence-overflow");
    // Symbols 254 and 255 are split valences above 255.
    for sp in [254, 255] {
        let rec = Rec {
            sp,
            ..tetra_split()
        };
        let err = decode_err(&[tetrahedron(), tetra_split_level(rec)]);
        assert_eq!(err, Error::SplitValenceOutOfRange);
    }
    // Symbol 253 is split valence 255: deficit 252 for P of valence 3.
    let rec = Rec {
        sp: 253,
        ..tetra_split()
    };
    let stream = write_stream(
        &params(ChunkCodec::Stored),
        &[tetrahedron(), tetra_split_level(rec)],
    );
    let mesh = decode_all(&stream, true).unwrap();
    assert_eq!(mesh.deficits[0], 252);
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
    let b = tetrahedron_with(&[0, 0, LEAF, LEAF]);
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
    let b = tetrahedron_with(&[0, LEAF, 0, LEAF]);
    // Vertex 2 was a candidate at round start: it may not be a wing, so
    // m = 2 (it still counts in the arc means).
    let rec = || Rec {
        m: 2,
        ..tetra_split()
    };
    for codec in [ChunkCodec::Stored, ChunkCodec::RansAlways { lanes: 2 }] {
        let stream = write_stream(&params(codec), &[b.clone(), tetra_split_level(rec())]);
        let mesh = decode_all(&stream, true).unwrap();
        assert_eq!(mesh.positions.len(), 5);
        assert_eq!(mesh.positions[4], [2, 2, 2]);
    }
}

#[test]
fn valence_overflow_on_a_wing() {
    // Vertices 0 and 1 are candidates that are not adjacent; vertex 2 (deficit
    // 1) is next to both. Both split in one round with 2 as a wing: after the
    // first split its deficit is 0, so the second split would take it past
    // its split valence. Both rings are (2, 4, 3, 5) in some rotation, every
    // entry eligible (m = 4): ranks (0, 1) name 2 and its successor.
    let b = octahedron(&[0, 0, 1, LEAF, LEAF, LEAF]);
    let rec = |valence_c| Rec {
        m: 4,
        valence_c,
        e: [0; 3],
        t: [0; 3],
        ..tetra_split()
    };
    let err = decode_err(&[b, level(&[true, true], vec![2], &[rec(5), rec(5)], 8, 12)]);
    assert_eq!(err, Error::ValenceOverflow);
}

#[test]
fn corrupt_bytes_are_caught_by_checksums() {
    let stream = write_stream(
        &params(ChunkCodec::Deflate(6)),
        &[tetrahedron(), tetra_split_level(tetra_split())],
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
    let b = bowtie();
    let stream = write_stream(&params(ChunkCodec::Stored), &[b]);
    assert_eq!(
        decode_all(&stream, false).unwrap_err().class(),
        "non-manifold"
    );
}
