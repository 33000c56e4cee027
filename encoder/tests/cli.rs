//! Running the `splitstream` binary from the command-line tests.
#![allow(dead_code)]

use std::path::PathBuf;
use std::process::{Command, Output};

/// Writes `contents` to `name` in a scratch folder of this test process
/// (`tag` keeps test binaries apart) and returns its path.
pub fn temp(tag: &str, name: &str, contents: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("splitstream-{tag}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join(name);
    std::fs::write(&path, contents).unwrap();
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
