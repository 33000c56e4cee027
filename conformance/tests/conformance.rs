//! The suite checks itself: decoder-core passes every vector, a broken
//! decoder is caught, the external-command path works, every invalid vector
//! fails with exactly its class, and the committed vectors are exactly what
//! the generator writes.

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Duration;

use splitstream_conformance::builtin::{self, decode_by_pieces, run_builtin};
use splitstream_conformance::generate;
use splitstream_conformance::manifest::{Manifest, default_vector_dir, hex};
use splitstream_conformance::protocol::{Verdict, judge};
use splitstream_conformance::runner::{run_external, run_vectors};
use splitstream_decoder_core::owned::decode_all;

const BIN: &str = env!("CARGO_BIN_EXE_splitstream-conformance");

fn manifest() -> Manifest {
    Manifest::load(&default_vector_dir().join("manifest.json")).expect("committed manifest")
}

fn stream(file: &str) -> Vec<u8> {
    std::fs::read(default_vector_dir().join(file)).expect("committed vector")
}

fn summary_line(stdout: &str) -> (usize, usize) {
    let line = stdout
        .lines()
        .rfind(|l| l.ends_with(" failed"))
        .unwrap_or_else(|| panic!("no summary line in:\n{stdout}"));
    let words: Vec<&str> = line.split(' ').collect();
    assert_eq!(words.len(), 4, "summary line {line:?}");
    assert_eq!(
        (words[1], words[3]),
        ("passed,", "failed"),
        "summary line {line:?}"
    );
    (words[0].parse().unwrap(), words[2].parse().unwrap())
}

fn run(args: &[&str]) -> (bool, String) {
    let out = Command::new(BIN).args(args).output().expect("runs");
    (
        out.status.success(),
        String::from_utf8(out.stdout).expect("UTF-8"),
    )
}

#[test]
fn manifest_matches_the_files() {
    let m = manifest();
    assert_eq!(m.format_version, "3.12");
    let mut names = BTreeSet::new();
    let mut total = 0;
    for v in &m.vectors {
        assert!(names.insert(v.name.clone()), "duplicate {}", v.name);
        let bytes = stream(&v.file);
        assert_eq!(bytes.len(), v.bytes, "{}", v.name);
        total += bytes.len();
        assert_eq!(v.valid, v.error_class.is_none(), "{}", v.name);
        assert!(
            !v.features.is_empty() && !v.description.is_empty(),
            "{}",
            v.name
        );
        if v.valid {
            let r = v.result.as_ref().expect("valid vectors have a result");
            assert_eq!(v.round_hashes.last(), Some(&r.state_hash), "{}", v.name);
            assert_eq!(v.round_hashes.len(), r.rounds + 1, "{}", v.name);
        }
    }
    assert!(
        total < 4 << 20,
        "the suite should stay a few MiB ({total} bytes)"
    );
}

#[test]
fn every_error_class_is_covered() {
    let covered: BTreeSet<String> = manifest()
        .vectors
        .iter()
        .filter_map(|v| v.error_class.clone())
        .collect();
    for class in [
        "bad-magic",
        "unsupported-version",
        "checksum-mismatch",
        "truncated",
        "malformed",
        "capacity-exceeded",
        "count-mismatch",
        "ring-offset-out-of-range",
        "valence-overflow",
        "non-manifold",
        "position-out-of-range",
    ] {
        assert!(covered.contains(class), "no vector for {class}");
    }
}

#[test]
fn decoder_core_decodes_every_vector_as_the_manifest_says() {
    for v in &manifest().vectors {
        let bytes = stream(&v.file);
        match decode_all(&bytes, true) {
            Ok(mesh) => {
                assert!(
                    v.valid,
                    "{}: decoded but must fail with {:?}",
                    v.name, v.error_class
                );
                let hashes: Vec<String> = mesh.round_hashes.iter().map(|&h| hex(h)).collect();
                assert_eq!(hashes, v.round_hashes, "{}", v.name);
                let r = v.result.as_ref().unwrap();
                assert_eq!(
                    (mesh.positions.len(), mesh.triangles.len(), mesh.levels),
                    (r.vertices, r.triangles, r.levels),
                    "{}",
                    v.name
                );
            }
            Err(e) => assert_eq!(Some(e.class()), v.error_class.as_deref(), "{}: {e}", v.name),
        }
    }
}

#[test]
fn builtin_decoder_core_passes_and_agrees_with_its_pieces() {
    let m = manifest();
    let b = builtin::find("decoder-core").unwrap();
    let report = run_vectors(&m, &default_vector_dir(), |s| run_builtin(b, s)).unwrap();
    assert_eq!(
        (report.passed(), report.failed()),
        (m.vectors.len(), 0),
        "{}",
        report.table()
    );
    for v in &m.vectors {
        let bytes = stream(&v.file);
        let (pieces, core) = (
            decode_by_pieces(&bytes, false),
            builtin::decoder_core(&bytes),
        );
        assert_eq!(pieces.verdict, core.verdict, "{}", v.name);
        // Equal, except where SPEC §8 reports a failing round-less seed's hash.
        assert!(pieces.hashes.starts_with(&core.hashes), "{}", v.name);
        let hashes: Vec<String> = pieces.hashes.iter().map(|&h| hex(h)).collect();
        assert_eq!(hashes, v.round_hashes, "{}", v.name);
        if v.valid {
            assert_eq!(pieces.hashes, core.hashes, "{}", v.name);
        }
    }
}

/// Whether the GPU built-ins of this build (features `gpu`, `opencl`) find
/// their devices. Outside CI a missing device skips what needs it, as in
/// tests/gpu.rs; under CI it is a failure, so nothing is probed.
fn gpu_builtins_have_devices() -> bool {
    #[cfg(feature = "gpu")]
    if std::env::var_os("CI").is_none() {
        use splitstream_sdk_native::gpu::{Api, GpuDevice};
        let mut apis = vec![Api::Wgpu];
        if cfg!(feature = "opencl") {
            apis.push(Api::OpenCl);
        }
        for api in apis {
            if let Err(e) = GpuDevice::open(api) {
                eprintln!("skipping: the {api} built-in has no device here: {e}");
                return false;
            }
        }
    }
    true
}

#[test]
fn run_without_arguments_runs_the_builtins() {
    if !gpu_builtins_have_devices() {
        return;
    }
    let (ok, out) = run(&["run"]);
    assert!(ok, "{out}");
    let (passed, failed) = summary_line(&out);
    // Every visible built-in of this build (the GPU ones with `gpu`,
    // `opencl`) on every vector.
    let visible = builtin::BUILTINS.iter().filter(|b| !b.hidden).count();
    assert_eq!((passed, failed), (visible * manifest().vectors.len(), 0));
    assert!(out.contains("decoder-core"));
    assert!(
        !out.contains("broken-swap"),
        "test-only decoders are hidden"
    );
}

#[test]
fn broken_swap_is_caught() {
    let (ok, out) = run(&["run", "--builtin", "broken-swap"]);
    assert!(!ok, "the runner must exit non-zero:\n{out}");
    let (passed, failed) = summary_line(&out);
    assert!(failed > 0 && passed > 0, "{out}");
    // Every valid vector with a split decodes differently.
    for v in manifest()
        .vectors
        .iter()
        .filter(|v| v.valid && v.round_hashes.len() > 1)
    {
        let line = out
            .lines()
            .find(|l| l.split_whitespace().nth(1) == Some(v.name.as_str()));
        assert!(
            line.is_some_and(|l| l.starts_with("FAIL")),
            "{}: {line:?}",
            v.name
        );
    }
}

#[test]
fn external_decoder_path_works() {
    let decoder = format!("'{BIN}' decode");
    let (ok, out) = run(&["run", "--decoder", &decoder]);
    assert!(ok, "{out}");
    assert_eq!(summary_line(&out), (manifest().vectors.len(), 0));
}

#[test]
fn external_decoders_that_misbehave_fail() {
    let m = manifest();
    let valid = m
        .vectors
        .iter()
        .find(|v| v.name == "icosphere-optimal-deflate")
        .unwrap();
    let bytes = stream(&valid.file);
    let limit = Duration::from_secs(20);
    // Says ok without hashes.
    let o = run_external("cat > /dev/null; echo ok", &bytes, limit);
    assert!(!judge(valid, &o).0);
    // Right hashes, but the stream is not read at all: still judged on output.
    let lines = valid.round_hashes.join("\n");
    let o = run_external(&format!("printf '{lines}\\nok\\n'"), &bytes, limit);
    assert!(judge(valid, &o).0, "{o:?}");
    // Garbage, crashes, and hangs.
    let o = run_external("echo hello", &bytes, limit);
    assert!(matches!(o.verdict, Verdict::Broken(_)));
    let o = run_external("kill -9 $$", &bytes, limit);
    assert!(matches!(o.verdict, Verdict::Broken(_)), "{o:?}");
    let started = std::time::Instant::now();
    let o = run_external("exec sleep 30", &bytes, Duration::from_millis(300));
    assert!(
        matches!(&o.verdict, Verdict::Broken(w) if w.contains("timed out")),
        "{o:?}"
    );
    assert!(started.elapsed() < Duration::from_secs(10));
    // A wrong class for an invalid vector.
    let invalid = m.vectors.iter().find(|v| v.name == "bad-magic").unwrap();
    let o = run_external("echo error truncated", &stream(&invalid.file), limit);
    assert!(!judge(invalid, &o).0);
    let o = run_external(
        "echo error bad-magic; exit 3",
        &stream(&invalid.file),
        limit,
    );
    assert!(judge(invalid, &o).0);
}

fn files_under(dir: &Path) -> BTreeSet<PathBuf> {
    let mut out = BTreeSet::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                stack.push(p);
            } else {
                out.insert(p.strip_prefix(dir).unwrap().to_path_buf());
            }
        }
    }
    out
}

#[test]
fn committed_vectors_are_exactly_what_the_generator_writes() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let real = root.join("../encoder/data/real");
    if !real.join("bunny.ply").exists() {
        eprintln!("skipped: run encoder/data/fetch.sh to regenerate the real-mesh vector");
        return;
    }
    let tmp = std::env::temp_dir().join(format!("splitstream-vectors-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&tmp);
    let generated = generate::generate(&real).expect("generates");
    generate::write(&generated, &tmp).expect("writes");
    let committed = default_vector_dir();
    let (a, b) = (files_under(&committed), files_under(&tmp));
    assert_eq!(a, b, "file sets differ: run conformance/generate.sh");
    for f in &a {
        assert!(
            std::fs::read(committed.join(f)).unwrap() == std::fs::read(tmp.join(f)).unwrap(),
            "{} differs from a fresh generation: run conformance/generate.sh (and bump the version if stream bytes or rules changed)",
            f.display()
        );
    }
    std::fs::remove_dir_all(&tmp).unwrap();
}

#[test]
fn the_appendix_a_vector_has_the_spec_hashes() {
    // decoder-core/SPEC.md Appendix A: the tetrahedron and its one split.
    for name in [
        "handmade-tetra-split-stored",
        "handmade-tetra-split-deflate",
    ] {
        let m = manifest();
        let v = m.vectors.iter().find(|v| v.name == name).unwrap();
        assert_eq!(
            v.round_hashes,
            ["e89ae8021be834dc", "500f34e8694c8efd"],
            "{name}"
        );
    }
}
