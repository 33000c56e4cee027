//! The vector manifest (`vectors/<version>/manifest.json`): what every vector
//! is and what a conforming decoder must report for it.

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

/// Version of the vector set, which is the format version it tests
/// (`decoder-core/SPEC.md` §1). Any change to stream bytes or decoding rules
/// bumps it and regenerates the set with `conformance/generate.sh`.
pub const SUITE_VERSION: &str = "3.12";

/// The whole manifest.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Manifest {
    /// Format version the vectors are written in and checked against.
    pub format_version: String,
    /// How the set was made (never edited by hand).
    pub generator: String,
    /// Where the protocol that runs decoders against the set is described.
    pub protocol: String,
    pub vectors: Vec<Vector>,
}

/// One vector: a stream and the expected decoder output.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Vector {
    /// Unique name (the file stem).
    pub name: String,
    /// Path of the stream, relative to the manifest.
    pub file: String,
    pub description: String,
    /// Tags: what the vector exercises (see conformance/README.md).
    pub features: Vec<String>,
    /// Stream length in bytes.
    pub bytes: usize,
    /// `true`: the stream is valid and must decode; `false`: it must be
    /// rejected with `error_class`.
    pub valid: bool,
    /// SPEC §10.1 error class of an invalid vector.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub error_class: Option<String>,
    /// Valid vector: the state hash (SPEC §8) after the seed mesh and after
    /// every round, in order. Invalid vector: the hashes SPEC §10.3 reports
    /// before the fault is met; a decoder may report any prefix of them (e.g.
    /// one that checks every chunk up front reports fewer).
    pub round_hashes: Vec<String>,
    /// Valid vectors only: the decoded mesh after the last level.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub result: Option<FinalMesh>,
}

/// Summary of the fully decoded mesh of a valid vector.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct FinalMesh {
    pub levels: u16,
    pub rounds: usize,
    pub vertices: usize,
    pub triangles: usize,
    /// Edges with one triangle (0: closed mesh).
    pub boundary_edges: usize,
    /// Largest number of triangles around one vertex in any state (the seed
    /// and after every round).
    pub max_vertex_triangles: usize,
    /// The last entry of `round_hashes`: positions, deficits and triangles.
    pub state_hash: String,
    /// FNV-1a 64 of the final positions then triangles alone (u32 little
    /// endian each, as in SPEC §8 without counts and deficits).
    pub geometry_hash: String,
}

impl Manifest {
    pub fn load(path: &Path) -> Result<Manifest, String> {
        let text = std::fs::read_to_string(path).map_err(|e| format!("{}: {e}", path.display()))?;
        serde_json::from_str(&text).map_err(|e| format!("{}: {e}", path.display()))
    }

    /// Pretty JSON with a final newline; the byte-exact form the generator writes.
    pub fn to_json(&self) -> String {
        let mut s = serde_json::to_string_pretty(self).expect("a manifest serialises");
        s.push('\n');
        s
    }
}

/// Directory of the vector set this crate was built with.
pub fn default_vector_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("vectors")
        .join(SUITE_VERSION)
}

/// `%016x` of a hash, the protocol's form.
pub fn hex(h: u64) -> String {
    format!("{h:016x}")
}
