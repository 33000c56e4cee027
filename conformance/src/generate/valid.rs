//! The valid vectors: hand-made streams, encoder output under the format's
//! options, and a real mesh.

use splitstream_decoder_core::handmade;
use splitstream_decoder_core::writer::{ChunkCodec, StreamParams, write_stream};
use splitstream_decoder_core::{
    DeficitContexts, Header, PlanePolicy, PositionMode, Schedule, WingPolicy,
};
use splitstream_encoder::Mesh;
use splitstream_encoder::emit::EncodeOptions;
use splitstream_encoder::quantize::Lattice;
use std::path::Path;

use super::meshes;
use super::mutate::*;
use super::{Specs, deflate_opts, encoded, every_vertex, opts};

pub(super) fn valid_vectors(s: &mut Specs, real_data: &Path) -> Result<(), String> {
    // The smallest legal streams, built by hand.
    s.valid(
        "minimal-triangle",
        "A single triangle as the seed, level 0 only and no rounds: the smallest legal stream.",
        &["minimal", "handmade", "base-only"],
        handmade::single_triangle_stream(),
    );
    s.valid(
        "minimal-tetrahedron",
        "A tetrahedron whose vertices are all leaves as the seed, level 0 only and no rounds.",
        &["minimal", "handmade", "base-only"],
        write_stream(&handmade::stored(), &[handmade::tetrahedron_leaves()]),
    );
    s.valid(
        "handmade-tetra-split-stored",
        "SPEC Appendix A: a tetrahedron and one split of vertex 0; 4-byte stored chunks.",
        &["minimal", "handmade", "one-split"],
        handmade::tetra_stream(ChunkCodec::Stored),
    );
    s.valid(
        "handmade-tetra-split-deflate",
        "SPEC Appendix A with every chunk a deflate stream of one stored block (larger than its raw bytes).",
        &["minimal", "handmade", "one-split", "deflate-stored-block"],
        wrap_chunks_in_deflate(&handmade::tetra_stream(ChunkCodec::Stored)),
    );
    s.valid(
        "handmade-boundary-ghost-wing",
        "One triangle; a boundary vertex splits with the ghost vertex as one wing (adds one triangle).",
        &["minimal", "handmade", "one-split", "ghost-wing"],
        handmade::boundary_ghost_wing_stream(),
    );

    // Encoded meshes.
    let Shapes {
        sphere3,
        sphere2,
        holed,
        small_holed,
        cone,
    } = Shapes::new();
    let bumpy = meshes::checked(meshes::grid(30, 30, 2, None), "grid");
    let locked = meshes::checked(meshes::grid(16, 16, 3, None), "grid for lock_boundary");
    s.valid(
        "icosphere-optimal-deflate",
        "Icosphere (642 vertices, closed): optimal positions, deflate, 5 levels.",
        &["encoded"],
        encoded(&sphere3, deflate_opts()),
    );
    s.valid(
        "icosphere-constrained-stored",
        "Icosphere (162 vertices), constrained positions, stored chunks, 10 bits.",
        &["encoded"],
        encoded(
            &sphere2,
            EncodeOptions {
                position_mode: PositionMode::Constrained,
                codec: ChunkCodec::Stored,
                bits: 10,
                ..opts()
            },
        ),
    );
    s.valid(
        "grid-hole-optimal-deflate",
        "Height field with an outer boundary and a rectangular hole, optimal positions, deflate.",
        &["encoded", "hole"],
        encoded(&holed, deflate_opts()),
    );
    s.valid(
        "grid-hole-constrained-tiny-chunks",
        "Small height field with a hole, constrained positions, 7-byte stored chunks: every substream spans many chunks and values straddle chunk boundaries.",
        &["encoded", "hole", "tiny-chunks"],
        encoded(
            &small_holed,
            EncodeOptions {
                position_mode: PositionMode::Constrained,
                codec: ChunkCodec::Stored,
                chunk_limit: 7,
                rans_chunk_limit: 7,
                ..opts()
            },
        ),
    );
    s.valid(
        "icosphere-tiny-chunks-deflate",
        "Icosphere (162 vertices), 24-byte chunks, deflate where it helps: stored and deflate chunks mixed within substreams.",
        &["encoded", "tiny-chunks", "mixed-codecs"],
        encoded(
            &sphere2,
            EncodeOptions {
                chunk_limit: 24,
                rans_chunk_limit: 24,
                ..deflate_opts()
            },
        ),
    );
    for (levels, mesh, what) in [
        (1, &sphere2, "icosphere"),
        (2, &sphere2, "icosphere"),
        (8, &bumpy, "grid"),
    ] {
        s.valid(
            &format!("{what}-levels-{levels}"),
            &format!("{what} encoded with levels = {levels}."),
            &["encoded"],
            encoded(mesh, EncodeOptions { levels, ..opts() }),
        );
    }
    s.valid(
        "grid-deflate-stored-blocks",
        "The small height field with a hole, 64-byte chunks, every chunk re-coded as a deflate stream of one stored block.",
        &["encoded", "hole", "deflate-stored-block"],
        wrap_chunks_in_deflate(&encoded(
            &small_holed,
            EncodeOptions {
                codec: ChunkCodec::Stored,
                chunk_limit: 64,
                rans_chunk_limit: 64,
                ..opts()
            },
        )),
    );
    s.valid(
        "cone-high-valence",
        "Closed cone whose apex and bottom centre have valence 96 (rings of 96 vertices).",
        &["encoded", "high-valence"],
        encoded(&cone, opts()),
    );
    s.valid(
        "grid-lock-boundary",
        "Height field encoded with lock_boundary (boundary vertices stay in the base mesh), 4 levels, 20 bits.",
        &["encoded", "lock-boundary"],
        encoded(
            &locked,
            EncodeOptions {
                lock_boundary: true,
                levels: 4,
                bits: 20,
                ..opts()
            },
        ),
    );
    let terrain = meshes::checked(
        splitstream_encoder::input::fractal_terrain(33, 7),
        "terrain",
    );
    s.valid(
        "terrain-constrained-deflate",
        "33x33 fractal terrain (the demo's generator), constrained positions, deflate, 6 levels; x and y quantized on the raster's own lattice (one step a cell).",
        &["encoded", "terrain"],
        encoded(
            &terrain,
            EncodeOptions {
                position_mode: PositionMode::Constrained,
                levels: 6,
                ..deflate_opts()
            },
        ),
    );
    s.valid(
        "stepped-terrain-placement-ties",
        "40x40 height field of whole-unit heights 0..3, constrained positions (every axis on its lattice), every substream rANS-coded: the placement context meets its ties 10t = -5u, u and 5u (SPEC §7.4).",
        &["encoded", "terrain", "rans", "position-constrained", "placement-ties"],
        encoded(
            &meshes::checked(meshes::stepped_grid(40, 40, 1), "stepped grid"),
            EncodeOptions {
                position_mode: PositionMode::Constrained,
                codec: ChunkCodec::RansAlways { lanes: 4 },
                ..opts()
            },
        ),
    );
    s.valid(
        "icosphere-rans",
        "Icosphere (642 vertices), default encoder options: optimal positions, rANS with 4 lanes (deflate where smaller), 5 levels.",
        &["encoded", "rans"],
        encoded(&sphere3, opts()),
    );
    s.valid(
        "grid-hole-rans-always-1-lane",
        "Height field with a hole, every substream rANS-coded in a single lane.",
        &["encoded", "hole", "rans", "rans-1-lane"],
        encoded(
            &holed,
            EncodeOptions {
                codec: ChunkCodec::RansAlways { lanes: 1 },
                ..opts()
            },
        ),
    );
    s.valid(
        "terrain-constrained-rans-32-lanes",
        "33x33 fractal terrain, constrained positions, every substream rANS-coded with 32 lanes (more lanes than values in small chunks: empty lanes).",
        &["encoded", "terrain", "rans", "rans-empty-lanes"],
        encoded(
            &terrain,
            EncodeOptions {
                position_mode: PositionMode::Constrained,
                codec: ChunkCodec::RansAlways { lanes: 32 },
                levels: 6,
                ..opts()
            },
        ),
    );
    s.valid(
        "icosphere-rans-tiny-chunks",
        "Icosphere (162 vertices), every substream rANS-coded in chunks of at most 5 values and 3 lanes: each chunk has its own tables and lanes.",
        &["encoded", "rans", "tiny-chunks"],
        encoded(
            &sphere2,
            EncodeOptions {
                codec: ChunkCodec::RansAlways { lanes: 3 },
                chunk_limit: 5,
                rans_chunk_limit: 5,
                ..opts()
            },
        ),
    );
    // Format 3.4: `max_chunk_len` bounds byte-codec chunks only. With every
    // substream rANS-coded there is no byte-codec chunk, the header says 1,
    // and every rANS chunk codes more values than that (SPEC §5.2).
    s.valid(
        "icosphere4-rans-chunks-above-max-chunk-len",
        "Icosphere (2,562 vertices), every substream rANS-coded in chunks of up to 16,384 values, no byte-codec chunk: max_chunk_len is 1, and the finest level's edge substream codes more values than RANS_SLOT_BYTES (format 3.4; a rANS chunk needs no buffer of its length).",
        &["encoded", "rans"],
        {
            let sphere4 = meshes::checked(meshes::icosphere(4), "icosphere(4)");
            let stream = encoded(
                &sphere4,
                EncodeOptions {
                    codec: ChunkCodec::RansAlways { lanes: 4 },
                    chunk_limit: 1,
                    // Static tables: no 3.9 feature, so the stream is 3.4's.
                    adaptive_tables: false,
                    ..opts()
                },
            );
            let header = Header::parse(&stream).expect("valid");
            assert_eq!((header.max_chunk_len, header.version_minor), (1, 4));
            stream
        },
    );
    // The reference encoder cuts each substream into rANS chunks where
    // their own tables pay (SPEC §5.2: chunk boundaries carry no meaning;
    // §11): chunks of one substream of different lengths.
    s.valid(
        "grid160-rans-chunks-uneven",
        "Height field of 160 x 160 samples (25,600 vertices), the encoder's defaults (constrained positions, rANS): a substream's rANS chunks are cut at different lengths (multiples of 4,096 values, SPEC §11), as the reference encoder cuts long substreams.",
        &["encoded", "rans", "rans-chunks-uneven"],
        {
            let grid = meshes::checked(meshes::grid(160, 160, 3, None), "grid(160)");
            encoded(&grid, EncodeOptions::default())
        },
    );
    s.valid(
        "handmade-tetra-split-rans",
        "SPEC Appendix A's split with every substream rANS-coded (1 lane).",
        &["minimal", "handmade", "one-split", "rans"],
        handmade::tetra_stream(ChunkCodec::RansAlways { lanes: 1 }),
    );
    s.valid(
        "handmade-tetra-split-rans-adaptive",
        "SPEC Appendix A's split rANS-coded (1 lane) with adaptive tables where the writer finds them smaller (3.9): the flag, the wing ranks and the split valences, each value a token of a two-token table whose one decision starts at one half.",
        &["minimal", "handmade", "one-split", "rans", "rans-adaptive"],
        handmade::tetra_stream_under(&StreamParams {
            adaptive_tables: true,
            ..handmade::params(ChunkCodec::RansAlways { lanes: 1 })
        }),
    );
    // Every plane policy byte (SPEC §5.1, §7.4), forced for every level.
    for (i, policy) in PlanePolicy::ALL.into_iter().enumerate() {
        let (mode, what) = if i % 2 == 0 {
            (PositionMode::Constrained, "constrained")
        } else {
            (PositionMode::Optimal, "optimal")
        };
        for (mesh, name) in [(&sphere2, "icosphere"), (&small_holed, "grid-hole")] {
            s.valid(
                &format!("plane-{}-{name}", policy.name()),
                &format!(
                    "{name} ({what} positions, stored chunks) with plane policy `{}` (byte {}) in every level.",
                    policy.name(),
                    policy.to_byte()
                ),
                &["encoded", "plane-policy"],
                encoded(
                    mesh,
                    EncodeOptions {
                        position_mode: mode,
                        codec: ChunkCodec::Stored,
                        plane: Some(policy),
                        ..opts()
                    },
                ),
            );
        }
    }
    // Every wing policy byte (SPEC §5.1, §7.4; near and near-xy are 3.2),
    // forced for every level, in both position modes.
    let small = [(&sphere2, "icosphere"), (&small_holed, "grid-hole")];
    for policy in WingPolicy::ALL {
        let choice = Forced {
            id: "wings",
            field: "wing policy",
            name: policy.name(),
            byte: policy.to_byte(),
            feature: "wing-policy",
        };
        forced_in_every_level(s, &small, choice, |mode| EncodeOptions {
            position_mode: mode,
            wings: Some(policy),
            ..opts()
        });
    }
    // Both deficit contexts (SPEC §5.1, §5.5.5; valence is 3.3), forced for
    // every level, in both position modes, with the rANS codec (the
    // contexts, and the number of tables, only matter to it).
    let split_valences = DeficitContexts::ALL
        .into_iter()
        .filter(|c| c.allowed_under(Schedule::SplitValences));
    for contexts in split_valences {
        let choice = Forced {
            id: "deficits",
            field: "deficit contexts",
            name: contexts.name(),
            byte: contexts.to_byte(),
            feature: "deficit-contexts",
        };
        forced_in_every_level(s, &small, choice, |mode| EncodeOptions {
            position_mode: mode,
            deficits: Some(contexts),
            ..opts()
        });
    }
    // 31 bits per axis: the arithmetic of SPEC §7.4 at its widest (the
    // seed's rounds span the whole grid).
    for (mode, what) in [
        (PositionMode::Optimal, "optimal"),
        (PositionMode::Constrained, "constrained"),
    ] {
        // rANS on the whole 31-bit grid (every axis, a raster's too), with
        // the plane policy `plane` or, without one, chosen per level.
        let wide_rans = |plane: Option<PlanePolicy>| EncodeOptions {
            position_mode: mode,
            bits: 31,
            codec: ChunkCodec::RansAlways { lanes: 2 },
            plane,
            lattice: Some(Lattice::Ignore),
            ..opts()
        };
        for (mesh, name) in [(&sphere3, "icosphere"), (&terrain, "terrain")] {
            s.valid(
                &format!("bits-31-{name}-{what}"),
                &format!(
                    "{name}, {what} positions, 31 bits per axis (the largest grid), rANS, plane policy chosen per level."
                ),
                &["encoded", "bits-31", "rans"],
                encoded(mesh, wide_rans(None)),
            );
        }
        s.valid(
            &format!("bits-31-icosphere-{what}-x"),
            &format!(
                "Icosphere (162 vertices), {what} positions, 31 bits per axis, plane policy `x` in every level: residuals and plane offsets wrap modulo 2^32 (SPEC §7.4)."
            ),
            &["encoded", "bits-31", "plane-policy", "wrapped-residuals"],
            encoded(
                &sphere2,
                EncodeOptions {
                    position_mode: mode,
                    bits: 31,
                    codec: ChunkCodec::Stored,
                    plane: Some(PlanePolicy::Axis(0)),
                    ..opts()
                },
            ),
        );
        s.valid(
            &format!("bits-31-icosphere-{what}-off"),
            &format!(
                "Icosphere (162 vertices), {what} positions, 31 bits per axis, plane policy `off` (no plane offsets: the residuals are read x, y, z)."
            ),
            &["encoded", "bits-31", "plane-policy"],
            encoded(
                &sphere2,
                EncodeOptions {
                    position_mode: mode,
                    bits: 31,
                    codec: ChunkCodec::Stored,
                    plane: Some(PlanePolicy::Off),
                    ..opts()
                },
            ),
        );
        // Format 3.1's height prediction at its widest: 128-bit surface
        // arithmetic, points far outside thin wedges, folded fans (the
        // sphere) where no wedge holds the point.
        for (mesh, name) in [(&terrain, "terrain"), (&sphere2, "icosphere")] {
            s.valid(
                &format!("bits-31-{name}-{what}-height"),
                &format!(
                    "{name}, {what} positions, 31 bits per axis, plane policy `height` (3.1) in every level: z predicted from the surface of R's fan, modulo 2^32 (SPEC §7.4)."
                ),
                &["encoded", "bits-31", "plane-policy", "height", "wrapped-residuals"],
                encoded(mesh, wide_rans(Some(PlanePolicy::Height))),
            );
        }
        s.valid(
            &format!("grid-hole-{what}-height"),
            &format!(
                "Small height field with a hole, {what} positions, plane policy `height` (3.1) in every level: boundary fans whose open side holds no wedge keep the linear prediction."
            ),
            &["encoded", "plane-policy", "height", "boundary"],
            encoded(
                &small_holed,
                EncodeOptions {
                    position_mode: mode,
                    codec: ChunkCodec::Stored,
                    plane: Some(PlanePolicy::Height),
                    ..opts()
                },
            ),
        );
        s.valid(
            &format!("bits-31-grid-hole-{what}-dominant"),
            &format!(
                "Small height field with a hole, {what} positions, 31 bits per axis, plane policy `dominant` in every level."
            ),
            &["encoded", "bits-31", "plane-policy"],
            encoded(
                &small_holed,
                EncodeOptions {
                    position_mode: mode,
                    bits: 31,
                    codec: ChunkCodec::Stored,
                    plane: Some(PlanePolicy::Dominant),
                    lattice: Some(Lattice::Ignore),
                    ..opts()
                },
            ),
        );
    }
    let bunny = meshes::real(real_data, "bunny.ply")?;
    s.valid(
        "bunny-npm",
        "The npm `bunny` package's Stanford bunny (encoder/data/fetch.sh), default encoder options.",
        &["encoded", "real-mesh"],
        encoded(&bunny, opts()),
    );
    let shapes = Shapes {
        sphere3,
        sphere2,
        holed,
        small_holed,
        cone,
    };
    every_vertex_vectors(s, &bunny, &shapes);
    super::positions_first::positions_first_valid(s);
    Ok(())
}

/// The synthetic meshes that the split-valences vectors and the
/// every-vertex ones both encode.
struct Shapes {
    /// Icosphere of 642 vertices.
    sphere3: Mesh,
    /// Icosphere of 162 vertices.
    sphere2: Mesh,
    /// Height field with an outer boundary and a rectangular hole.
    holed: Mesh,
    /// A smaller one, with a hole too.
    small_holed: Mesh,
    /// Cone of 96 sides: an apex of high valence.
    cone: Mesh,
}

impl Shapes {
    fn new() -> Shapes {
        Shapes {
            sphere3: meshes::checked(meshes::icosphere(3), "icosphere(3)"),
            sphere2: meshes::checked(meshes::icosphere(2), "icosphere(2)"),
            holed: meshes::checked(
                meshes::grid(24, 20, 1, Some([8, 15, 6, 12])),
                "grid with hole",
            ),
            small_holed: meshes::checked(
                meshes::grid(14, 12, 4, Some([4, 9, 4, 8])),
                "small grid with hole",
            ),
            cone: meshes::checked(meshes::cone(96, 4), "cone"),
        }
    }
}

/// The schedule `every-vertex` (SPEC §3.2, §6.2, §7.3–§7.5, format 3.6):
/// the encoder's current defaults, and the options the vectors above vary
/// for split valences (position modes, codecs, chunks, lanes, boundaries,
/// wing and plane policies, levels).
fn every_vertex_vectors(s: &mut Specs, bunny: &Mesh, shapes: &Shapes) {
    let Shapes {
        sphere3,
        sphere2,
        holed,
        small_holed,
        cone,
    } = shapes;
    let tag = "schedule-every-vertex";
    s.valid(
        "every-vertex-bunny-npm",
        "The npm `bunny` package's Stanford bunny with the encoder's defaults: constrained positions, rANS, the schedule every-vertex (a flag for every vertex in contexts by its valence, and from format 3.10 by whether it has split in the level; no split valences; format 3.6).",
        &["encoded", "real-mesh", tag],
        encoded(bunny, EncodeOptions::default()),
    );
    s.valid(
        "every-vertex-icosphere-optimal-deflate",
        "Icosphere (642 vertices, closed): optimal positions, deflate, the schedule every-vertex.",
        &["encoded", tag],
        encoded(sphere3, every_vertex(deflate_opts())),
    );
    s.valid(
        "every-vertex-icosphere-constrained-stored",
        "Icosphere (162 vertices), constrained positions, stored chunks, 10 bits, the schedule every-vertex.",
        &["encoded", tag],
        encoded(
            sphere2,
            every_vertex(EncodeOptions {
                position_mode: PositionMode::Constrained,
                codec: ChunkCodec::Stored,
                bits: 10,
                ..opts()
            }),
        ),
    );
    s.valid(
        "every-vertex-grid-hole-optimal-rans",
        "Height field with an outer boundary and a rectangular hole (ghost wings, boundary valences), optimal positions, rANS, the schedule every-vertex.",
        &["encoded", "hole", tag],
        encoded(holed, every_vertex(opts())),
    );
    s.valid(
        "every-vertex-grid-hole-tiny-chunks",
        "Small height field with a hole, constrained positions, 7-byte stored chunks (flag bits straddle chunks), the schedule every-vertex.",
        &["encoded", "hole", "tiny-chunks", tag],
        encoded(
            small_holed,
            every_vertex(EncodeOptions {
                position_mode: PositionMode::Constrained,
                codec: ChunkCodec::Stored,
                chunk_limit: 7,
                rans_chunk_limit: 7,
                ..opts()
            }),
        ),
    );
    s.valid(
        "every-vertex-cone-rans-1-lane",
        "Cone of 96 sides (an apex of valence 97 and above: the flag context of the largest valences), rANS in 1 lane with 64-value chunks, the schedule every-vertex.",
        &["encoded", "rans", tag],
        encoded(
            cone,
            every_vertex(EncodeOptions {
                codec: ChunkCodec::RansAlways { lanes: 1 },
                rans_chunk_limit: 64,
                ..opts()
            }),
        ),
    );
    s.valid(
        "every-vertex-icosphere-rans-32-lanes-levels-8",
        "Icosphere (642 vertices), rANS in 32 lanes, 8 levels, the schedule every-vertex.",
        &["encoded", "rans", tag],
        encoded(
            sphere3,
            every_vertex(EncodeOptions {
                codec: ChunkCodec::RansAlways { lanes: 32 },
                levels: 8,
                ..opts()
            }),
        ),
    );
    // Both flag contexts (SPEC §5.1, §5.5.5; split-history is 3.10),
    // forced in every level, in both position modes: the flags by valence,
    // or by valence and the split-history bit (SPEC §6.1).
    for (contexts, name) in [
        (DeficitContexts::Plain, "valence"),
        (DeficitContexts::SplitHistory, "split-history"),
    ] {
        let choice = Forced {
            id: "every-vertex-flags",
            field: "the flag contexts",
            name,
            byte: contexts.to_byte(),
            feature: "flag-contexts",
        };
        forced_in_every_level(
            s,
            &[(sphere3, "icosphere"), (small_holed, "grid-hole")],
            choice,
            |mode| {
                every_vertex(EncodeOptions {
                    position_mode: mode,
                    deficits: Some(contexts),
                    ..opts()
                })
            },
        );
    }
    // Every wing policy under every-vertex, where every ring entry may be
    // a wing (SPEC §7.4): the ranks count the whole ring.
    for policy in WingPolicy::ALL {
        for (mode, what) in [
            (PositionMode::Constrained, "constrained"),
            (PositionMode::Optimal, "optimal"),
        ] {
            s.valid(
                &format!("every-vertex-wings-{}-grid-hole-{what}", policy.name()),
                &format!(
                    "Small height field with a hole ({what} positions, rANS) with wing policy `{}` in every level, the schedule every-vertex: wing ranks among every ring entry.",
                    policy.name()
                ),
                &["encoded", "wing-policy", tag],
                encoded(
                    small_holed,
                    every_vertex(EncodeOptions {
                        position_mode: mode,
                        wings: Some(policy),
                        ..opts()
                    }),
                ),
            );
        }
    }
}

/// A level-header choice forced in every level of a vector (SPEC §5.1):
/// `{id}-{name}-{mesh}-{mode}` names the vector, `field` and `byte` describe it.
struct Forced {
    id: &'static str,
    field: &'static str,
    name: &'static str,
    byte: u8,
    feature: &'static str,
}

/// One rANS vector per mesh of `meshes` and position mode with `choice`
/// forced in every level, encoded with `options(mode)`.
fn forced_in_every_level(
    s: &mut Specs,
    meshes: &[(&Mesh, &str)],
    choice: Forced,
    options: impl Fn(PositionMode) -> EncodeOptions,
) {
    for (mode, what) in [
        (PositionMode::Constrained, "constrained"),
        (PositionMode::Optimal, "optimal"),
    ] {
        for &(mesh, name) in meshes {
            s.valid(
                &format!("{}-{}-{name}-{what}", choice.id, choice.name),
                &format!(
                    "{name} ({what} positions, rANS) with {} `{}` (byte {}) in every level.",
                    choice.field, choice.name, choice.byte
                ),
                &["encoded", choice.feature],
                encoded(mesh, options(mode)),
            );
        }
    }
}
