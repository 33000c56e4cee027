//! The vector generator: every vector of `vectors/<version>/` and its
//! manifest entry come from here, deterministically (same bytes on every
//! run and machine). Run it with `conformance/generate.sh`.

mod meshes;
mod mutate;

use std::collections::BTreeMap;
use std::path::Path;

use splitstream_decoder_core::handmade;
use splitstream_decoder_core::limits::{LEAF, codec};
use splitstream_decoder_core::owned::{OwnedWorkspace, decode_all};
use splitstream_decoder_core::writer::{ChunkCodec, write_stream};
use splitstream_decoder_core::{
    DeficitContexts, Fnv1a, Header, LevelHeader, LevelTable, PlanePolicy, PositionMode, WingPolicy,
    head_len,
};
use splitstream_encoder::Mesh;
use splitstream_encoder::emit::{EncodeOptions, encode};
use splitstream_encoder::quantize::Lattice;

use crate::builtin;
use crate::manifest::{FinalMesh, Manifest, SUITE_VERSION, Vector, hex};
use crate::protocol::Verdict;
use handmade::{Rec, base, level, tetra_split, tetra_split_level};
use mutate::*;

/// The generated set: the manifest and each file's bytes (paths relative
/// to the set's directory).
pub struct Generated {
    pub manifest: Manifest,
    pub files: BTreeMap<String, Vec<u8>>,
}

/// One vector before its expectations are computed.
struct Spec {
    name: String,
    description: String,
    features: Vec<String>,
    stream: Vec<u8>,
    /// `None`: valid.
    error_class: Option<&'static str>,
}

struct Specs(Vec<Spec>);

impl Specs {
    fn valid(&mut self, name: &str, description: &str, features: &[&str], stream: Vec<u8>) {
        self.push(name, description, features, stream, None);
    }

    fn invalid(
        &mut self,
        name: &str,
        class: &'static str,
        description: &str,
        features: &[&str],
        stream: Vec<u8>,
    ) {
        self.push(name, description, features, stream, Some(class));
    }

    fn push(
        &mut self,
        name: &str,
        description: &str,
        features: &[&str],
        stream: Vec<u8>,
        error_class: Option<&'static str>,
    ) {
        assert!(
            self.0.iter().all(|s| s.name != name),
            "duplicate vector {name}"
        );
        self.0.push(Spec {
            name: name.to_string(),
            description: description.to_string(),
            features: features.iter().map(|s| s.to_string()).collect(),
            stream,
            error_class,
        });
    }
}

fn encoded(mesh: &Mesh, options: EncodeOptions) -> Vec<u8> {
    encode(mesh, &options, |_| {})
        .unwrap_or_else(|e| panic!("generator: encoding failed: {e}"))
        .stream
}

/// The encoder's defaults in optimal mode, the encoder's default when the
/// vectors were first written (constrained mode since 2026-12-03): the
/// vectors named `position-constrained` ask for it.
fn opts() -> EncodeOptions {
    EncodeOptions {
        position_mode: PositionMode::Optimal,
        ..EncodeOptions::default()
    }
}

/// [`opts`] with deflate instead of rANS.
fn deflate_opts() -> EncodeOptions {
    EncodeOptions {
        codec: ChunkCodec::Deflate(9),
        ..opts()
    }
}

/// Generates the whole set. `real_data` is `encoder/data/real` (filled by
/// `encoder/data/fetch.sh`).
pub fn generate(real_data: &Path) -> Result<Generated, String> {
    let mut specs = Specs(Vec::new());
    valid_vectors(&mut specs, real_data)?;
    invalid_vectors(&mut specs);
    let mut files = BTreeMap::new();
    let mut vectors = Vec::new();
    for spec in specs.0 {
        let dir = if spec.error_class.is_none() {
            "valid"
        } else {
            "invalid"
        };
        let file = format!("{dir}/{}.sps", spec.name);
        vectors.push(describe(&spec, &file));
        files.insert(file, spec.stream);
    }
    let manifest = Manifest {
        format_version: SUITE_VERSION.to_string(),
        generator: "conformance/generate.sh (splitstream-conformance generate); never edit by hand"
            .to_string(),
        protocol: "conformance/README.md".to_string(),
        vectors,
    };
    files.insert("manifest.json".to_string(), manifest.to_json().into_bytes());
    Ok(Generated { manifest, files })
}

/// Writes the set into `dir`, removing stream files that are not part of it.
pub fn write(generated: &Generated, dir: &Path) -> Result<(), String> {
    let err = |p: &Path, e: std::io::Error| format!("{}: {e}", p.display());
    for sub in ["valid", "invalid"] {
        let d = dir.join(sub);
        std::fs::create_dir_all(&d).map_err(|e| err(&d, e))?;
        for entry in std::fs::read_dir(&d).map_err(|e| err(&d, e))? {
            let path = entry.map_err(|e| err(&d, e))?.path();
            let rel = format!(
                "{sub}/{}",
                path.file_name().unwrap_or_default().to_string_lossy()
            );
            if !generated.files.contains_key(&rel) {
                std::fs::remove_file(&path).map_err(|e| err(&path, e))?;
            }
        }
    }
    for (rel, bytes) in &generated.files {
        let path = dir.join(rel);
        std::fs::write(&path, bytes).map_err(|e| err(&path, e))?;
    }
    Ok(())
}

/// Checks the reference decoder against the intended expectation and
/// builds the manifest entry.
fn describe(spec: &Spec, file: &str) -> Vector {
    let outcome = builtin::decoder_core(&spec.stream);
    let by_pieces = builtin::decode_by_pieces(&spec.stream, false);
    assert_eq!(
        outcome.verdict, by_pieces.verdict,
        "{}: decoder-core and its pieces disagree",
        spec.name
    );
    assert!(
        by_pieces.hashes.starts_with(&outcome.hashes),
        "{}: decoder-core's hashes are not a prefix of the pieces decoder's",
        spec.name
    );
    let mut features = spec.features.clone();
    let (round_hashes, result) = match spec.error_class {
        None => {
            assert_eq!(outcome.verdict, Verdict::Ok, "{}: not valid", spec.name);
            let mesh = decode_all(&spec.stream, true).expect("valid");
            assert_eq!(mesh.round_hashes, outcome.hashes, "{}", spec.name);
            let (result, tags) = final_mesh(&spec.stream);
            features.extend(tags);
            (mesh.round_hashes, Some(result))
        }
        Some(class) => {
            assert_eq!(
                outcome.verdict,
                Verdict::Error(class.to_string()),
                "{}: the reference decoder does not report the intended class",
                spec.name
            );
            // The hashes SPEC §10.3 reports before the fault.
            (by_pieces.hashes, None)
        }
    };
    features.sort();
    features.dedup();
    Vector {
        name: spec.name.clone(),
        file: file.to_string(),
        description: spec.description.clone(),
        features,
        bytes: spec.stream.len(),
        valid: spec.error_class.is_none(),
        error_class: spec.error_class.map(str::to_string),
        round_hashes: round_hashes.into_iter().map(hex).collect(),
        result,
    }
}

/// Decodes a valid stream round by round for the manifest's summary, and
/// derives feature tags from what the stream really contains.
fn final_mesh(stream: &[u8]) -> (FinalMesh, Vec<String>) {
    let header = Header::parse(stream).expect("valid");
    let table = LevelTable::parse(stream, &header).expect("valid");
    let mut tags = vec![
        match header.position_mode {
            PositionMode::Optimal => "position-optimal",
            PositionMode::Constrained => "position-constrained",
        }
        .to_string(),
        format!("levels-{}", header.level_count),
        format!("bits-{}", header.bits),
    ];
    for k in 0..header.level_count {
        let info = table.get(k);
        let bytes = &stream[info.offset as usize..(info.offset + info.length as u64) as usize];
        let lh = LevelHeader::parse(bytes, k == 0, header.max_chunk_len).expect("valid");
        if k == 0 && lh.round_count > 0 {
            tags.push("seed-rounds".to_string());
        }
        let mut per_substream = BTreeMap::new();
        for c in 0..lh.chunk_count {
            let e = lh.chunk(c).expect("valid");
            tags.push(
                match e.codec {
                    codec::STORED => "stored-chunks",
                    codec::DEFLATE => "deflate-chunks",
                    _ => "rans",
                }
                .to_string(),
            );
            // Format 3.4: a rANS chunk coding more values than the header's
            // max_chunk_len (SPEC §5.2).
            if e.codec == codec::RANS && e.raw_len > header.max_chunk_len {
                tags.push("rans-chunk-above-max".to_string());
            }
            *per_substream.entry(e.substream).or_insert(0) += 1;
        }
        if per_substream.values().any(|&n| n > 1) {
            tags.push("multi-chunk-substreams".to_string());
        }
    }
    let mut ws = OwnedWorkspace::for_stream(stream).expect("valid");
    let mut decoder = ws.decoder(stream).expect("valid");
    let mut max_vertex_triangles = 0;
    let mut rounds = 0;
    let mut track = |triangles: &[[u32; 3]], vertices: usize| {
        let mut count = vec![0usize; vertices];
        for t in triangles {
            for &v in t {
                count[v as usize] += 1;
            }
        }
        max_vertex_triangles = max_vertex_triangles.max(count.into_iter().max().unwrap_or(0));
    };
    while let Some(k) = decoder.next_level() {
        let range = decoder.level_range(k);
        let mut level = decoder
            .begin_level(k, &stream[range.start as usize..range.end as usize])
            .expect("valid");
        track(
            level.state().triangles(),
            level.state().vertex_count() as usize,
        );
        while level.next_round().expect("valid").is_some() {
            rounds += 1;
            track(
                level.state().triangles(),
                level.state().vertex_count() as usize,
            );
        }
    }
    let triangles = decoder.triangles();
    let mut directed: Vec<(u32, u32)> = triangles
        .iter()
        .flat_map(|t| [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])])
        .collect();
    directed.sort_unstable();
    let boundary_edges = directed
        .iter()
        .filter(|&&(a, b)| directed.binary_search(&(b, a)).is_err())
        .count();
    tags.push(
        if boundary_edges == 0 {
            "closed"
        } else {
            "boundary"
        }
        .to_string(),
    );
    if max_vertex_triangles >= 32 {
        tags.push("high-valence".to_string());
    }
    let mut geometry = Fnv1a::default();
    for p in decoder.positions() {
        for &x in p {
            geometry.u32(x);
        }
    }
    for t in triangles {
        for &v in t {
            geometry.u32(v);
        }
    }
    let result = FinalMesh {
        levels: decoder.levels_done(),
        rounds,
        vertices: decoder.positions().len(),
        triangles: triangles.len(),
        boundary_edges,
        max_vertex_triangles,
        state_hash: hex(decoder.state_hash()),
        geometry_hash: hex(geometry.finish()),
    };
    (result, tags)
}

fn valid_vectors(s: &mut Specs, real_data: &Path) -> Result<(), String> {
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
    let sphere3 = meshes::checked(meshes::icosphere(3), "icosphere(3)");
    let sphere2 = meshes::checked(meshes::icosphere(2), "icosphere(2)");
    let holed = meshes::checked(
        meshes::grid(24, 20, 1, Some([8, 15, 6, 12])),
        "grid with hole",
    );
    let small_holed = meshes::checked(
        meshes::grid(14, 12, 4, Some([4, 9, 4, 8])),
        "small grid with hole",
    );
    let bumpy = meshes::checked(meshes::grid(30, 30, 2, None), "grid");
    let locked = meshes::checked(meshes::grid(16, 16, 3, None), "grid for lock_boundary");
    let cone = meshes::checked(meshes::cone(96, 4), "cone");
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
                    ..opts()
                },
            );
            let header = Header::parse(&stream).expect("valid");
            assert_eq!((header.max_chunk_len, header.version_minor), (1, 4));
            stream
        },
    );
    s.valid(
        "handmade-tetra-split-rans",
        "SPEC Appendix A's split with every substream rANS-coded (1 lane).",
        &["minimal", "handmade", "one-split", "rans"],
        handmade::tetra_stream(ChunkCodec::RansAlways { lanes: 1 }),
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
    for policy in WingPolicy::ALL {
        for (mode, what) in [
            (PositionMode::Constrained, "constrained"),
            (PositionMode::Optimal, "optimal"),
        ] {
            for (mesh, name) in [(&sphere2, "icosphere"), (&small_holed, "grid-hole")] {
                s.valid(
                    &format!("wings-{}-{name}-{what}", policy.name()),
                    &format!(
                        "{name} ({what} positions, rANS) with wing policy `{}` (byte {}) in every level.",
                        policy.name(),
                        policy.to_byte()
                    ),
                    &["encoded", "wing-policy"],
                    encoded(
                        mesh,
                        EncodeOptions {
                            position_mode: mode,
                            wings: Some(policy),
                            ..opts()
                        },
                    ),
                );
            }
        }
    }
    // Both deficit contexts (SPEC §5.1, §5.5.5; valence is 3.3), forced for
    // every level, in both position modes, with the rANS codec (the
    // contexts, and the number of tables, only matter to it).
    for contexts in DeficitContexts::ALL {
        for (mode, what) in [
            (PositionMode::Constrained, "constrained"),
            (PositionMode::Optimal, "optimal"),
        ] {
            for (mesh, name) in [(&sphere2, "icosphere"), (&small_holed, "grid-hole")] {
                s.valid(
                    &format!("deficits-{}-{name}-{what}", contexts.name()),
                    &format!(
                        "{name} ({what} positions, rANS) with deficit contexts `{}` (byte {}) in every level.",
                        contexts.name(),
                        contexts.to_byte()
                    ),
                    &["encoded", "deficit-contexts"],
                    encoded(
                        mesh,
                        EncodeOptions {
                            position_mode: mode,
                            deficits: Some(contexts),
                            ..opts()
                        },
                    ),
                );
            }
        }
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
    Ok(())
}

fn flip(mut s: Vec<u8>, at: usize, mask: u8) -> Vec<u8> {
    s[at] ^= mask;
    s
}

fn invalid_vectors(s: &mut Specs) {
    let sphere = meshes::icosphere(3);
    let subject = encoded(&sphere, deflate_opts());
    let stored_subject = encoded(
        &meshes::icosphere(2),
        EncodeOptions {
            codec: ChunkCodec::Stored,
            ..opts()
        },
    );
    let constrained = encoded(
        &meshes::icosphere(2),
        EncodeOptions {
            position_mode: PositionMode::Constrained,
            codec: ChunkCodec::Stored,
            ..opts()
        },
    );
    let levels = Header::parse(&subject).expect("valid").level_count;
    let last = levels - 1;
    let head = head_len(levels);

    // Truncation at several depths.
    let cut = |n: usize| subject[..n].to_vec();
    let level0 = level_range(&subject, 0);
    let level2 = level_range(&subject, 2);
    for (name, at, what) in [
        ("truncated-signature", 5, "inside the 8-byte signature"),
        ("truncated-header", 60, "inside the 96-byte header"),
        ("truncated-level-table", head - 10, "inside the level table"),
        (
            "truncated-base-level",
            level0.start + level0.len() / 2,
            "in the middle of level 0",
        ),
        (
            "truncated-mid-level",
            level2.start + level2.len() / 2,
            "in the middle of level 2 (levels 0 and 1 decode first)",
        ),
        (
            "truncated-last-byte",
            subject.len() - 1,
            "one byte before the end",
        ),
    ] {
        s.invalid(
            name,
            "truncated",
            &format!("The icosphere stream cut {what}."),
            &["truncated"],
            cut(at),
        );
    }

    // Checksums.
    s.invalid(
        "checksum-header",
        "checksum-mismatch",
        "A bit of the header's origin flipped; the header CRC left as it was.",
        &["checksum"],
        flip(subject.clone(), 40, 0x01),
    );
    s.invalid(
        "checksum-level-table",
        "checksum-mismatch",
        "A bit of level 1's geometric error flipped in the level table; its CRC left as it was.",
        &["checksum"],
        flip(subject.clone(), table_entry(1) + 24, 0x01),
    );
    s.invalid(
        "checksum-level-header",
        "checksum-mismatch",
        "A bit of a split count of level 1 flipped; the level header CRC left as it was.",
        &["checksum"],
        flip(subject.clone(), split_count_at(&subject, 1, 0), 0x01),
    );
    let c = chunk_count(&subject, 2) - 1;
    let payload = chunk_payload(&subject, 2, c);
    s.invalid(
        "checksum-chunk",
        "checksum-mismatch",
        "A bit of the last chunk of level 2 flipped; its CRC left as it was (met when the chunk is loaded).",
        &["checksum"],
        flip(subject.clone(), payload.start + payload.len() / 2, 0x01),
    );

    // Signature and version.
    s.invalid(
        "bad-magic",
        "bad-magic",
        "The second signature byte changed from 'S' to 'X'.",
        &["header"],
        {
            let mut b = subject.clone();
            b[1] = b'X';
            b
        },
    );
    s.invalid(
        "unsupported-version",
        "unsupported-version",
        "Major version 2, the previous format (header CRC recomputed).",
        &["header", "versioning"],
        {
            let mut b = subject.clone();
            b[8] = 2;
            fix_header_crc(&mut b);
            b
        },
    );
    s.valid(
        "minor-version-1",
        "Minor version 1 of major 3 with every reserved field zero: decodes exactly as 3.0 (header CRC recomputed).",
        &["header", "versioning"],
        {
            let mut b = handmade::tetra_stream(ChunkCodec::Stored);
            b[9] = 1;
            fix_header_crc(&mut b);
            b
        },
    );

    s.valid(
        "trailing-bytes-ignored",
        "The icosphere stream followed by 16 bytes past the end of its last level, which decoders ignore (SPEC §10.3).",
        &["framing"],
        {
            let mut b = subject.clone();
            b.extend_from_slice(b"not splitstream!");
            b
        },
    );
    s.invalid(
        "seed-level-trailing-data",
        "count-mismatch",
        "A tetrahedron seed with no rounds, but one byte in level 0's flag substream: the seed's hash is reported, then the end of level 0 fails (SPEC §7.6).",
        &["handmade", "record-count", "seed"],
        {
            let mut p = unframe(&write_stream(
                &handmade::stored(),
                &[handmade::tetrahedron_leaves()],
            ));
            p.levels[0].substreams[0].push(0);
            reframe(&p)
        },
    );
    s.invalid(
        "round-count-mismatch",
        "count-mismatch",
        "Level-table entry 1 declares one round more than level 1's header (table CRC recomputed).",
        &["framing", "level-count"],
        {
            let mut b = subject.clone();
            let at = table_entry(1) + 20;
            let rounds = u32::from_le_bytes(b[at..at + 4].try_into().expect("4 bytes"));
            b[at..at + 4].copy_from_slice(&(rounds + 1).to_le_bytes());
            fix_table_crc(&mut b);
            b
        },
    );

    // Header capacities and the declared workspace.
    let patch_header = |f: &dyn Fn(&mut Header)| {
        let mut h = Header::parse(&subject).expect("valid");
        f(&mut h);
        let mut b = subject.clone();
        let mut out = [0u8; 96];
        h.write(&mut out);
        b[..96].copy_from_slice(&out);
        b
    };
    s.invalid(
        "capacity-vertices-lie",
        "capacity-exceeded",
        "Header vertex_capacity one less than the last level's vertex count (header CRC recomputed).",
        &["capacity"],
        patch_header(&|h| h.vertex_capacity -= 1),
    );
    s.invalid(
        "capacity-triangles-lie",
        "capacity-exceeded",
        "Header triangle_capacity one less than the last level's triangle count (header CRC recomputed).",
        &["capacity"],
        patch_header(&|h| h.triangle_capacity -= 1),
    );
    s.invalid(
        "workspace-bytes-wrong",
        "malformed",
        "Header workspace_bytes 8 more than SPEC §9 gives (header CRC recomputed).",
        &["capacity", "workspace"],
        patch_header(&|h| h.workspace_bytes += 8),
    );

    // Reserved fields and codecs (covering CRCs recomputed).
    s.invalid(
        "reserved-header-flag",
        "malformed",
        "Header flag bit 1 (reserved) set.",
        &["reserved"],
        {
            let mut b = subject.clone();
            b[10] |= 2;
            fix_header_crc(&mut b);
            b
        },
    );
    for (name, lanes) in [("lane-count-0", 0u8), ("lane-count-33", 33)] {
        s.invalid(
            name,
            "malformed",
            &format!("Header lane_count (byte 13) {lanes}, outside 1..=32."),
            &["header", "rans"],
            {
                let mut b = subject.clone();
                b[13] = lanes;
                fix_header_crc(&mut b);
                b
            },
        );
    }
    s.invalid(
        "reserved-level-table",
        "malformed",
        "The reserved field of level-table entry 0 not zero (table CRC recomputed).",
        &["reserved"],
        {
            let mut b = subject.clone();
            b[table_entry(0) + 28] = 1;
            fix_table_crc(&mut b);
            b
        },
    );
    s.invalid(
        "reserved-chunk-entry",
        "malformed",
        "The reserved field of level 1's first chunk-directory entry not zero (level header CRC recomputed).",
        &["reserved"],
        with_level_header_byte(&subject, 1, chunk_entry_at(&subject, 1, 0) + 2, 1),
    );
    s.invalid(
        "plane-policy-reserved",
        "malformed",
        "Level 1's plane policy byte (level header byte 8) set to 6, the first value 3.1 reserves (level header CRC recomputed).",
        &["reserved", "plane-policy"],
        with_level_header_byte(&subject, 1, plane_policy_at(&subject, 1), 6),
    );
    s.invalid(
        "plane-policy-255",
        "malformed",
        "Level 0's plane policy byte set to 255 (level header CRC recomputed).",
        &["reserved", "plane-policy"],
        with_level_header_byte(&subject, 0, plane_policy_at(&subject, 0), 255),
    );
    s.invalid(
        "wing-policy-reserved",
        "malformed",
        "Level 1's wing policy byte (level header byte 9) set to 3, the first value 3.2 reserves (level header CRC recomputed).",
        &["reserved", "wing-policy"],
        with_level_header_byte(&subject, 1, plane_policy_at(&subject, 1) + 1, 3),
    );
    s.invalid(
        "deficit-contexts-reserved",
        "malformed",
        "Level 1's deficit contexts byte (level header byte 10) set to 2, the first value 3.3 reserves (level header CRC recomputed).",
        &["reserved", "deficit-contexts"],
        with_level_header_byte(&subject, 1, plane_policy_at(&subject, 1) + 2, 2),
    );
    // A level whose rANS chunks were written under the deficit contexts
    // `valence` (5 and 6 tables for deficit-p and deficit-c) read as
    // `plain` (1 and 5): deficit-p's first chunk then ends its tables early
    // and reads a table byte as its lane directory (SPEC §5.5.2, §5.5.3).
    s.invalid(
        "deficit-contexts-switched",
        "malformed",
        "Level 1, written with deficit contexts `valence` (byte 10 = 1), relabelled `plain` (level header CRC recomputed): its deficit-p and deficit-c chunks hold more tables than `plain` reads.",
        &["deficit-contexts", "rans"],
        {
            let valence = encoded(
                &sphere,
                EncodeOptions {
                    deficits: Some(DeficitContexts::Valence),
                    codec: ChunkCodec::RansAlways { lanes: 4 },
                    ..opts()
                },
            );
            let at = plane_policy_at(&valence, 1) + 2;
            assert_eq!(valence[at], 1);
            with_level_header_byte(&valence, 1, at, 0)
        },
    );
    s.invalid(
        "reserved-level-header",
        "malformed",
        "Level 1's reserved level header byte 11 (after the deficit contexts) not zero (level header CRC recomputed).",
        &["reserved", "plane-policy"],
        with_level_header_byte(&subject, 1, plane_policy_at(&subject, 1) + 3, 1),
    );
    // A stored chunk longer than the header's max_chunk_len: the buffer a
    // decoder sized from the header could not hold it (SPEC §5.2). Both
    // lengths are below RANS_SLOT_BYTES, so the declared workspace stays
    // right (SPEC §9) and the level header is what fails.
    s.invalid(
        "byte-chunk-above-max-chunk-len",
        "malformed",
        "A stream of 64-byte stored chunks whose header says max_chunk_len 63 and minor version 4 (header CRC recomputed; the declared workspace is unchanged, both lengths being below RANS_SLOT_BYTES): level 0's first 64-byte chunk is above the maximum, which in 3.4 still bounds stored and deflate chunks, whatever the minor version.",
        &["codec", "byte-chunk-above-max"],
        {
            let mut stream = encoded(
                &sphere,
                EncodeOptions {
                    codec: ChunkCodec::Stored,
                    chunk_limit: 64,
                    rans_chunk_limit: 64,
                    ..opts()
                },
            );
            assert_eq!(Header::parse(&stream).expect("valid").max_chunk_len, 64);
            stream[24..28].copy_from_slice(&63u32.to_le_bytes());
            stream[9] = 4;
            fix_header_crc(&mut stream);
            stream
        },
    );
    s.invalid(
        "unknown-codec",
        "malformed",
        "Codec id 3 (reserved) on a stored chunk of level 1 (level header CRC recomputed).",
        &["codec"],
        {
            let mut b = stored_subject.clone();
            assert_eq!(chunk_codec(&b, 1, 0), 0);
            b[chunk_entry_at(&stored_subject, 1, 0) + 1] = 3;
            fix_level_header_crc(&mut b, 1);
            b
        },
    );
    s.invalid(
        "corrupt-deflate-chunk",
        "malformed",
        "A deflate chunk of level 1 whose first byte announces the reserved block type 3; chunk and level header CRCs recomputed.",
        &["codec"],
        {
            let mut b = subject.clone();
            let c = (0..chunk_count(&b, 1))
                .find(|&c| chunk_codec(&b, 1, c) == 1)
                .expect("a deflate chunk in level 1");
            let at = chunk_payload(&b, 1, c).start;
            b[at] = 0xFF;
            fix_chunk_crc(&mut b, 1, c);
            b
        },
    );

    // Record-level faults, re-framed with the writer (all checksums valid).
    let parts = unframe(&subject);
    s.invalid(
        "ring-offset-wing-distance",
        "ring-offset-out-of-range",
        "Level 1's first split record with wing distance 255 (o + d beyond the ring).",
        &["records", "ring-offset"],
        {
            let mut p = parts.clone();
            p.levels[1].substreams[2][0] = 255;
            reframe(&p)
        },
    );
    // The near order's ranks (3.2) out of range: the first wing's rank u
    // beyond the m eligible entries, the second's v beyond those after it.
    let near = unframe(&encoded(
        &meshes::icosphere(2),
        EncodeOptions {
            codec: ChunkCodec::Stored,
            wings: Some(WingPolicy::Near),
            ..opts()
        },
    ));
    for (slot, name, what) in [
        (
            1,
            "near-wing-first-rank",
            "first wing's near rank u = 255 (u >= m)",
        ),
        (
            2,
            "near-wing-second-rank",
            "second wing's near rank v = 255 (beyond the entries after the first)",
        ),
    ] {
        s.invalid(
            name,
            "ring-offset-out-of-range",
            &format!(
                "Level 1 (wing policy `near`, 3.2): its first split record's {what} (SPEC §7.4)."
            ),
            &["records", "ring-offset", "wing-policy"],
            {
                let mut p = near.clone();
                assert_eq!(p.levels[1].wings, WingPolicy::Near);
                p.levels[1].substreams[slot][0] = 255;
                reframe(&p)
            },
        );
    }
    s.invalid(
        "flag-count-declared-less",
        "count-mismatch",
        "A round of the last level declares one split fewer than it flags (level counts in the table adjusted to the declaration).",
        &["records", "flag-count"],
        {
            let mut p = parts.clone();
            let l = &mut p.levels[last as usize];
            let r = l.round_splits.iter().position(|&n| n >= 2).expect("a round with 2 splits");
            l.round_splits[r] -= 1;
            l.vertex_count -= 1;
            l.triangle_count -= 2;
            reframe(&p)
        },
    );
    s.invalid(
        "level-triangles-low",
        "count-mismatch",
        "The last level's table entry (and so the header capacity) one triangle short of what its splits make.",
        &["records", "level-count"],
        {
            let mut p = parts.clone();
            p.levels[last as usize].triangle_count -= 1;
            reframe(&p)
        },
    );
    s.invalid(
        "seed-triangles-over-entry",
        "count-mismatch",
        "Level 0 alone, its table entry (and so the header capacity and workspace) one triangle short of the seed mesh its header declares (3.5, SPEC §5.1: failed in the level header, before the seed is read; a 3.4 decoder met it as capacity-exceeded or count-mismatch, by its memory).",
        &["framing", "level-count", "capacity"],
        {
            let mut p = parts.clone();
            p.levels.truncate(1);
            let (_, seed_triangles, _) = p.levels[0].seed.as_ref().expect("level 0 has a seed");
            p.levels[0].triangle_count = seed_triangles - 1;
            reframe(&p)
        },
    );
    s.invalid(
        "record-trailing-data",
        "count-mismatch",
        "One byte appended to the edge substream of the last level: data after the level's last record.",
        &["records", "record-count"],
        {
            let mut p = parts.clone();
            p.levels[last as usize].substreams[5].push(0);
            reframe(&p)
        },
    );
    s.invalid(
        "record-substream-short",
        "count-mismatch",
        "The wing-distance substream of the last level one byte short: it runs out in the last record.",
        &["records", "record-count"],
        {
            let mut p = parts.clone();
            p.levels[last as usize].substreams[2].pop();
            reframe(&p)
        },
    );
    s.invalid(
        "flags-padding-not-zero",
        "count-mismatch",
        "The top padding bit after the last flag of a refinement level set (SPEC §5.4): every round of that level decodes, and the level's end-of-level check finds the unread bit.",
        &["records", "record-count"],
        {
            // The first level whose last flag byte has padding bits: its
            // flag count is not a multiple of 8. Setting the top bit of a
            // byte without padding would change a real flag instead (a
            // count-mismatch within a round), so each level is tried and
            // kept only when decoder-core decodes all its rounds first.
            let rounds_through = |k: usize| -> usize {
                1 + parts.levels[..=k]
                    .iter()
                    .map(|l| l.round_splits.len())
                    .sum::<usize>()
            };
            (1..parts.levels.len())
                .find_map(|k| {
                    let mut p = parts.clone();
                    *p.levels[k].substreams[0].last_mut()? |= 0x80;
                    let bytes = reframe(&p);
                    let outcome = builtin::decoder_core(&bytes);
                    (outcome.verdict == Verdict::Error("count-mismatch".into())
                        && outcome.hashes.len() == rounds_through(k))
                    .then_some(bytes)
                })
                .expect("a level whose flags end with padding bits")
        },
    );
    s.invalid(
        "deflate-unused-payload-byte",
        "malformed",
        "A deflate chunk (one stored block) followed by a zero byte inside its payload, lengths and CRCs matching: no payload byte may remain unused (SPEC §5.2).",
        &["chunks", "deflate-stored-block"],
        // Level 1's first chunk: level 0 decodes first.
        wrap_chunks_in_deflate_with(&stored_subject, Some((1, 0))),
    );
    s.invalid(
        "placement-code-3",
        "malformed",
        "Constrained mode: the first placement code of level 1 is 3.",
        &["records", "position-constrained"],
        {
            let mut p = unframe(&constrained);
            p.levels[1].substreams[6][0] = 3;
            reframe(&p)
        },
    );

    // Hand-made faults (SPEC §6.3, §7).
    let hand = |levels: &[splitstream_decoder_core::writer::LevelPayload]| {
        write_stream(&handmade::deflated(), levels)
    };
    let tetra = handmade::tetrahedron;
    s.invalid(
        "ring-offset-handmade",
        "ring-offset-out-of-range",
        "Tetrahedron split with wing ranks o' = 2, d' = 1 among m = 3 eligible ring entries (o' + d' = m).",
        &["handmade", "ring-offset"],
        {
            let mut rec = tetra_split();
            rec.o = 2;
            hand(&[tetra(), tetra_split_level(rec)])
        },
    );
    s.invalid(
        "ring-offset-distance-0",
        "ring-offset-out-of-range",
        "Tetrahedron split with wing rank distance d' = 0.",
        &["handmade", "ring-offset"],
        {
            let mut rec = tetra_split();
            rec.d = 0;
            hand(&[tetra(), tetra_split_level(rec)])
        },
    );
    s.invalid(
        "wing-rank-skips-round-start-candidate",
        "ring-offset-out-of-range",
        "Tetrahedron with adjacent candidates 0 and 1: vertex 1 was a candidate at the start of the round, so it may not be a wing and vertex 0's ring (1, 3, 2) has m = 2 eligible entries; ranks o' = 0, d' = 2 name none (SPEC §7.4).",
        &["handmade", "ring-offset", "wing-eligibility"],
        {
            let rec = Rec {
                m: 2,
                d: 2,
                ..tetra_split()
            };
            hand(&[
                handmade::tetrahedron_two_candidates(),
                tetra_split_level(rec),
            ])
        },
    );
    s.valid(
        "wing-ranks-skip-round-start-candidate",
        "Tetrahedron with adjacent candidates 0 and 1; vertex 0 splits and ranks 0 and 1 among its m = 2 eligible ring entries (3 and 2; vertex 1 was a candidate at round start) name wings 3 and 2. Vertex 1 stays a candidate: its flag is inferred (SPEC §7.2, §7.4).",
        &["handmade", "one-split", "wing-eligibility", "inferred-flags"],
        {
            let build = |rec: Rec| {
                write_stream(
                    &handmade::stored(),
                    &[
                        handmade::tetrahedron_two_candidates(),
                        tetra_split_level(rec),
                    ],
                )
            };
            let rec = Rec {
                m: 2,
                ..tetra_split()
            };
            let rec = handmade::solve(rec, 0, 4, [0, 0, 0], [4, 0, 2], &build)
                .expect("the record decodes");
            build(rec)
        },
    );
    s.invalid(
        "flag-count-handmade",
        "count-mismatch",
        "Tetrahedron: one split declared, the only candidate's flag 0.",
        &["handmade", "flag-count"],
        hand(&[tetra(), level(&[false], vec![1], &[tetra_split()], 5, 6)]),
    );
    s.invalid(
        "flag-of-inferred-candidate",
        "count-mismatch",
        "Tetrahedron with adjacent candidates 0 and 1; the stream codes a flag 1 for vertex 1 too, but vertex 1's flag is inferred 0 once vertex 0 is flagged (SPEC §7.2), so the round flags 1 split where 2 are declared.",
        &["handmade", "independence", "inferred-flags"],
        hand(&[
            handmade::tetrahedron_two_candidates(),
            level(&[true, true], vec![2], &[tetra_split(), tetra_split()], 6, 8),
        ]),
    );
    s.invalid(
        "valence-overflow-wing",
        "valence-overflow",
        "Octahedron whose non-adjacent vertices 0 and 1 are candidates and whose vertex 2 (deficit 1) is next to both: both split in one round with 2 as a wing. At round start 2 may be a wing (deficit 1); after the first split its deficit is 0 and the second split fails (SPEC §7.5).",
        &["handmade", "valence", "wing-eligibility"],
        {
            let rec = Rec {
                m: 4,
                valence_c: 5,
                e: [0; 3],
                t: [0; 3],
                ..tetra_split()
            };
            hand(&[
                handmade::octahedron(&[0, 0, 1, 255, 255, 255]),
                level(&[true, true], vec![2], &[rec, rec], 8, 12),
            ])
        },
    );
    rans_vectors(s);
    s.invalid(
        "valence-overflow-base",
        "valence-overflow",
        "Base tetrahedron vertex of valence 3 with deficit 253 (split valence 256 > 255).",
        &["handmade", "valence", "base-only"],
        hand(&[handmade::tetrahedron_with(&[253, LEAF, LEAF, LEAF])]),
    );
    s.invalid(
        "valence-overflow-split",
        "valence-overflow",
        "Split record whose split-valence symbol for P is 254: split valence 256 > 255 (SPEC §7.4).",
        &["handmade", "valence", "split-valence"],
        {
            let rec = Rec {
                sp: 254,
                ..tetra_split()
            };
            hand(&[tetra(), tetra_split_level(rec)])
        },
    );
    s.invalid(
        "split-valence-below-valence",
        "valence-overflow",
        "Split record whose split-valence symbol for C is 1 (split valence 3) while C's valence right after the split is 4 (SPEC §7.4).",
        &["handmade", "valence", "split-valence"],
        {
            let rec = Rec {
                sc: 1,
                ..tetra_split()
            };
            hand(&[tetra(), tetra_split_level(rec)])
        },
    );
    s.valid(
        "split-valence-255",
        "Split record whose split-valence symbol for P is 253: split valence 255, P keeps deficit 252 at valence 3 (the largest legal symbol, SPEC §7.4).",
        &["handmade", "one-split", "split-valence"],
        {
            let build = |rec: Rec| {
                write_stream(
                    &handmade::stored(),
                    &[tetra(), tetra_split_level(rec)],
                )
            };
            let rec = Rec {
                sp: 253,
                ..tetra_split()
            };
            let rec = handmade::solve(rec, 0, 4, [0, 0, 0], [2, 2, 2], &build)
                .expect("the record decodes");
            build(rec)
        },
    );
    s.invalid(
        "non-manifold-bowtie",
        "non-manifold",
        "Base mesh of two tetrahedra sharing one vertex (two fans at a vertex).",
        &["handmade", "base-only", "manifold"],
        hand(&[handmade::bowtie()]),
    );
    s.invalid(
        "non-manifold-flipped-face",
        "non-manifold",
        "Base tetrahedron with one face reversed: a directed edge used twice.",
        &["handmade", "base-only", "manifold"],
        hand(&[base(
            &handmade::TETRA_POSITIONS,
            &[[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 3, 2]],
            &[255; 4],
        )]),
    );
    s.invalid(
        "position-out-of-range-base",
        "position-out-of-range",
        "Base vertex x = 256 with 8 bits per axis.",
        &["handmade", "base-only", "positions"],
        hand(&[base(
            &[[0, 0, 0], [256, 0, 0], [0, 10, 0]],
            &[[0, 1, 2]],
            &[255; 3],
        )]),
    );
    s.invalid(
        "position-out-of-range-split",
        "position-out-of-range",
        "A split placing C at x = 300 with 8 bits per axis.",
        &["handmade", "positions"],
        {
            let build = |rec: Rec| hand(&[tetra(), tetra_split_level(rec)]);
            let rec = handmade::solve(tetra_split(), 0, 4, [0, 0, 0], [300, 2, 2], &build)
                .expect("the record decodes");
            build(rec)
        },
    );
    let triangle = || handmade::triangle(&[LEAF; 3]);
    for (name, bytes, what) in [
        (
            "varint-not-minimal",
            &[0x80u8, 0x00, 0x01, 0x02][..],
            "index 0 written as 0x80 0x00 (not minimal)",
        ),
        (
            "varint-too-long",
            &[0x80, 0x80, 0x80, 0x80, 0x80, 0x00, 0x01, 0x02][..],
            "a 6-byte varint",
        ),
        (
            "varint-over-32-bits",
            &[0xFF, 0xFF, 0xFF, 0xFF, 0x1F, 0x01, 0x02][..],
            "a 5-byte varint above 2^32 - 1",
        ),
    ] {
        s.invalid(
            name,
            "malformed",
            &format!("Base triangle substream with {what}."),
            &["handmade", "varint"],
            hand(&[handmade::with_raw_substream(triangle(), 1, bytes)
                .expect("a base level has a triangle substream (1)")]),
        );
    }
}

/// Faults inside rANS chunks (SPEC §5.5), patched into SPEC Appendix A's
/// stream coded with rANS in one lane (chunk CRCs recomputed).
fn rans_vectors(s: &mut Specs) {
    let subject = handmade::tetra_stream(ChunkCodec::RansAlways { lanes: 1 });
    // Level 1's first chunk is its flags: one context, one lane.
    let flags = chunk_payload(&subject, 1, 0);
    assert_eq!(chunk_codec(&subject, 1, 0), codec::RANS);
    let layout = rans_layout(&subject, flags, 1, 1);
    let patched = |f: &dyn Fn(&mut Vec<u8>)| {
        let mut b = subject.clone();
        f(&mut b);
        fix_chunk_crc(&mut b, 1, 0);
        b
    };
    s.invalid(
        "rans-lane-state-low",
        "malformed",
        "The flags lane's initial state is 1, below 2^23 (SPEC §5.5.3).",
        &["rans", "handmade"],
        patched(&|b| b[layout.lanes[0]..layout.lanes[0] + 4].copy_from_slice(&1u32.to_le_bytes())),
    );
    s.invalid(
        "rans-lane-not-exhausted",
        "malformed",
        "The flags lane's initial state is 2^23 + 1: its only value decodes, but the lane does not end in state 2^23 (SPEC §5.5.4).",
        &["rans", "handmade"],
        patched(&|b| {
            b[layout.lanes[0]..layout.lanes[0] + 4].copy_from_slice(&((1u32 << 23) + 1).to_le_bytes())
        }),
    );
    s.invalid(
        "rans-too-many-tokens",
        "malformed",
        "The flags table announces 45 tokens; the code has 44 (SPEC §5.5.2).",
        &["rans", "handmade"],
        patched(&|b| b[layout.token_counts[0]] = 45),
    );
    // The tetrahedron's split in rANS with one substream holding a single
    // value out of its field's range (slots from substream id 1).
    let out_of_range = |slot: usize, value: u32| {
        let mut lvl = tetra_split_level(tetra_split());
        let mut w = splitstream_decoder_core::writer::SubstreamWriter::default();
        w.varint(value);
        lvl.substreams[slot] = w;
        write_stream(
            &handmade::params(ChunkCodec::RansAlways { lanes: 1 }),
            &[handmade::tetrahedron(), lvl],
        )
    };
    s.invalid(
        "rans-bit-value-2",
        "malformed",
        "The flags substream, rANS-coded, holds the value 2 for a one-bit field (SPEC §5.5).",
        &["rans", "handmade"],
        out_of_range(0, 2),
    );
    s.invalid(
        "rans-byte-value-256",
        "malformed",
        "The deficit-p substream, rANS-coded, holds the value 256 for a byte field (SPEC §5.5): the wings read, the split-valence symbol does not.",
        &["rans", "handmade"],
        // Slot 3: substream id 4, deficit-p.
        out_of_range(3, 256),
    );
    s.invalid(
        "rans-mixed-codecs",
        "malformed",
        "A substream whose chunks mix rANS and stored (the codec byte of its second chunk set to 0; level header CRC recomputed).",
        &["rans", "codec"],
        {
            let mut b = encoded(
                &meshes::icosphere(2),
                EncodeOptions {
                    codec: ChunkCodec::RansAlways { lanes: 2 },
                    chunk_limit: 5,
                    rans_chunk_limit: 5,
                    ..opts()
                },
            );
            let c = 1;
            assert_eq!(chunk_codec(&b, 1, c), codec::RANS);
            let id = |c: usize| b[chunk_entry_at(&b, 1, c)];
            assert_eq!(id(0), id(1), "two chunks of one substream");
            let at = chunk_entry_at(&b, 1, c) + 1;
            b[at] = codec::STORED;
            fix_level_header_crc(&mut b, 1);
            b
        },
    );
}
