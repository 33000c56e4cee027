//! The conformance vectors the tests read (shared by the test files).

use std::path::{Path, PathBuf};

/// The newest vector set in conformance/vectors (by version number).
pub fn newest_vectors() -> PathBuf {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../conformance/vectors");
    let mut sets: Vec<PathBuf> = std::fs::read_dir(&root)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.join("manifest.json").is_file())
        .collect();
    sets.sort_by_key(|p| {
        p.file_name()
            .unwrap()
            .to_string_lossy()
            .split('.')
            .map(|n| n.parse::<u32>().unwrap_or(0))
            .collect::<Vec<_>>()
    });
    sets.pop().expect("a vector set")
}
