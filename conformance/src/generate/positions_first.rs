//! Vectors of the record orders that read positions first (SPEC §5.1,
//! §7.4, formats 3.7 and 3.8): terrains whose records read the new vertex
//! first, with and without boundaries, under both schedules and codecs,
//! under each tie rule, a stream whose fans all escape, and the faults a
//! decoder must find in them.

use splitstream_decoder_core::writer::ChunkCodec;
use splitstream_decoder_core::{DeficitContexts, PositionMode, RecordOrder, Schedule, Ties};
use splitstream_encoder::Mesh;
use splitstream_encoder::emit::EncodeOptions;
use splitstream_encoder::quantize::Lattice;

use splitstream_decoder_core::owned::decode_all;

use super::meshes;
use super::mutate::*;
use super::{Specs, encoded, opts};
use crate::builtin;
use crate::protocol::Verdict;

/// [`opts`] in constrained mode with every level read positions first.
fn positions_first(options: EncodeOptions) -> EncodeOptions {
    EncodeOptions {
        position_mode: PositionMode::Constrained,
        records: Some(RecordOrder::PositionsFirst),
        ..options
    }
}

fn terrain() -> Mesh {
    meshes::checked(
        splitstream_encoder::input::fractal_terrain(33, 7),
        "terrain",
    )
}

/// The deflate stream the record faults are made in.
fn deflated_terrain() -> Vec<u8> {
    encoded(
        &terrain(),
        positions_first(EncodeOptions {
            codec: ChunkCodec::Deflate(9),
            schedule: Schedule::EveryVertex,
            ..opts()
        }),
    )
}

pub(super) fn positions_first_valid(s: &mut Specs) {
    s.valid(
        "positions-first-terrain-rans",
        "33x33 fractal terrain, constrained positions on the raster's lattice, the schedule every-vertex, every level read positions first (3.7): the new vertex as a rank among its fan's free lattice points, the wings among the pairs that keep the new triangles counter-clockwise, z from the fan's surface; every substream rANS-coded.",
        &["encoded", "terrain", "rans", "positions-first"],
        encoded(
            &terrain(),
            positions_first(EncodeOptions {
                codec: ChunkCodec::RansAlways { lanes: 4 },
                schedule: Schedule::EveryVertex,
                ..opts()
            }),
        ),
    );
    s.valid(
        "positions-first-terrain-split-valences-deflate",
        "33x33 fractal terrain read positions first (3.7) under the schedule split-valences (the split valences of P and C read after the wings, in the contexts `valence`), deflate: the lattice ranks as varints.",
        &["encoded", "terrain", "deflate", "positions-first", "split-valences"],
        encoded(
            &terrain(),
            positions_first(EncodeOptions {
                codec: ChunkCodec::Deflate(9),
                deficits: Some(DeficitContexts::Valence),
                ..opts()
            }),
        ),
    );
    s.valid(
        "positions-first-grid-hole",
        "Height field with an outer boundary and a rectangular hole read positions first (3.7): boundary fans (the ghost among the wings, open sides with no lattice point), rANS.",
        &["encoded", "boundary", "ghost-wing", "rans", "positions-first"],
        encoded(
            &meshes::checked(
                meshes::grid(24, 20, 1, Some([8, 15, 6, 12])),
                "grid with hole",
            ),
            positions_first(EncodeOptions {
                codec: ChunkCodec::RansAlways { lanes: 4 },
                schedule: Schedule::EveryVertex,
                ..opts()
            }),
        ),
    );
    s.valid(
        "positions-first-stepped-terrain",
        "40x40 height field of whole-unit heights 0..3 read positions first (3.7, 3.8): many free points at equal distances from the ring's centroid (ties by y, then x) and cocircular wings (ties by the level's rule, the encoder's choice).",
        &["encoded", "terrain", "rans", "positions-first", "ties"],
        encoded(
            &meshes::checked(meshes::stepped_grid(40, 40, 1), "stepped grid"),
            positions_first(EncodeOptions {
                codec: ChunkCodec::RansAlways { lanes: 4 },
                schedule: Schedule::EveryVertex,
                ..opts()
            }),
        ),
    );
    for (ties, name, why) in [
        (
            Ties::Ring,
            "positions-first-terrain-ties-ring",
            "record order 1 in every level, its cocircular wing choices by ring position (a 3.7 stream)",
        ),
        (
            Ties::Rising,
            "positions-first-terrain-ties-rising",
            "record order 2 in every level (3.8): of cocircular wing choices, those whose new edges would run along the falling diagonal last; the terrain's cells are split along the rising one",
        ),
        (
            Ties::Falling,
            "positions-first-terrain-ties-falling",
            "record order 3 in every level (3.8): of cocircular wing choices, those whose new edges would run along the rising diagonal last, against the terrain's own cells",
        ),
    ] {
        s.valid(
            name,
            &format!(
                "33x33 fractal terrain read positions first, rANS, the tie rule forced: {why}."
            ),
            &["encoded", "terrain", "rans", "positions-first", "ties"],
            encoded(
                &terrain(),
                positions_first(EncodeOptions {
                    codec: ChunkCodec::RansAlways { lanes: 4 },
                    schedule: Schedule::EveryVertex,
                    ties: Some(ties),
                    ..opts()
                }),
            ),
        );
    }
    s.valid(
        "positions-first-height-outside-fan",
        "Hand-made: a boundary vertex R at (10, 10) whose fan covers the square up to (14, 14) (two wedges, a quarter turn) splits read positions first, kind 1: C at R + (1, 1), P at R − (1, 1), outside every wedge's cone. The height prediction of the edge vector takes the surface at both ends; at P there is none, so h = 0 and z is the residual alone (SPEC §7.4 `read_record_pf`: `if h is none: h = 0`), though the fan is not flat.",
        &["handmade", "positions-first", "boundary", "ghost-wing"],
        height_outside_fan(),
    );
    s.valid(
        "positions-first-p-on-ring-entry",
        "Hand-made: a boundary vertex R at (10, 10) whose fan turns three quarters, from R + (1, -2) through R + (3, 0) and R + (0, 2) to q4 = R + (-1, 0), splits read positions first, kind 1 with C at R + (1, 0) and t = 0: P lands on q4 in x and y (not in z). The wings are the ghost and the first entry, so P's arc has no wedge and q4's two wedges (one of them the ghost's) go to C, and the pair holds (SPEC §7.4 `pair`, and the note after `incircle`: P on a ring entry). No encoder-made vector holds such a record.",
        &["handmade", "positions-first", "boundary", "ghost-wing"],
        p_on_ring_entry(),
    );
    s.valid(
        "positions-first-all-escapes",
        "33x33 fractal terrain at 20 bits per axis, its x and y quantized over the bounding box instead of kept on the raster's lattice (whose cells would be about 2^15 steps wide): every fan's bounding box holds more than 1,024 lattice points, so every record of the positions-first levels is read wings first (an escape without a kind, SPEC §7.4).",
        &["encoded", "terrain", "rans", "positions-first", "escape"],
        encoded(
            &terrain(),
            positions_first(EncodeOptions {
                bits: 20,
                codec: ChunkCodec::RansAlways { lanes: 4 },
                schedule: Schedule::EveryVertex,
                // Kept on the lattice (the constrained default), x and y
                // would count the raster's cells, and most fans would hold
                // a few dozen points: only 7 of 1,073 records escaped so.
                lattice: Some(Lattice::Ignore),
                ..opts()
            }),
        ),
    );
}

/// The first stream made from `subject` by `mutate` on one of its levels
/// from level 1 on that fails with `class` (a record fault needs a level
/// whose first record is read positions first).
fn first_failing(
    subject: &[u8],
    class: &str,
    mutate: impl Fn(&mut Vec<Vec<u8>>) -> Option<()>,
) -> Vec<u8> {
    let parts = unframe(subject);
    (1..parts.levels.len())
        .find_map(|k| {
            let mut p = parts.clone();
            mutate(&mut p.levels[k].substreams)?;
            let bytes = reframe(&p);
            (builtin::decoder_core(&bytes).verdict == Verdict::Error(class.into())).then_some(bytes)
        })
        .unwrap_or_else(|| panic!("no level gives {class}"))
}

pub(super) fn positions_first_invalid(s: &mut Specs) {
    let subject = deflated_terrain();
    let record_at = |k: u16| plane_policy_at(&subject, k) + 3;
    assert!(
        (1..=3).contains(&subject[record_at(1)]),
        "level 1 is read positions first"
    );
    s.invalid(
        "record-order-4",
        "malformed",
        "Level 1's record order (level header byte 11) is 4, a reserved value (2 and 3 are the tie rules of 3.8; level header CRC recomputed).",
        &["positions-first", "level-header"],
        with_level_header_byte(&subject, 1, record_at(1), 4),
    );
    s.invalid(
        "positions-first-plane-off",
        "malformed",
        "Level 1 is read positions first under the plane policy off: positions-first needs the plane policy height (level header CRC recomputed).",
        &["positions-first", "level-header", "plane-policy"],
        with_level_header_byte(&subject, 1, plane_policy_at(&subject, 1), 0),
    );
    s.invalid(
        "positions-first-kind-3",
        "malformed",
        "A positions-first level whose first placement value is 3: a kind above 2 (SPEC §7.4).",
        &["positions-first", "records"],
        first_failing(&subject, "malformed", |subs| {
            *subs[6].first_mut()? = 3;
            Some(())
        }),
    );
    s.invalid(
        "positions-first-offset-4",
        "malformed",
        "A positions-first level's first midpoint offset t (a kind-1 record's second placement value) set to 4: t is 0 to 3 (SPEC §7.4). Found as the first placement value where 3 reads on and 4 fails.",
        &["positions-first", "records"],
        midpoint_offset_4(&subject),
    );
    // The record faults below go to the first record of a level that is
    // read positions first with a kind 0 or 1: a level whose first record
    // escapes would meet them in the wings-first reading instead.
    let (named, parts) = (first_named_level(&subject), unframe(&subject));
    let in_named = |slot: usize, edit: &dyn Fn(&mut Vec<u8>)| {
        let mut p = parts.clone();
        edit(&mut p.levels[named as usize].substreams[slot]);
        reframe(&p)
    };
    s.invalid(
        "positions-first-rank-past-free-points",
        "position-out-of-range",
        "A positions-first level whose first record (of kind 0 or 1) names lattice rank 255: a fan has at most 255 free points (SPEC §7.4: j >= len(F)).",
        &["positions-first", "records"],
        in_named(5, &|edge| {
            // The first value is a one-byte varint; 255 takes two.
            assert!(edge[0] < 0x80);
            edge.splice(0..1, [0xFF, 0x01]);
        }),
    );
    s.invalid(
        "positions-first-wing-past-choices",
        "ring-offset-out-of-range",
        "A positions-first level whose first record (of kind 0 or 1) has wing rank u = 200: more than the pairs that keep the new triangles counter-clockwise (SPEC §7.4: u >= len(xs)).",
        &["positions-first", "records", "ring-offset"],
        in_named(1, &|offsets| offsets[0] = 200),
    );
    s.invalid(
        "positions-first-second-wing-past-choices",
        "ring-offset-out-of-range",
        "A positions-first level whose first record (of kind 0 or 1) has second wing rank v = 200: more than the wings that pair with its first (SPEC §7.4: v >= len(ys)).",
        &["positions-first", "records", "ring-offset"],
        in_named(2, &|distances| distances[0] = 200),
    );
}

/// `subject` with its first midpoint offset (SPEC §7.4 `t`) set to 4. The
/// placement substream interleaves kinds (0 to 2), offsets (0 to 3) and
/// escaped records' placement codes (0 to 2); only at an offset does 3
/// read on while 4 fails.
fn midpoint_offset_4(subject: &[u8]) -> Vec<u8> {
    let parts = unframe(subject);
    let invalid_placement = |b: &[u8]| {
        matches!(
            decode_all(b, false),
            Err(splitstream_decoder_core::Error::InvalidPlacement)
        )
    };
    for k in 1..parts.levels.len() {
        for i in 0..parts.levels[k].substreams[6].len() {
            let with = |v: u8| {
                let mut p = parts.clone();
                p.levels[k].substreams[6][i] = v;
                reframe(&p)
            };
            let four = with(4);
            if invalid_placement(&four) && !invalid_placement(&with(3)) {
                return four;
            }
        }
    }
    panic!("no midpoint offset in the positions-first levels")
}

/// The first level from 1 on whose first record is read positions first
/// with a kind of 0 or 1 (SPEC §7.4): its fan has free points and its
/// first placement value, the kind, is below 2.
fn first_named_level(subject: &[u8]) -> u16 {
    #[derive(Default)]
    struct FirstRecord {
        has_free_points: Option<bool>,
        pf: splitstream_decoder_core::positions_first::PositionsFirst,
    }
    impl splitstream_decoder_core::SplitObserver for FirstRecord {
        fn record(
            &mut self,
            state: &splitstream_decoder_core::MeshState<'_>,
            r: u32,
            ring: &splitstream_decoder_core::Ring,
            _: &splitstream_decoder_core::SplitRecord,
        ) {
            if self.has_free_points.is_none() {
                let positions = state.positions();
                let free = self.pf.free_points(positions, positions[r as usize], ring);
                self.has_free_points = Some(free.is_some());
            }
        }
    }
    let parts = unframe(subject);
    let mut workspace =
        splitstream_decoder_core::owned::OwnedWorkspace::for_stream(subject).expect("valid");
    let mut decoder = workspace.decoder(subject).expect("valid");
    while let Some(k) = decoder.next_level() {
        let bytes = decoder.level_bytes(k, subject).expect("valid");
        let mut level = decoder.begin_level(k, bytes).expect("valid");
        let mut first = FirstRecord::default();
        while level
            .next_round_observed(&mut first)
            .expect("valid")
            .is_some()
        {}
        let named = parts.levels[k as usize].records == RecordOrder::PositionsFirst
            && first.has_free_points == Some(true)
            && parts.levels[k as usize].substreams[6]
                .first()
                .is_some_and(|&kind| kind < 2);
        if k >= 1 && named {
            return k;
        }
    }
    panic!("no level whose first record is named positions first")
}

/// The stream of the `positions-first-height-outside-fan` vector: a seed
/// of two triangles, (R, q1, q2) and (R, q2, q3), and one split of R read
/// positions first, kind 1: C = R + (1, 1), P = R − (1, 1), the ghost and
/// q1 the wings.
fn height_outside_fan() -> Vec<u8> {
    let stream = one_split_kind_1(&OneSplit {
        positions: &[[10, 10, 50], [14, 10, 60], [14, 14, 80], [10, 14, 70]],
        triangles: &[[0, 1, 2], [0, 2, 3]],
        n: [1, 1],
        t: 0,
        r_z: 6,
        wings: (0, 1),
    });
    let mesh = decode_all(&stream, false).expect("the split decodes");
    // P = R − (X >> 1) with X = (2, 2, r_z): h = 0 puts P at z 50 − 3.
    assert_eq!(mesh.positions[0], [9, 9, 47]);
    assert_eq!(mesh.positions[4], [11, 11, 53]);
    stream
}

/// The stream of the `positions-first-p-on-ring-entry` vector: R at
/// (10, 10) on a boundary, its fan (R, q1, q2), (R, q2, q3), (R, q3, q4)
/// turning from q1 = R + (1, −2) through R + (3, 0) and R + (0, 2) to
/// q4 = R + (−1, 0); kind 1 with C = R + (1, 0) and t = 0 puts P at
/// R + (−1, 0), on q4 in x and y. The ghost and q1 are the wings, so P
/// takes no wedge of the ring and C all three, q4's among them: the one
/// way a pair can hold when A falls on a ring entry (SPEC §7.4, the note
/// after `incircle`).
fn p_on_ring_entry() -> Vec<u8> {
    let q4 = [9, 10, 90];
    let stream = one_split_kind_1(&OneSplit {
        positions: &[[10, 10, 50], [11, 8, 55], [13, 10, 60], [10, 12, 65], q4],
        triangles: &[[0, 1, 2], [0, 2, 3], [0, 3, 4]],
        n: [1, 0],
        t: 0,
        r_z: -4,
        wings: (0, 1),
    });
    let mesh = decode_all(&stream, false).expect("the split decodes");
    let (p, c) = (mesh.positions[0], mesh.positions[5]);
    assert_eq!(&p[..2], &q4[..2], "P on q4 in x and y");
    assert_ne!(p[2], q4[2], "P and q4 apart in z");
    assert_eq!(&c[..2], &[11, 10]);
    // P keeps one triangle, the new one with C and q1; C takes R's three.
    let with = |v: u32| mesh.triangles.iter().filter(|t| t.contains(&v)).count();
    assert_eq!((with(0), with(5)), (1, 4));
    assert!(mesh.triangles.iter().any(|t| {
        let mut t = *t;
        let at = t.iter().position(|&v| v == 5).unwrap_or(0);
        t.rotate_left(at);
        t == [5, 0, 1]
    }));
    stream
}

/// A seed and one split of its vertex 0 read positions first, kind 1
/// (stored chunks, constrained mode, `every-vertex`): the new edge's
/// rank, the midpoint offset `t` and the wing ranks are found with
/// decoder-core's own positions-first lists on the seed's state.
struct OneSplit<'a> {
    positions: &'a [[u32; 3]],
    triangles: &'a [[u32; 3]],
    /// C − R in x and y; P = R − N + t.
    n: [i64; 2],
    /// The midpoint offset: bit 0 for x, bit 1 for y.
    t: u8,
    /// The z residual of the edge vector.
    r_z: i32,
    /// The wings' ring positions (x, y), x < y: P owns the arc from x to y.
    wings: (usize, usize),
}

fn one_split_kind_1(split: &OneSplit) -> Vec<u8> {
    use splitstream_decoder_core::positions_first::{NewEdge, PositionsFirst};
    use splitstream_decoder_core::writer::{
        LevelPayload, StreamParams, SubstreamWriter, write_stream,
    };
    use splitstream_decoder_core::{PlanePolicy, Ring, WingPolicy, handmade};

    let params = StreamParams {
        position_mode: PositionMode::Constrained,
        schedule: Schedule::EveryVertex,
        ..handmade::params(ChunkCodec::Stored)
    };
    let ghost_wing = split.wings.0 == 0;
    let build = |j: u32, u: u8, v: u8| {
        let mut subs = vec![SubstreamWriter::default(); 7];
        subs[0].bit(true); // R's flag; its neighbours' are inferred
        subs[6].byte(1); // kind 1: R sat on the floor midpoint
        subs[5].varint(j); // C's rank among the free points
        subs[6].byte(split.t);
        subs[1].byte(u);
        subs[2].byte(v);
        subs[5].signed(split.r_z);
        let level = LevelPayload {
            round_splits: vec![1],
            plane: PlanePolicy::Height,
            wings: WingPolicy::Ranks,
            deficits: DeficitContexts::Plain,
            records: RecordOrder::PositionsFirst,
            ties: Ties::Ring,
            substreams: subs,
            vertex_count: split.positions.len() as u32 + 1,
            // Two new triangles, one when a wing is the ghost.
            triangle_count: split.triangles.len() as u32 + if ghost_wing { 1 } else { 2 },
            geometric_error: 0.0,
        };
        write_stream(
            &params,
            &[handmade::base(split.positions, split.triangles, &[]), level],
        )
    };
    let draft = build(0, 0, 0);
    let mut workspace =
        splitstream_decoder_core::owned::OwnedWorkspace::for_stream(&draft).expect("valid");
    let mut decoder = workspace.decoder(&draft).expect("valid");
    let k = decoder.next_level().expect("level 0");
    let bytes = decoder.level_bytes(k, &draft).expect("level 0");
    let level = decoder.begin_level(k, bytes).expect("level 0");
    let state = level.state();
    let mut ring = Ring::default();
    state.ring(0, &mut ring).expect("R's ring");
    assert_eq!(
        ring.vertices()[1],
        1,
        "the ring starts at the ghost, then vertex 1"
    );
    let mut pf = PositionsFirst::default();
    pf.free_points(state.positions(), state.positions()[0], &ring)
        .expect("the fan has free points");
    let n = split.n;
    let j = pf.rank_of(n).expect("N is a free point") as u32;
    let edge = NewEdge {
        a: [
            -n[0] + i64::from(split.t & 1),
            -n[1] + i64::from(split.t >> 1),
        ],
        b: n,
        midpoint: true,
    };
    let (x, y) = split.wings;
    let xs = pf.order_xs(&state.wing_candidates(&ring), &edge);
    let u = pf.rank_of_choice(xs, x).expect("x pairs");
    let ys = pf.order_ys(&edge, x);
    let v = pf.rank_of_choice(ys, y).expect("y pairs with x");
    build(j, u as u8, v as u8)
}
