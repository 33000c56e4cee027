//! Command-line definitions and dispatch.

mod bench;
mod decode;
mod demo;
mod encode;
mod grid;
mod info;
mod output;
mod verify;

use std::path::PathBuf;

use clap::{Parser, Subcommand, ValueEnum};

/// One-line errors for the command line.
pub type CliResult = Result<(), String>;

#[derive(Parser)]
#[command(
    name = "splitstream",
    version,
    about = "Progressive streaming of terrain and 3D meshes"
)]
pub struct Cli {
    #[command(subcommand)]
    pub command: Command,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum Position {
    /// Two deltas per split: the merged vertex anywhere (QEM optimum).
    Optimal,
    /// One delta and a placement code: the merged vertex on P, C or midway.
    Constrained,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum Codec {
    Deflate,
    Stored,
}

#[derive(Subcommand)]
pub enum Command {
    /// Encode a mesh (.ply .obj .off) or elevation grid (.tif .asc .npy .npz).
    Encode(encode::Args),
    /// Decode a stream to .ply or .obj, in decoded vertex order.
    Decode {
        input: PathBuf,
        #[arg(short, long)]
        output: PathBuf,
        /// Stop after this level (0 = base mesh).
        #[arg(long)]
        level: Option<u16>,
    },
    /// Header, level table, bits per field and per vertex, decoder memory.
    Info {
        input: PathBuf,
        #[arg(long)]
        json: bool,
    },
    /// Decode fully, checking every checksum and rule; print the state hash.
    Verify { input: PathBuf },
    /// Measure the encoder's goals: bits per vertex, quality and speed
    /// against the sequential baseline, throughput (see encoder/BENCHMARKS.md).
    Bench(bench::Settings),
    /// Simplify an elevation grid (.tif .asc .npy .npz) as one tile on the
    /// client side: quad-tree split/merge with edge straightening, threshold
    /// min(H/800, Res/25); print facets before/after and the max vertical
    /// error; write the mesh.
    Grid(grid::Args),
    /// The main job on a built-in default: generate a terrain, encode it,
    /// decode it level by level and print the level table.
    Demo {
        /// Side of the generated square terrain, in samples.
        #[arg(long, default_value_t = 512)]
        side: usize,
        /// Also write the stream here.
        #[arg(short, long)]
        output: Option<PathBuf>,
    },
}

pub fn run(cli: Cli) -> CliResult {
    match cli.command {
        Command::Encode(args) => encode::run(args),
        Command::Decode {
            input,
            output,
            level,
        } => decode::run(&input, &output, level),
        Command::Info { input, json } => info::run(&input, json),
        Command::Verify { input } => verify::run(&input),
        Command::Bench(settings) => bench::run(&settings),
        Command::Grid(args) => grid::run(args),
        Command::Demo { side, output } => demo::run(side, output.as_deref()),
    }
}

/// Reads a whole file, naming it in the error.
pub fn read_file(path: &std::path::Path) -> Result<Vec<u8>, String> {
    std::fs::read(path).map_err(|e| format!("{}: {e}", path.display()))
}
