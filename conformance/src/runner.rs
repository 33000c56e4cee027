//! Runs decoders against the vector set and reports a pass/fail table.

use std::io::{Read, Write};
use std::path::Path;
use std::process::{Command, Stdio};
use std::sync::mpsc;
use std::time::{Duration, Instant};

use crate::manifest::Manifest;
use crate::protocol::{Outcome, Verdict, expected, judge, parse_output};

/// Default time one decoder gets for one vector.
pub const DEFAULT_TIMEOUT: Duration = Duration::from_secs(20);

/// One vector's result.
#[derive(Clone, Debug)]
pub struct Row {
    pub vector: String,
    pub expected: String,
    pub got: String,
    pub passed: bool,
}

/// Every vector's result for one decoder.
#[derive(Clone, Debug, Default)]
pub struct Report {
    pub rows: Vec<Row>,
}

impl Report {
    pub fn passed(&self) -> usize {
        self.rows.iter().filter(|r| r.passed).count()
    }

    pub fn failed(&self) -> usize {
        self.rows.len() - self.passed()
    }

    /// The pass/fail table, one vector a line.
    pub fn table(&self) -> String {
        let w0 = self
            .rows
            .iter()
            .map(|r| r.vector.len())
            .max()
            .unwrap_or(6)
            .max(6);
        let w1 = self
            .rows
            .iter()
            .map(|r| r.expected.len())
            .max()
            .unwrap_or(8)
            .max(8);
        let mut s = format!("{:<4}  {:<w0$}  {:<w1$}  got\n", "", "vector", "expected");
        for r in &self.rows {
            let mark = if r.passed { "pass" } else { "FAIL" };
            s.push_str(&format!(
                "{mark:<4}  {:<w0$}  {:<w1$}  {}\n",
                r.vector, r.expected, r.got
            ));
        }
        s
    }

    /// The summary line, exactly `N passed, M failed`.
    pub fn summary(&self) -> String {
        format!("{} passed, {} failed", self.passed(), self.failed())
    }
}

/// Runs `decode` on every vector of `manifest`, whose files lie under `dir`.
pub fn run_vectors(
    manifest: &Manifest,
    dir: &Path,
    mut decode: impl FnMut(&[u8]) -> Outcome,
) -> Result<Report, String> {
    let mut report = Report::default();
    for v in &manifest.vectors {
        let path = dir.join(&v.file);
        let stream = std::fs::read(&path).map_err(|e| format!("{}: {e}", path.display()))?;
        let outcome = decode(&stream);
        let (passed, got) = judge(v, &outcome);
        report.rows.push(Row {
            vector: v.name.clone(),
            expected: expected(v),
            got,
            passed,
        });
    }
    Ok(report)
}

/// Runs `command` through `sh -c`, writes `stream` to its standard input and
/// parses its standard output (the protocol of conformance/README.md). After
/// `timeout` the shell is killed (SIGKILL); processes it started that keep
/// the output open are abandoned after a short grace period, so a decoder
/// wrapped in a script should `exec` it.
pub fn run_external(command: &str, stream: &[u8], timeout: Duration) -> Outcome {
    let mut child = match Command::new("sh")
        .arg("-c")
        .arg(command)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
    {
        Ok(c) => c,
        Err(e) => return Outcome::broken(format!("cannot start sh: {e}")),
    };
    let mut stdin = child.stdin.take().expect("piped");
    let input = stream.to_vec();
    // The decoder may stop reading early (a bad header): a broken pipe is fine.
    std::thread::spawn(move || {
        let _ = stdin.write_all(&input);
    });
    let (out_tx, out_rx) = mpsc::channel();
    let mut stdout = child.stdout.take().expect("piped");
    std::thread::spawn(move || {
        let mut out = Vec::new();
        let _ = stdout.read_to_end(&mut out);
        let _ = out_tx.send(out);
    });
    let (err_tx, err_rx) = mpsc::channel();
    let mut stderr = child.stderr.take().expect("piped");
    std::thread::spawn(move || {
        let mut out = Vec::new();
        let _ = stderr.read_to_end(&mut out);
        let _ = err_tx.send(out);
    });
    let started = Instant::now();
    let status = loop {
        match child.try_wait() {
            Ok(Some(status)) => break Some(status),
            Ok(None) if started.elapsed() >= timeout => break None,
            Ok(None) => std::thread::sleep(Duration::from_millis(2)),
            Err(e) => return Outcome::broken(format!("waiting for the decoder: {e}")),
        }
    };
    if status.is_none() {
        let _ = child.kill();
        let _ = child.wait();
    }
    // Output still open after the shell ended belongs to a process it left
    // behind; wait a little, then judge what arrived.
    let grace = Duration::from_secs(2);
    let out = out_rx.recv_timeout(grace);
    let err = err_rx
        .recv_timeout(Duration::from_millis(100))
        .unwrap_or_default();
    let Some(status) = status else {
        return Outcome::broken(format!("timed out after {} s", timeout.as_secs_f64()));
    };
    let Ok(out) = out else {
        return Outcome::broken("the decoder exited but its output stayed open");
    };
    let mut outcome = parse_output(&out);
    if status.code().is_none() {
        outcome.verdict = Verdict::Broken(format!("killed by a signal ({status})"));
    }
    if let Verdict::Broken(why) = &mut outcome.verdict {
        let text = String::from_utf8_lossy(&err);
        if let Some(last) = text.lines().rev().find(|l| !l.trim().is_empty()) {
            let last: String = last.chars().take(80).collect();
            why.push_str(&format!(" [stderr: {}]", last.trim()));
        }
    }
    outcome
}
