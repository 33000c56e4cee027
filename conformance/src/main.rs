//! `splitstream-conformance`: run decoders against the vectors, act as the
//! reference decoder of the protocol, or regenerate the vectors.

use std::io::{Read, Write};
use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Duration;

use clap::{Parser, Subcommand};
use splitstream_conformance::builtin::{self, BUILTINS, run_builtin};
use splitstream_conformance::manifest::{Manifest, default_vector_dir};
use splitstream_conformance::runner::{run_external, run_vectors};
use splitstream_conformance::{generate, protocol::Verdict};

#[derive(Parser)]
#[command(
    name = "splitstream-conformance",
    version,
    about = "splitstream conformance suite: vectors, runner and reference protocol decoder"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Run decoders against every vector: built-in decoders by default, or an
    /// external command speaking the protocol of conformance/README.md.
    Run {
        /// Shell command of a decoder under test (run with `sh -c`, stream on
        /// stdin, protocol lines on stdout).
        #[arg(long, conflicts_with = "builtin")]
        decoder: Option<String>,
        /// Run only this built-in decoder (also test-only ones).
        #[arg(long)]
        builtin: Option<String>,
        /// Vector set directory (holding manifest.json).
        #[arg(long)]
        vectors: Option<PathBuf>,
        /// Seconds an external decoder gets per vector.
        #[arg(long, default_value_t = 20.0)]
        timeout: f64,
        /// Print every vector's row, not only failures (always on for --decoder
        /// and --builtin).
        #[arg(long, short)]
        verbose: bool,
    },
    /// The reference decoder speaking the protocol: reads a stream on stdin,
    /// prints the state hash after the seed mesh and after every round, then
    /// `ok` or `error <class>`.
    Decode,
    /// List the built-in decoders.
    List,
    /// Regenerate the vector set (see conformance/generate.sh).
    Generate {
        /// Output directory (default: the committed set, conformance/vectors/<version>).
        #[arg(long)]
        out: Option<PathBuf>,
        /// Directory of the real meshes fetched by encoder/data/fetch.sh.
        #[arg(long)]
        real_data: Option<PathBuf>,
    },
}

/// `println!` that ignores a closed standard output (`run ... | head`).
macro_rules! say {
    ($($arg:tt)*) => {{
        let mut line = format!($($arg)*);
        line.push('\n');
        let _ = std::io::stdout().lock().write_all(line.as_bytes());
    }};
}

/// `print!` of text that already ends in a newline, ignoring a closed stdout.
fn put(text: &str) {
    let _ = std::io::stdout().lock().write_all(text.as_bytes());
}

fn main() -> ExitCode {
    match run(Cli::parse()) {
        Ok(code) => code,
        Err(e) => {
            eprintln!("splitstream-conformance: error: {e}");
            ExitCode::FAILURE
        }
    }
}

fn run(cli: Cli) -> Result<ExitCode, String> {
    match cli.command {
        Command::Run {
            decoder,
            builtin,
            vectors,
            timeout,
            verbose,
        } => {
            let dir = vectors.unwrap_or_else(default_vector_dir);
            let manifest = Manifest::load(&dir.join("manifest.json"))?;
            say!(
                "splitstream conformance vectors {} ({} vectors) in {}",
                manifest.format_version,
                manifest.vectors.len(),
                dir.display()
            );
            if let Some(command) = decoder {
                if !(timeout > 0.0 && timeout.is_finite()) {
                    return Err("--timeout must be positive".into());
                }
                let limit = Duration::from_secs_f64(timeout);
                let report = run_vectors(&manifest, &dir, |s| run_external(&command, s, limit))?;
                say!("decoder: {command}");
                put(&report.table());
                say!("{}", report.summary());
                return Ok(exit(report.failed() == 0));
            }
            let chosen: Vec<_> = match builtin {
                Some(name) => vec![builtin::find(&name).ok_or_else(|| {
                    let names: Vec<_> = BUILTINS.iter().map(|b| b.name).collect();
                    format!("no built-in decoder {name:?} (have: {})", names.join(", "))
                })?],
                None => BUILTINS.iter().filter(|b| !b.hidden).collect(),
            };
            let single = chosen.len() == 1;
            let mut rows = Vec::new();
            let (mut passed, mut failed) = (0, 0);
            for b in chosen {
                let report = run_vectors(&manifest, &dir, |s| run_builtin(b, s))?;
                if verbose || single {
                    say!("decoder: {} (built-in)", b.name);
                    put(&report.table());
                } else if report.failed() > 0 {
                    let mut failures = report.clone();
                    failures.rows.retain(|r| !r.passed);
                    say!("decoder: {} (built-in), failures:", b.name);
                    put(&failures.table());
                }
                passed += report.passed();
                failed += report.failed();
                rows.push((b.name, report.passed(), report.failed()));
            }
            say!("\n{:<16}  {:>6}  {:>6}", "built-in", "passed", "failed");
            for (name, p, f) in rows {
                say!("{name:<16}  {p:>6}  {f:>6}");
            }
            say!("{passed} passed, {failed} failed");
            Ok(exit(failed == 0))
        }
        Command::Decode => {
            let mut stream = Vec::new();
            std::io::stdin()
                .read_to_end(&mut stream)
                .map_err(|e| format!("reading stdin: {e}"))?;
            let outcome = builtin::decoder_core(&stream);
            let mut out = std::io::stdout().lock();
            out.write_all(outcome.to_protocol().as_bytes())
                .and_then(|_| out.flush())
                .map_err(|e| format!("writing stdout: {e}"))?;
            Ok(exit(outcome.verdict == Verdict::Ok))
        }
        Command::List => {
            for b in BUILTINS {
                let hidden = if b.hidden { " (hidden)" } else { "" };
                say!("{:<16} {}{hidden}", b.name, b.summary);
            }
            Ok(ExitCode::SUCCESS)
        }
        Command::Generate { out, real_data } => {
            let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
            let out = out.unwrap_or_else(default_vector_dir);
            let real = real_data.unwrap_or_else(|| root.join("../encoder/data/real"));
            let generated = generate::generate(&real)?;
            generate::write(&generated, &out)?;
            let bytes: usize = generated.files.values().map(Vec::len).sum();
            say!(
                "wrote {} vectors ({} bytes with the manifest) to {}",
                generated.manifest.vectors.len(),
                bytes,
                out.display()
            );
            Ok(ExitCode::SUCCESS)
        }
    }
}

fn exit(ok: bool) -> ExitCode {
    if ok {
        ExitCode::SUCCESS
    } else {
        ExitCode::FAILURE
    }
}
