//! `splitstream encode`.

use std::path::PathBuf;
use std::time::Instant;

use indicatif::{ProgressBar, ProgressStyle};
use splitstream_decoder_core::PositionMode;
use splitstream_encoder::Mesh;
use splitstream_encoder::emit::{EncodeError, EncodeOptions, SEED_VERTICES, encode};
use splitstream_encoder::input::{ReadOptions, read_mesh, repair_mesh};
use splitstream_encoder::quantize::{Quantization, Units};

use super::coding::CodingArgs;
use super::output::check_stream_output;
use super::{BackendArg, CliResult, LatticeArg, Position, QuantizationArg};

/// `splitstream encode`'s arguments.
#[derive(clap::Args)]
pub struct Args {
    pub input: PathBuf,
    #[arg(short, long)]
    pub output: PathBuf,
    /// Quantization bits per axis (1..=31).
    #[arg(long, default_value_t = 14, value_parser = clap::value_parser!(u8).range(1..=31))]
    pub bits: u8,
    /// Levels of detail, base mesh included.
    #[arg(long, default_value_t = 5)]
    pub levels: usize,
    /// Base mesh vertex count (default: vertices / 2^(levels-1); no effect
    /// with one level).
    #[arg(long)]
    pub base_vertices: Option<usize>,
    #[arg(long, value_enum, default_value_t = Position::Constrained)]
    pub position: Position,
    /// Largest quadric error a collapse may have (0 or more).
    // A negative value is read as one (and refused with its reason), not
    // as an unknown flag.
    #[arg(long, allow_negative_numbers = true)]
    pub max_error: Option<f64>,
    #[command(flatten)]
    pub coding: CodingArgs,
    /// Keep boundary vertices in place (patch borders).
    #[arg(long)]
    pub lock_boundary: bool,
    /// Fix what the checker rejects: drop degenerate/duplicate triangles,
    /// reorient, split non-manifold vertices.
    #[arg(long)]
    pub repair: bool,
    /// Write the input vertex id of each decoded vertex, one per line: the
    /// 0-based index of its vertex in the file (PLY, OBJ, OFF), of its
    /// welded position (glTF, STL: the vertices at one position are one),
    /// or of its grid sample, row by row from the southern row; after
    /// --repair, or on a grid with missing samples, an index into the mesh
    /// as repaired or as triangulated.
    #[arg(long)]
    pub permutation: Option<PathBuf>,
    /// .npz only: the array with the elevations (default: the first 2-D
    /// array not named as coordinates). Scalars dx, dy, xmin, ymin (xmax,
    /// ymax) or coordinate arrays x/lon/longitude and y/lat/latitude (1-D,
    /// or 2-D as np.meshgrid writes them) place the samples.
    #[arg(long)]
    pub npz_array: Option<String>,
    /// Multiply z by this (e.g. to match x/y units).
    #[arg(long, default_value_t = 1.0, allow_negative_numbers = true)]
    pub z_scale: f64,
    /// Fraction of candidate collapses admitted per step (0..1].
    #[arg(long, default_value_t = 0.5, allow_negative_numbers = true)]
    pub admit: f64,
    /// x and y are longitude and latitude in degrees (z in metres):
    /// errors are measured in metres.
    #[arg(long)]
    pub geographic: bool,
    /// One quantization step per axis (default), or one for all axes (in
    /// metres with --geographic), as Draco does at the same bit count.
    #[arg(long, value_enum, default_value_t = QuantizationArg::PerAxis)]
    pub quantization: QuantizationArg,
    /// Axes whose coordinates all lie on a regular lattice coarser than the
    /// step (a raster's x and y, heights in whole metres) are quantized on
    /// it, exactly: smaller streams for terrain. `auto` keeps them in
    /// constrained mode only.
    #[arg(long, value_enum, default_value_t = LatticeArg::Auto)]
    pub lattice: LatticeArg,
    /// Where the simplification's data-parallel passes run (GPU backends:
    /// quadrics, best edges and selection on the device, collapses on the CPU).
    #[arg(long, value_enum, default_value_t = BackendArg::Cpu)]
    pub backend: BackendArg,
}

pub fn run(a: Args) -> CliResult {
    // The options do not depend on the input: checked by the library's
    // rules (`EncodeOptions::check`) before anything is read.
    let options = EncodeOptions {
        bits: a.bits,
        levels: a.levels,
        base_vertices: a.base_vertices,
        position_mode: match a.position {
            Position::Optimal => PositionMode::Optimal,
            Position::Constrained => PositionMode::Constrained,
        },
        max_error: a.max_error,
        lock_boundary: a.lock_boundary,
        admit_quantile: a.admit,
        units: if a.geographic {
            Units::Geographic
        } else {
            Units::Linear
        },
        quantization: a.quantization.into(),
        lattice: a.lattice.lattice(),
        backend: a.backend.into(),
        ..EncodeOptions::default()
    }
    // The lane count of a mesh whose size is not known yet; set again
    // below, once it is.
    .with_coding(a.coding.options(usize::MAX));
    a.coding.check()?;
    options.check().map_err(|e| e.to_string())?;
    check_stream_output(&a.output, Some(&a.input))?;
    // As `grid` checks it: a NaN scale was reported as the file's first
    // vertex having a non-finite coordinate.
    if !(a.z_scale.is_finite() && a.z_scale != 0.0) {
        return Err(format!(
            "--z-scale {} must be finite and non-zero",
            a.z_scale
        ));
    }
    if options.levels == 1 && options.base_vertices.is_some() {
        eprintln!(
            "note: --base-vertices has no effect with --levels 1: the one level holds the whole mesh"
        );
    }
    let started = Instant::now();
    let read = ReadOptions {
        npz_array: a.npz_array.clone(),
        z_scale: a.z_scale,
        ..ReadOptions::default()
    };
    let mut mesh = read_mesh(&a.input, &read).map_err(|e| e.to_string())?;
    if a.repair {
        let (fixed, report) = repair_mesh(&mesh);
        eprintln!("repair: {report}");
        mesh = fixed;
    }
    // The mesh is checked by `encode` (check_mesh, before anything else).
    let read_seconds = started.elapsed().as_secs_f64();
    let degrees_unconverted = !a.geographic && looks_geographic(&mesh);
    if degrees_unconverted {
        eprintln!(
            "note: x and y look like longitude/latitude in degrees; pass --geographic to measure errors in metres"
        );
    }
    let n = mesh.positions.len();
    let options = options.with_coding(a.coding.options(n));
    let bar = ProgressBar::new(n as u64);
    bar.set_style(
        ProgressStyle::with_template("{msg} [{bar:40}] {pos}/{len} collapses")
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    bar.set_message("simplifying");
    let progress = |done| bar.set_position(done as u64);
    let result = encode(&mesh, &options, progress);
    bar.finish_and_clear();
    let encoded = result.map_err(|e| match e {
        EncodeError::Input(e) => format!("{}: {e}", a.input.display()),
        e => e.to_string(),
    })?;
    let stats = encoded.input;
    if encoded.rounds == 0 && n > SEED_VERTICES {
        // Seen on a DEM in degrees quantized with one step for degrees and
        // metres, until a triangle without a normal was allowed to keep none
        // (`simplify::check`): x and y fell on a handful of steps, every
        // triangle was degenerate and no collapse passed its checks.
        let hint = if degrees_unconverted && options.quantization == Quantization::Uniform {
            "with --quantization uniform, x and y in degrees fall on a few steps of the height's \
             scale and every triangle degenerates: pass --geographic, or use --quantization per-axis"
        } else if options.max_error.is_some_and(|e| e <= 0.0) {
            // `--max-error 0` admits only collapses without any error.
            "--max-error 0 admits only collapses that cost no error"
        } else {
            "the quantized mesh may be degenerate: try more --bits"
        };
        eprintln!(
            "note: no collapse passed its checks, so the stream holds the whole mesh in level 0 ({hint})"
        );
    }
    std::fs::write(&a.output, &encoded.stream)
        .map_err(|e| format!("{}: {e}", a.output.display()))?;
    if let Some(path) = &a.permutation {
        let text: String = encoded
            .permutation
            .iter()
            .map(|v| format!("{v}\n"))
            .collect();
        std::fs::write(path, text).map_err(|e| format!("{}: {e}", path.display()))?;
    }
    let bytes = encoded.stream.len();
    println!(
        "{}: {} vertices, {} triangles ({} boundary edges) -> {} bytes, {:.2} bits/vertex, {} levels, {} rounds",
        a.output.display(),
        n,
        stats.triangles,
        stats.boundary_edges,
        bytes,
        8.0 * bytes as f64 / n as f64,
        encoded.level_vertex_counts.len(),
        encoded.rounds,
    );
    println!(
        "{}",
        positions_line(options.position_mode, encoded.on_lattice)
    );
    println!(
        "time: read {:.2} s, check {:.2} s, simplify {:.2} s, emit {:.2} s",
        read_seconds, encoded.check_seconds, encoded.simplify_seconds, encoded.emit_seconds
    );
    Ok(())
}

/// `positions: MODE[; AXES on the input's own lattice (exact)]`, the line
/// `encode` and `demo` print about positions.
pub fn positions_line(mode: PositionMode, on_lattice: [bool; 3]) -> String {
    let mode = match mode {
        PositionMode::Optimal => "optimal",
        PositionMode::Constrained => "constrained",
    };
    let exact = lattice_axes(on_lattice);
    if exact.is_empty() {
        format!("positions: {mode}")
    } else {
        format!("positions: {mode}; {exact} on the input's own lattice (exact)")
    }
}

/// The names of the axes on their lattice, as "x, y" ("" when none).
pub fn lattice_axes(on_lattice: [bool; 3]) -> String {
    let names: Vec<&str> = ["x", "y", "z"]
        .into_iter()
        .zip(on_lattice)
        .filter_map(|(name, on)| on.then_some(name))
        .collect();
    names.join(", ")
}

/// Degrees-sized x/y extents inside lon/lat ranges (longitudes from -180
/// to 180 or from 0 to 360, as matplotlib's topobathy.npz has them) next to
/// a z range in the hundreds: a geographic grid whose errors would be
/// meaningless in raw units.
fn looks_geographic(mesh: &Mesh) -> bool {
    let Some((lo, hi)) = mesh.bounding_box() else {
        return false;
    };
    let xy = (hi[0] - lo[0]).max(hi[1] - lo[1]);
    lo[0] >= -180.0
        && hi[0] <= 360.0
        && lo[1] >= -90.0
        && hi[1] <= 90.0
        && xy < 5.0
        && hi[2] - lo[2] > 50.0 * xy
}
