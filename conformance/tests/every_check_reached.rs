//! Every detailed check decoder-core makes is met by some invalid vector:
//! the errors that name the rule they enforce (`InvalidHeader("…")`,
//! `InvalidLevelTable`, `InvalidLevelHeader`, `InvalidRansChunk`,
//! `NonManifold`) are read from decoder-core's sources, and each must be the
//! error decoder-core gives for at least one invalid vector. A check added
//! to the decoder without a vector fails here, so a third-party decoder
//! cannot skip a rule the suite does not test. (The runner compares error
//! classes only; this test is about the suite's reach.)

use std::collections::BTreeSet;
use std::path::Path;

use splitstream_conformance::manifest::{Manifest, default_vector_dir};
use splitstream_decoder_core::owned::decode_all;

/// The error variants whose argument names the rule broken.
const DETAILED: [&str; 5] = [
    "InvalidHeader",
    "InvalidLevelTable",
    "InvalidLevelHeader",
    "InvalidRansChunk",
    "NonManifold",
];

/// Checks no stream can reach, kept as guards, each with its reason.
const GUARDS: [(&str, &str); 5] = [
    (
        "InvalidLevelTable(\"empty\")",
        "the header already rejects level_count 0 (SPEC §3.3)",
    ),
    (
        "InvalidHeader(\"level table shorter than its CRC\")",
        "a parsed header's table is at least 8 x level_count + 4 bytes (SPEC §3.3); only a header built by hand reaches it",
    ),
    (
        "InvalidRansChunk(\"counts cannot be normalised\")",
        "with the last count nonzero, f[j] >= 92 - 43 (SPEC §5.5.2)",
    ),
    (
        "InvalidRansChunk(\"adaptive table without room\")",
        "an adaptive table's (m - 1) x lane_count <= 48 is checked when the table is read (SPEC §5.5.2)",
    ),
    (
        "InvalidRansChunk(\"slot beyond the table\")",
        "normalised frequencies sum to 4096, so cum[n] exceeds every slot (SPEC §5.5.4)",
    ),
];

/// Every `Variant("literal")` of [`DETAILED`] in `source`, as `Debug`
/// prints it (the literal may start on the next line).
fn detailed_errors(source: &str) -> Vec<String> {
    let mut found = Vec::new();
    for variant in DETAILED {
        let open = format!("{variant}(");
        let mut rest = source;
        while let Some(at) = rest.find(&open) {
            rest = &rest[at + open.len()..];
            let arg = rest.trim_start();
            if let Some(literal) = arg.strip_prefix('"') {
                let end = literal.find('"').expect("a closed string literal");
                found.push(format!("{variant}({:?})", &literal[..end]));
            }
        }
    }
    found
}

#[test]
fn the_source_scan_finds_the_checks() {
    let found = detailed_errors(
        "Err(Error::InvalidHeader(\"no levels\")); Error::NonManifold(\n    \"degenerate triangle\",\n)",
    );
    assert_eq!(
        found,
        [
            "InvalidHeader(\"no levels\")",
            "NonManifold(\"degenerate triangle\")"
        ]
    );
}

#[test]
fn every_detailed_check_is_met_by_a_vector() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("../decoder-core/src");
    let mut checks = BTreeSet::new();
    for entry in std::fs::read_dir(&src).expect("decoder-core/src") {
        let path = entry.expect("a directory entry").path();
        if path.extension().is_some_and(|e| e == "rs") {
            let source = std::fs::read_to_string(&path).expect("a source file");
            checks.extend(detailed_errors(&source));
        }
    }
    assert!(checks.len() > 40, "the scan found only {checks:?}");
    for (guard, _why) in GUARDS {
        assert!(checks.remove(guard), "{guard} is no longer in decoder-core");
    }
    let dir = default_vector_dir();
    let manifest = Manifest::load(&dir.join("manifest.json")).expect("manifest");
    let mut met = BTreeSet::new();
    for v in manifest.vectors.iter().filter(|v| !v.valid) {
        let stream = std::fs::read(dir.join(&v.file)).expect("vector");
        if let Err(e) = decode_all(&stream, false) {
            met.insert(format!("{e:?}"));
        }
    }
    let unmet: Vec<&String> = checks.difference(&met).collect();
    assert!(
        unmet.is_empty(),
        "checks no invalid vector meets (add one in conformance/src/generate/malformed.rs): {unmet:?}"
    );
}
