//! Running the `splitstream` binary from the command-line tests.
#![allow(dead_code)]

use std::path::PathBuf;
use std::process::{Command, Output};
use std::sync::atomic::{AtomicUsize, Ordering};

/// Writes `contents` to `name` in a scratch folder of this test process
/// (`tag` keeps test binaries apart) and returns its path. Tests of one
/// binary run on several threads and may write the same file at once: each
/// writes a file of its own and renames it into place, so that a reader
/// never sees one half written (`encode_cli` failed that way).
pub fn temp(tag: &str, name: &str, contents: &str) -> PathBuf {
    static WRITES: AtomicUsize = AtomicUsize::new(0);
    let dir = std::env::temp_dir().join(format!("splitstream-{tag}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join(name);
    let n = WRITES.fetch_add(1, Ordering::Relaxed);
    let staged = dir.join(format!("{name}.{n}.part"));
    std::fs::write(&staged, contents).unwrap();
    std::fs::rename(&staged, &path).unwrap();
    path
}

/// Runs `splitstream` with `args`.
pub fn splitstream(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_splitstream"))
        .args(args)
        .output()
        .unwrap()
}

/// A failed run's stderr, checked to be one line.
pub fn one_line_error(out: &Output) -> String {
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr).to_string();
    assert_eq!(err.trim_end().lines().count(), 1, "{err}");
    err
}

/// A successful run's stdout (its stderr shown if it failed).
pub fn succeeded(out: &Output) -> String {
    let stdout = String::from_utf8_lossy(&out.stdout).to_string();
    assert!(
        out.status.success(),
        "{stdout}{}",
        String::from_utf8_lossy(&out.stderr)
    );
    stdout
}
