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
    Encode {
        input: PathBuf,
        #[arg(short, long)]
        output: PathBuf,
        /// Quantization bits per axis (1..=31).
        #[arg(long, default_value_t = 14)]
        bits: u8,
        /// Levels of detail, base mesh included.
        #[arg(long, default_value_t = 5)]
        levels: usize,
        /// Base mesh vertex count (default: vertices / 2^(levels-1)).
        #[arg(long)]
        base_vertices: Option<usize>,
        #[arg(long, value_enum, default_value_t = Position::Optimal)]
        position: Position,
        /// Largest quadric error a collapse may have.
        #[arg(long)]
        max_error: Option<f64>,
        #[arg(long, value_enum, default_value_t = Codec::Deflate)]
        codec: Codec,
        /// Largest raw chunk in bytes (bounds decoder buffers).
        #[arg(long, default_value_t = 16384)]
        chunk_size: u32,
        /// Keep boundary vertices in place (patch borders).
        #[arg(long)]
        lock_boundary: bool,
        /// Fix what the checker rejects: drop degenerate/duplicate triangles,
        /// reorient, split non-manifold vertices.
        #[arg(long)]
        repair: bool,
        /// Write the input vertex id of each decoded vertex, one per line.
        #[arg(long)]
        permutation: Option<PathBuf>,
        /// .npz only: the array with the elevations.
        #[arg(long)]
        npz_array: Option<String>,
        /// Multiply z by this (e.g. to match x/y units).
        #[arg(long, default_value_t = 1.0)]
        z_scale: f64,
        /// Fraction of candidate collapses admitted per step (0..1].
        #[arg(long, default_value_t = 0.5)]
        admit: f64,
        /// x and y are longitude and latitude in degrees (z in metres):
        /// errors are measured in metres.
        #[arg(long)]
        geographic: bool,
    },
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
    Bench {
        /// Folder with the real inputs (encoder/data/fetch.sh).
        #[arg(long, default_value = "encoder/data/real")]
        data: PathBuf,
        /// Side of the synthetic terrain for the throughput figures.
        #[arg(long, default_value_t = 1000)]
        terrain_side: usize,
        /// Only sizes and throughput.
        #[arg(long)]
        skip_quality: bool,
        /// Fraction of candidate collapses admitted per step (0..1].
        #[arg(long, default_value_t = 0.5)]
        admit: f64,
        /// Only inputs whose name contains this.
        #[arg(long)]
        only: Option<String>,
        /// Skip the synthetic-terrain throughput run.
        #[arg(long)]
        skip_throughput: bool,
    },
    /// Simplify an elevation grid (.tif .asc .npy .npz) as one tile on the
    /// client side: quad-tree split/merge with edge straightening, threshold
    /// min(H/800, Res/25); print facets before/after and the max vertical
    /// error; write the mesh.
    Grid {
        input: PathBuf,
        /// Viewing height H, in the units of the elevations.
        #[arg(long, allow_negative_numbers = true)]
        height: f64,
        /// Resolution of the neighbouring tile on each side, N,E,S,W (a
        /// number or - for none; in the units of the spacing, metres with
        /// --geographic); a coarser one sets that border's threshold.
        #[arg(long)]
        neighbour_res: Option<String>,
        #[arg(short, long)]
        output: Option<PathBuf>,
        /// x and y are longitude and latitude in degrees: convert the
        /// spacing to metres (~111 km per degree, times cos(latitude) for x).
        #[arg(long)]
        geographic: bool,
        /// .npz only: the array with the elevations.
        #[arg(long)]
        npz_array: Option<String>,
        /// Multiply z by this.
        #[arg(long, default_value_t = 1.0)]
        z_scale: f64,
        /// Keep a leftover border corner when removing it would cost more
        /// than 2 T (a T-junction exactly on the neighbour's edge).
        #[arg(long)]
        bounded_border: bool,
        /// Cut tiles of this many cells a side, time them and compare with
        /// QEM at the same triangle count (see encoder/BENCHMARKS.md).
        #[arg(long)]
        bench: Option<usize>,
    },
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
        Command::Encode {
            input,
            output,
            bits,
            levels,
            base_vertices,
            position,
            max_error,
            codec,
            chunk_size,
            lock_boundary,
            repair,
            permutation,
            npz_array,
            z_scale,
            admit,
            geographic,
        } => encode::run(encode::Args {
            input,
            output,
            bits,
            levels,
            base_vertices,
            position,
            max_error,
            codec,
            chunk_size,
            lock_boundary,
            repair,
            permutation,
            npz_array,
            z_scale,
            admit,
            geographic,
        }),
        Command::Decode {
            input,
            output,
            level,
        } => decode::run(&input, &output, level),
        Command::Info { input, json } => info::run(&input, json),
        Command::Verify { input } => verify::run(&input),
        Command::Bench {
            data,
            terrain_side,
            skip_quality,
            admit,
            only,
            skip_throughput,
        } => bench::run(&bench::Settings {
            data,
            terrain_side,
            skip_quality,
            admit,
            only,
            skip_throughput,
        }),
        Command::Grid {
            input,
            height,
            neighbour_res,
            output,
            geographic,
            npz_array,
            z_scale,
            bounded_border,
            bench,
        } => grid::run(grid::Args {
            input,
            height,
            neighbour_res,
            output,
            geographic,
            npz_array,
            z_scale,
            bounded_border,
            bench,
        }),
        Command::Demo { side, output } => demo::run(side, output.as_deref()),
    }
}

/// Reads a whole file, naming it in the error.
pub fn read_file(path: &std::path::Path) -> Result<Vec<u8>, String> {
    std::fs::read(path).map_err(|e| format!("{}: {e}", path.display()))
}
