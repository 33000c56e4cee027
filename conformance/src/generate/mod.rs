//! The vector generator: every vector of `vectors/<version>/` and its
//! manifest entry come from here, deterministically (same bytes on every
//! run and machine). Run it with `conformance/generate.sh`.

mod compact;
mod invalid;
mod malformed;
mod meshes;
mod mutate;
mod positions_first;
mod rans;
mod reach;
mod table;
mod valid;

use std::collections::BTreeMap;
use std::path::Path;

use splitstream_decoder_core::limits::codec;
use splitstream_decoder_core::owned::{OwnedWorkspace, decode_all};
use splitstream_decoder_core::writer::ChunkCodec;
use splitstream_decoder_core::{
    Fnv1a, Framing, Header, LevelHeader, LevelTable, PositionMode, RecordOrder, Schedule,
};
use splitstream_encoder::Mesh;
use splitstream_encoder::emit::{EncodeOptions, encode};

use crate::builtin;
use crate::manifest::{FinalMesh, Manifest, SUITE_VERSION, Vector, hex};
use crate::protocol::Verdict;
use invalid::invalid_vectors;
use valid::valid_vectors;

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

/// The encoder's defaults in optimal mode with split valences, the
/// encoder's defaults when the vectors were first written (constrained
/// mode since 2026-12-03, the schedule `every-vertex` since format 3.6):
/// the vectors named `position-constrained` ask for constrained mode, and
/// those named `every-vertex-…` for the schedule `every-vertex`
/// ([`every_vertex`]); records are read wings first (format 3.7's
/// `positions-first` has vectors of its own, `positions_first.rs`); level
/// headers in the fixed framing, which the vectors were written in and
/// whose offsets the invalid vectors patch (format 3.11's compact framing
/// has vectors of its own, `compact.rs`, and 3.12's compact table
/// `table.rs`).
fn opts() -> EncodeOptions {
    EncodeOptions {
        position_mode: PositionMode::Optimal,
        schedule: Schedule::SplitValences,
        records: Some(RecordOrder::WingsFirst),
        framing: Framing::Fixed,
        ..EncodeOptions::default()
    }
}

/// `options` under the schedule `every-vertex` (SPEC §3.2, format 3.6).
fn every_vertex(options: EncodeOptions) -> EncodeOptions {
    EncodeOptions {
        schedule: Schedule::EveryVertex,
        ..options
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
    malformed::malformed_vectors(&mut specs);
    reach::reach_vectors(&mut specs);
    compact::compact_vectors(&mut specs);
    table::table_vectors(&mut specs);
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
            // A vector that names a feature `final_mesh` derives must have it.
            for derived in DERIVED_TAGS {
                assert!(
                    !spec.features.iter().any(|f| f == derived)
                        || tags.iter().any(|t| t == derived),
                    "{}: declared {derived}, the stream does not have it",
                    spec.name
                );
            }
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

/// Tags [`final_mesh`] derives that a vector may also declare (the
/// generator then checks that its stream has them).
const DERIVED_TAGS: [&str; 1] = ["rans-chunks-uneven"];

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
        let lh = LevelHeader::parse(bytes, k == 0, header.level_rules()).expect("valid");
        if k == 0 && lh.round_count > 0 {
            tags.push("seed-rounds".to_string());
        }
        let mut per_substream = BTreeMap::new();
        let mut rans_lengths: BTreeMap<u8, Vec<u32>> = BTreeMap::new();
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
            if e.codec == codec::RANS {
                rans_lengths.entry(e.substream).or_default().push(e.raw_len);
            }
        }
        if per_substream.values().any(|&n| n > 1) {
            tags.push("multi-chunk-substreams".to_string());
        }
        // rANS chunks of one substream cut at different lengths, as the
        // reference encoder cuts them (SPEC §5.2, §11), not every chunk but
        // the last one length.
        let uneven = |lengths: &Vec<u32>| match lengths.split_last() {
            Some((last, rest)) if !rest.is_empty() => {
                rest.iter().any(|&l| l != rest[0]) || *last > rest[0]
            }
            _ => false,
        };
        if rans_lengths.values().any(uneven) {
            tags.push("rans-chunks-uneven".to_string());
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
