//! The C ABI from C: compiles tests/c/example.c with `cc` against
//! include/splitstream.h and the crate's static library, then runs it on
//! every conformance vector (hashes and error classes from the manifest)
//! and on synthetic grid tiles. Without a C compiler it skips with a note,
//! unless `CI` is set.

mod vectors;

use std::path::{Path, PathBuf};
use std::process::Command;

use serde_json::Value;
use vectors::newest_vectors;

/// The crate's static library, freshly built. `cargo test` builds the
/// library for its tests as an rlib only (a `libsplitstream_sdk_native.a`
/// beside the test binary may be missing or stale), so this runs `cargo
/// build --lib` into a target directory of its own under the test's
/// scratch directory: no lock shared with the running cargo, incremental
/// after the first run.
fn static_lib() -> PathBuf {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("c-abi-lib");
    let status = Command::new(env!("CARGO"))
        .args(["build", "--quiet", "-p", "splitstream-sdk-native", "--lib"])
        .arg("--target-dir")
        .arg(&dir)
        .current_dir(root)
        .status()
        .expect("run cargo");
    assert!(status.success(), "cargo build of the static library failed");
    let lib = dir.join("debug/libsplitstream_sdk_native.a");
    assert!(lib.is_file(), "{} not built", lib.display());
    lib
}

fn build_example() -> Option<PathBuf> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let cc = std::env::var("CC").unwrap_or_else(|_| "cc".into());
    if Command::new(&cc).arg("--version").output().is_err() {
        assert!(
            std::env::var_os("CI").is_none(),
            "no C compiler ({cc}) and CI is set"
        );
        eprintln!("note: no C compiler ({cc}): C ABI test skipped");
        return None;
    }
    let lib = static_lib();
    let out = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("splitstream-c-example");
    let status = Command::new(&cc)
        .args(["-std=c11", "-Wall", "-Wextra", "-Werror", "-O1"])
        .arg("-I")
        .arg(root.join("include"))
        .arg(root.join("tests/c/example.c"))
        .arg(&lib)
        .args(["-lpthread", "-ldl", "-lm", "-o"])
        .arg(&out)
        .status()
        .expect("run cc");
    assert!(status.success(), "cc failed");
    Some(out)
}

fn run(exe: &Path, args: &[&str]) -> String {
    let out = Command::new(exe).args(args).output().expect("run example");
    assert!(
        out.status.success(),
        "example {args:?} exited with {}: {}",
        out.status,
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8(out.stdout).unwrap()
}

#[test]
fn c_program_decodes_the_conformance_vectors_and_simplifies_tiles() {
    let Some(exe) = build_example() else { return };
    let dir = newest_vectors();
    let manifest: Value =
        serde_json::from_slice(&std::fs::read(dir.join("manifest.json")).unwrap()).unwrap();
    let mut checked = 0;
    for v in manifest["vectors"].as_array().unwrap() {
        let name = v["name"].as_str().unwrap();
        let file = dir.join(v["file"].as_str().unwrap());
        let out = run(&exe, &["decode", file.to_str().unwrap()]);
        let words: Vec<&str> = out.split_whitespace().collect();
        if v["valid"].as_bool().unwrap() {
            let r = &v["result"];
            let expected = format!(
                "ok {} {} {}",
                r["state_hash"].as_str().unwrap(),
                r["vertices"],
                r["triangles"]
            );
            assert_eq!(out.trim(), expected, "{name}");
        } else {
            let class = format!("{}:", v["error_class"].as_str().unwrap());
            assert_eq!(
                words.get(..2),
                Some(&["error", class.as_str()][..]),
                "{name}: {out}"
            );
        }
        checked += 1;
    }
    assert!(checked > 10);

    let out = run(&exe, &["grid"]);
    let lines: Vec<&str> = out.lines().collect();
    assert_eq!(lines.len(), 3, "{out}");
    // The plane collapses to one rectangle, two triangles.
    assert_eq!(lines[0], "grid 4096 1 2 0.000000");
    let hilly: Vec<f64> = lines[1]
        .split_whitespace()
        .skip(1)
        .map(|w| w.parse().unwrap())
        .collect();
    assert!(hilly[1] < hilly[0] && hilly[1] > 1.0, "{out}");
    assert!(hilly[3] <= 1.0 + 1e-6, "{out}");
    assert!(lines[2].starts_with("error grid-tile: "), "{out}");
}
