//! `splitstream`: encode meshes and terrains into progressive streams, decode,
//! inspect and verify them. Every failure prints one line and exits non-zero.

mod cli;

use std::process::ExitCode;

use clap::Parser;

fn main() -> ExitCode {
    let args = cli::Cli::parse();
    match cli::run(args) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("splitstream: error: {e}");
            ExitCode::FAILURE
        }
    }
}
