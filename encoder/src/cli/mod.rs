//! Command-line definitions and dispatch.

mod bench;
mod coding;
mod decode;
mod demo;
mod encode;
mod gpu_bench;
mod grid;
mod info;
mod output;
mod transcode;
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
    /// One delta and a placement code: the merged vertex on P, C or midway;
    /// axes on the input's own lattice (a raster's x and y) kept exactly.
    /// The smaller stream: 35-37 % below optimal mode on scanned meshes.
    Constrained,
    /// Two deltas per split: the merged vertex anywhere (QEM optimum), for
    /// clients limited by vertex count rather than bytes (coarse levels
    /// 1.3-2.2x more accurate at the same vertex count).
    Optimal,
}

/// How positions are quantized (the stream format is the same either way).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, ValueEnum)]
pub enum QuantizationArg {
    /// Each axis over its own extent: full precision for terrain heights.
    #[default]
    PerAxis,
    /// One step for all axes (the largest extent), as Draco quantizes: for
    /// size comparisons at equal precision.
    Uniform,
}

impl From<QuantizationArg> for splitstream_encoder::quantize::Quantization {
    fn from(q: QuantizationArg) -> Self {
        use splitstream_encoder::quantize::Quantization;
        match q {
            QuantizationArg::PerAxis => Quantization::PerAxis,
            QuantizationArg::Uniform => Quantization::Uniform,
        }
    }
}

/// Whether axes whose coordinates lie on a regular lattice keep it.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, ValueEnum)]
pub enum LatticeArg {
    /// Keep lattices in constrained mode, where positions are input
    /// vertices or midpoints; ignore them in optimal mode.
    #[default]
    Auto,
    /// A raster's x and y (and heights in whole units) quantized exactly on
    /// their lattice whenever it is coarser than the step.
    Keep,
    /// Every axis on the step of --quantization.
    Ignore,
}

impl LatticeArg {
    /// The encoder option (`None`: decided by the position mode).
    pub fn lattice(self) -> Option<splitstream_encoder::quantize::Lattice> {
        use splitstream_encoder::quantize::Lattice;
        match self {
            LatticeArg::Auto => None,
            LatticeArg::Keep => Some(Lattice::Keep),
            LatticeArg::Ignore => Some(Lattice::Ignore),
        }
    }
}

/// Which axis of each position residual the split's plane predicts (SPEC §7.4).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, ValueEnum)]
pub enum PlaneArg {
    /// Per level, the policy whose residuals take fewest bytes.
    #[default]
    Auto,
    Off,
    Dominant,
    X,
    Y,
    Z,
    /// z from the surface of the split vertex's fan at the vector's x and y
    /// (terrain; format 3.1).
    Height,
}

impl PlaneArg {
    pub fn policy(self) -> Option<splitstream_decoder_core::PlanePolicy> {
        use splitstream_decoder_core::PlanePolicy;
        match self {
            PlaneArg::Auto => None,
            PlaneArg::Off => Some(PlanePolicy::Off),
            PlaneArg::Dominant => Some(PlanePolicy::Dominant),
            PlaneArg::X => Some(PlanePolicy::Axis(0)),
            PlaneArg::Y => Some(PlanePolicy::Axis(1)),
            PlaneArg::Z => Some(PlanePolicy::Axis(2)),
            PlaneArg::Height => Some(PlanePolicy::Height),
        }
    }
}

/// How each level names the wings of its splits (SPEC §7.4, format 3.2).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, ValueEnum)]
pub enum WingsArg {
    /// Per level, the policy whose wing ranks take fewest bytes.
    #[default]
    Auto,
    /// Ranks in ring order (readable by every 3.x decoder).
    Ranks,
    /// Ranks in the near order: by distance to the ring's centre (3.2).
    Near,
    /// The near order over x and y only (terrain; 3.2).
    NearXy,
}

impl WingsArg {
    pub fn policy(self) -> Option<splitstream_decoder_core::WingPolicy> {
        use splitstream_decoder_core::WingPolicy;
        match self {
            WingsArg::Auto => None,
            WingsArg::Ranks => Some(WingPolicy::Ranks),
            WingsArg::Near => Some(WingPolicy::Near),
            WingsArg::NearXy => Some(WingPolicy::NearXy),
        }
    }
}

/// Which contexts code each level's split valences (SPEC §5.5.5, format
/// 3.3).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, ValueEnum)]
pub enum DeficitsArg {
    /// Per level, the contexts whose split valences take fewest bytes.
    #[default]
    Auto,
    /// P's in one context, C's by its valence up to 6 (every 3.x decoder).
    Plain,
    /// P's and C's each by its own valence, up to 8 (3.3).
    Valence,
}

impl DeficitsArg {
    pub fn contexts(self) -> Option<splitstream_decoder_core::DeficitContexts> {
        use splitstream_decoder_core::DeficitContexts;
        match self {
            DeficitsArg::Auto => None,
            DeficitsArg::Plain => Some(DeficitContexts::Plain),
            DeficitsArg::Valence => Some(DeficitContexts::Valence),
        }
    }
}

/// Which contexts code each level's flags under the schedule
/// `every-vertex` (SPEC §5.1, §5.5.5).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, ValueEnum)]
pub enum FlagsArg {
    /// `split-history`, or on a small level the smaller of the two.
    #[default]
    Auto,
    /// By the vertex's valence (3.6).
    Valence,
    /// By the vertex's valence and whether it has split in the level
    /// (3.10).
    SplitHistory,
}

impl FlagsArg {
    pub fn contexts(self) -> Option<splitstream_decoder_core::DeficitContexts> {
        use splitstream_decoder_core::DeficitContexts;
        match self {
            FlagsArg::Auto => None,
            FlagsArg::Valence => Some(DeficitContexts::Plain),
            FlagsArg::SplitHistory => Some(DeficitContexts::SplitHistory),
        }
    }
}

/// How each level reads its split records (SPEC §5.1, §7.4, format 3.7).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, ValueEnum)]
pub enum RecordsArg {
    /// Per level, positions first where it is allowed and smaller.
    #[default]
    Auto,
    /// The wings first (every 3.x decoder; the fastest to decode).
    WingsFirst,
    /// The new vertex first, as a rank among its fan's free lattice points
    /// (rasters on their lattice, constrained mode; 3.7).
    PositionsFirst,
}

impl RecordsArg {
    pub fn order(self) -> Option<splitstream_decoder_core::RecordOrder> {
        use splitstream_decoder_core::RecordOrder;
        match self {
            RecordsArg::Auto => None,
            RecordsArg::WingsFirst => Some(RecordOrder::WingsFirst),
            RecordsArg::PositionsFirst => Some(RecordOrder::PositionsFirst),
        }
    }
}

/// How a positions-first level breaks its wing choices' ties (SPEC §5.1,
/// §7.4; format 3.8).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, ValueEnum)]
pub enum TiesArg {
    /// Per level, the rule whose wings code smallest.
    #[default]
    Auto,
    /// By ring position alone (3.7).
    Ring,
    /// Fewer new edges along the falling diagonal first: cells split along
    /// the rising one.
    Rising,
    /// Fewer new edges along the rising diagonal first.
    Falling,
}

impl TiesArg {
    pub fn ties(self) -> Option<splitstream_decoder_core::Ties> {
        use splitstream_decoder_core::Ties;
        match self {
            TiesArg::Auto => None,
            TiesArg::Ring => Some(Ties::Ring),
            TiesArg::Rising => Some(Ties::Rising),
            TiesArg::Falling => Some(Ties::Falling),
        }
    }
}

/// How a stream says which vertices split in which round (SPEC §3.2).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, ValueEnum)]
pub enum ScheduleArg {
    /// A flag for every vertex, in contexts by its valence (format 3.6).
    #[default]
    EveryVertex,
    /// The paper's split valences, with flags for the candidates they make
    /// (every 3.x decoder).
    SplitValences,
}

impl From<ScheduleArg> for splitstream_decoder_core::Schedule {
    fn from(s: ScheduleArg) -> Self {
        use splitstream_decoder_core::Schedule;
        match s {
            ScheduleArg::EveryVertex => Schedule::EveryVertex,
            ScheduleArg::SplitValences => Schedule::SplitValences,
        }
    }
}

/// Where the simplifier's data-parallel passes run.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, ValueEnum)]
pub enum BackendArg {
    /// CPU threads (rayon), f64.
    #[default]
    Cpu,
    /// WGSL kernels through wgpu (Vulkan, Metal, DX12); topology on the CPU.
    Wgpu,
    /// OpenCL C kernels through ocl; topology on the CPU.
    Opencl,
}

impl From<BackendArg> for splitstream_encoder::simplify::Backend {
    fn from(b: BackendArg) -> Self {
        use splitstream_encoder::simplify::Backend;
        match b {
            BackendArg::Cpu => Backend::Cpu,
            BackendArg::Wgpu => Backend::Wgpu,
            BackendArg::Opencl => Backend::OpenCl,
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum Codec {
    /// Context-modelled rANS (SPEC §5.5), deflate where that is smaller.
    Rans,
    Deflate,
    Stored,
}

#[derive(Subcommand)]
pub enum Command {
    /// Encode a mesh (.ply .obj .off .gltf .glb .stl) or elevation grid (.tif
    /// .asc .npy .npz).
    Encode(encode::Args),
    /// Write a stream again from its own refinement, without the input
    /// mesh: another codec, lane count or chunk size (smaller stored and
    /// deflate chunks, less decoder memory), each level's coding chosen
    /// again (older streams get the newest); the same state after every
    /// round.
    Transcode(transcode::Args),
    /// Decode a stream to .ply, .obj or .glb, in decoded vertex order.
    Decode {
        input: PathBuf,
        #[arg(short, long)]
        output: PathBuf,
        /// Stop after this level (0 = base mesh).
        #[arg(long)]
        level: Option<u16>,
        /// Decode the levels whose bytes are all in the file and stop
        /// before the first one cut off (a prefix of the stream, as fetched
        /// with range requests), instead of failing on a truncated file.
        #[arg(long)]
        available: bool,
        /// 2 (the default): read a large level's split records on a second
        /// thread while the rounds run on this one (sdk-native `threaded`;
        /// a level under 4,096 splits, or a machine with one core, decodes
        /// on one); 1: everything on this thread. The same mesh either way.
        #[arg(long, default_value_t = 2)]
        threads: u32,
    },
    /// Header, level table (with the decoder memory each prefix of levels
    /// needs), bits and chunks per field, bits per vertex.
    Info {
        input: PathBuf,
        #[arg(long)]
        json: bool,
        /// Also code the stream again with rANS and with deflate (as
        /// `transcode` would, nothing written) and give every field's bits
        /// per vertex under each.
        #[arg(long)]
        codecs: bool,
        /// Also give each field's bytes in each level (`--json` always
        /// has them, as each level's `field_bytes`).
        #[arg(long)]
        by_level: bool,
    },
    /// Decode fully, checking every checksum and rule; print the state hash.
    Verify { input: PathBuf },
    /// Measure the encoder's goals: bits per vertex, quality and speed
    /// against the sequential baseline, throughput (see encoder/BENCHMARKS.md).
    Bench(bench::Settings),
    /// Time the simplifier's backends (cpu, sequential baseline, wgpu,
    /// opencl) on the 1M and 4M vertex fractal terrains in one run, each
    /// stream checked by decoding it; ratios from the same run.
    GpuBench(gpu_bench::Settings),
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
        /// How the stream says which vertices split in which round (SPEC
        /// §3.2; as `encode --schedule`).
        #[arg(long, value_enum, default_value_t = ScheduleArg::EveryVertex)]
        schedule: ScheduleArg,
        /// How each level reads its split records (as `encode --records`).
        #[arg(long, value_enum, default_value_t = RecordsArg::Auto)]
        records: RecordsArg,
    },
}

pub fn run(cli: Cli) -> CliResult {
    match cli.command {
        Command::Encode(args) => encode::run(args),
        Command::Transcode(args) => transcode::run(args),
        Command::Decode {
            input,
            output,
            level,
            available,
            threads,
        } => decode::run(
            &input,
            &output,
            decode::DecodeOptions {
                level,
                available,
                threads,
            },
        ),
        Command::Info {
            input,
            json,
            codecs,
            by_level,
        } => info::run(
            &input,
            info::InfoOptions {
                json,
                codecs,
                by_level,
            },
        ),
        Command::Verify { input } => verify::run(&input),
        Command::Bench(settings) => bench::run(&settings),
        Command::GpuBench(settings) => gpu_bench::run(&settings),
        Command::Grid(args) => grid::run(args),
        Command::Demo {
            side,
            output,
            schedule,
            records,
        } => demo::run(side, output.as_deref(), schedule.into(), records.order()),
    }
}

/// Reads a whole file, naming it in the error.
pub fn read_file(path: &std::path::Path) -> Result<Vec<u8>, String> {
    std::fs::read(path).map_err(|e| format!("{}: {e}", path.display()))
}
