//! `splitstream bench`: the encoder's measured goals in one run — bits per
//! vertex, quality and speed against the sequential baseline, throughput.
//! Figures go to BENCHMARKS.md with the machine and date.

use std::path::Path;
use std::time::Instant;

use splitstream_decoder_core::PositionMode;
use splitstream_decoder_core::owned::OwnedWorkspace;
use splitstream_decoder_core::writer::ChunkCodec;
use splitstream_encoder::Mesh;
use splitstream_encoder::baseline::{BaselineOptions, simplify_sequential};
use splitstream_encoder::emit::{EncodeOptions, encode, lanes_for};
use splitstream_encoder::input::{ReadOptions, check_mesh, fractal_terrain, read_mesh};
use splitstream_encoder::metrics::{DistanceReport, surface_distance};
use splitstream_encoder::quantize::{Quantization, QuantizedMesh, Units, quantize};
use splitstream_encoder::simplify::{
    Backend, Checked, Simplification, SimplifyOptions, simplify_on,
};
use splitstream_encoder::spatial_order::spatially_ordered;

use super::info::{field_sizes, is_geometry};
use super::output::write_mesh;
use super::{BackendArg, CliResult};

const SAMPLES: usize = 200_000;

struct Input {
    name: &'static str,
    file: &'static str,
    units: Units,
}

const INPUTS: [Input; 6] = [
    Input {
        name: "armadillo",
        file: "armadillo.off",
        units: Units::Linear,
    },
    Input {
        name: "bunny00",
        file: "bunny00.off",
        units: Units::Linear,
    },
    Input {
        name: "refined_elephant",
        file: "refined_elephant.off",
        units: Units::Linear,
    },
    Input {
        name: "dragon",
        file: "dragon_vrip.ply",
        units: Units::Linear,
    },
    Input {
        name: "jacksboro DEM",
        file: "jacksboro_fault_dem.npz",
        units: Units::Geographic,
    },
    // matplotlib's second sample raster: 91 x 120 samples, land and sea
    // floor, its longitudes and latitudes in the file.
    Input {
        name: "topobathy DEM",
        file: "topobathy.npz",
        units: Units::Geographic,
    },
];

/// `splitstream bench`'s arguments.
#[derive(clap::Args)]
pub struct Settings {
    /// Folder with the real inputs (encoder/data/fetch.sh).
    #[arg(long, default_value = "encoder/data/real")]
    pub data: std::path::PathBuf,
    /// Side of the synthetic terrain for the throughput figures.
    #[arg(long, default_value_t = 1000)]
    pub terrain_side: usize,
    /// Only sizes and throughput.
    #[arg(long)]
    pub skip_quality: bool,
    /// Fraction of candidate collapses admitted per step (0..1].
    #[arg(long, default_value_t = 0.5, allow_negative_numbers = true)]
    pub admit: f64,
    /// Only inputs whose name contains this (one that matches none, such
    /// as `none`, leaves the throughput run alone).
    #[arg(long)]
    pub only: Option<String>,
    /// Skip the synthetic-terrain throughput run.
    #[arg(long)]
    pub skip_throughput: bool,
    /// Where the parallel simplifier's data-parallel passes run.
    #[arg(long, value_enum, default_value_t = BackendArg::Cpu)]
    pub backend: BackendArg,
    /// Also write each quality row's meshes to this folder as PLY, in the
    /// frame the distances are measured in (the quantized input in metric
    /// units, origin at the quantization origin): `INPUT-PERCENT-reference`,
    /// `-parallel` and `-sequential`, to look at where the farthest samples
    /// lie.
    #[arg(long, value_name = "DIR")]
    pub dump: Option<std::path::PathBuf>,
}

pub fn run(settings: &Settings) -> CliResult {
    let data: &Path = &settings.data;
    let admit = settings.admit;
    // Every argument is checked before the report's first line (the
    // terrain's side as `demo --side` checks it: an unchecked side aborted
    // on a failed allocation or overflowed the grid's size).
    if !(admit > 0.0 && admit <= 1.0) {
        return Err(format!("--admit {admit} is outside (0, 1]"));
    }
    if !settings.skip_throughput && !(2..=4096).contains(&settings.terrain_side) {
        return Err(format!(
            "--terrain-side {} is outside 2..=4096",
            settings.terrain_side
        ));
    }
    let reads_inputs = settings
        .only
        .as_ref()
        .is_none_or(|only| INPUTS.iter().any(|i| i.name.contains(only.as_str())));
    if reads_inputs && !data.is_dir() {
        return Err(format!(
            "--data {}: no such folder (run encoder/data/fetch.sh, or name the folder of the real inputs)",
            data.display()
        ));
    }
    let backend: Backend = settings.backend.into();
    let simplify_options = |target: usize, max_error: Option<f64>| SimplifyOptions {
        target_vertices: target,
        max_error,
        admit_quantile: admit,
        ..SimplifyOptions::default()
    };
    if let Some(only) = &settings.only
        && !INPUTS.iter().any(|i| i.name.contains(only.as_str()))
    {
        // Not an error: `--only none` is how the throughput runs alone.
        let names: Vec<&str> = INPUTS.iter().map(|i| i.name).collect();
        eprintln!(
            "note: --only {only} matches no input ({}): no size or quality rows",
            names.join(", ")
        );
    }
    println!("# splitstream encoder benchmark\n");
    println!("## Stream size (5 levels, 14-bit positions), bits per vertex\n");
    println!(
        "| input | vertices | mode | codec | quantization | total | connectivity | geometry | rounds | encode s | decode ms | M splits/s |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|---|---|");
    let mut loaded = Vec::new();
    for input in INPUTS.iter().filter(|i| {
        settings
            .only
            .as_ref()
            .is_none_or(|o| i.name.contains(o.as_str()))
    }) {
        let path = data.join(input.file);
        if !path.exists() {
            println!(
                "| {} | skipped: run encoder/data/fetch.sh | | | | | | | | | | |",
                input.name
            );
            continue;
        }
        let mesh = read_mesh(&path, &ReadOptions::default()).map_err(|e| e.to_string())?;
        check_mesh(&mesh).map_err(|e| format!("{}: {e}", path.display()))?;
        // Per-axis steps are the encoder's default; one step for all axes
        // is what Draco does at the same bit count (fair comparisons).
        for mode in [PositionMode::Optimal, PositionMode::Constrained] {
            for quantization in [Quantization::PerAxis, Quantization::Uniform] {
                // The lanes `splitstream encode` writes for this mesh.
                let lanes = lanes_for(mesh.positions.len());
                for codec in [ChunkCodec::Rans { lanes }, ChunkCodec::Deflate(9)] {
                    size_row(
                        input.name,
                        &mesh,
                        input.units,
                        (mode, codec, quantization),
                        admit,
                        backend,
                    )?;
                }
            }
        }
        loaded.push((input, mesh));
    }
    if !settings.skip_quality {
        println!(
            "\n## Quality against the sequential baseline (same quadrics), symmetric distances in % of the bounding-box diagonal\n"
        );
        println!(
            "| input | target | parallel Hausdorff | sequential Hausdorff | ratio | parallel RMS | sequential RMS | ratio | parallel s | sequential s | speed-up |"
        );
        println!("|---|---|---|---|---|---|---|---|---|---|---|");
        if let Some(dir) = &settings.dump {
            std::fs::create_dir_all(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
        }
        let mut farthest = Vec::new();
        for (input, mesh) in &loaded {
            for fraction in [0.25, 0.0625] {
                let row = QualityRow {
                    input,
                    mesh,
                    fraction,
                    dump: settings.dump.as_deref(),
                };
                farthest.push(quality_row(&row, &simplify_options, backend)?);
            }
        }
        println!(
            "\n### The largest distances: 99.9th percentile of the samples (% of the diagonal) and the farthest sample (metric frame, origin at the quantization origin; on which surface)\n"
        );
        println!(
            "| input | target | parallel 99.9 % | sequential 99.9 % | ratio | parallel farthest | sequential farthest |"
        );
        println!("|---|---|---|---|---|---|---|");
        for line in farthest {
            println!("{line}");
        }
        println!("\n## Vertices kept at the same maximum quadric error\n");
        println!(
            "| input | max error (from the parallel run to 6.25 %) | parallel vertices | sequential vertices | extra |"
        );
        println!("|---|---|---|---|---|");
        for (input, mesh) in &loaded {
            equal_error_row(input, mesh, &simplify_options, backend)?;
        }
    }
    if !settings.skip_throughput {
        let side = settings.terrain_side;
        println!("\n## Throughput on the synthetic {side}x{side} terrain\n");
        throughput(side, admit, backend)?;
    }
    Ok(())
}

fn size_row(
    name: &str,
    mesh: &Mesh,
    units: Units,
    (mode, codec, quantization): (PositionMode, ChunkCodec, Quantization),
    admit: f64,
    backend: Backend,
) -> CliResult {
    let options = EncodeOptions {
        position_mode: mode,
        codec,
        units,
        quantization,
        admit_quantile: admit,
        backend,
        ..EncodeOptions::default()
    };
    let t = Instant::now();
    let encoded = encode(mesh, &options, |_| {}).map_err(|e| e.to_string())?;
    let seconds = t.elapsed().as_secs_f64();
    let stream = &encoded.stream;
    let header = splitstream_decoder_core::Header::parse(stream).map_err(|e| e.to_string())?;
    let table =
        splitstream_decoder_core::LevelTable::parse(stream, &header).map_err(|e| e.to_string())?;
    let sizes = field_sizes(stream, &header, &table)?;
    let n = mesh.positions.len() as f64;
    let bpv = |b: u64| 8.0 * b as f64 / n;
    let fields = sizes.stored.len();
    let connectivity: u64 = (1..fields)
        .filter(|&i| !is_geometry(i))
        .map(|i| sizes.stored[i])
        .sum();
    let geometry: u64 = (1..fields)
        .filter(|&i| is_geometry(i))
        .map(|i| sizes.stored[i])
        .sum();
    let decode_ms = median_decode_ms(stream)?;
    // Every vertex but the seed's comes from a split.
    let level0 = table.get(0);
    let level0 = &stream[level0.offset as usize..(level0.offset + level0.length as u64) as usize];
    let seed = splitstream_decoder_core::LevelHeader::parse(level0, true, header.level_rules())
        .map_err(|e| e.to_string())?
        .seed_vertices;
    let splits = (header.vertex_capacity - seed) as f64;
    println!(
        "| {name} | {} | {} | {} | {} | {:.2} | {:.2} | {:.2} | {} | {:.2} | {:.1} | {:.2} |",
        mesh.positions.len(),
        if mode == PositionMode::Optimal {
            "optimal"
        } else {
            "constrained"
        },
        match codec {
            ChunkCodec::Deflate(_) => "deflate",
            ChunkCodec::Stored => "stored",
            _ => "rans",
        },
        {
            let how = match quantization {
                Quantization::PerAxis => "per-axis",
                Quantization::Uniform => "uniform",
            };
            match super::encode::lattice_axes(encoded.on_lattice).as_str() {
                "" => how.to_string(),
                axes => format!("{how}, lattice {axes}"),
            }
        },
        bpv(stream.len() as u64),
        bpv(connectivity),
        bpv(geometry),
        encoded.rounds,
        seconds,
        decode_ms,
        splits / decode_ms / 1e3,
    );
    Ok(())
}

/// Median of 5 full decodes (workspace set up outside the timing), in ms.
fn median_decode_ms(stream: &[u8]) -> Result<f64, String> {
    let fail = |e: splitstream_decoder_core::Error| e.to_string();
    let mut ws = OwnedWorkspace::for_stream(stream).map_err(fail)?;
    let mut times = Vec::new();
    for _ in 0..5 {
        let mut decoder = ws.decoder(stream).map_err(fail)?;
        let t = Instant::now();
        decoder.decode_available(stream).map_err(fail)?;
        times.push(t.elapsed().as_secs_f64() * 1e3);
    }
    times.sort_by(f64::total_cmp);
    Ok(times[times.len() / 2])
}

/// The input quantized and in the spatial order the encoder simplifies it
/// in (`spatial_order`; 2-10 ms on these meshes, outside the timed spans).
fn quantized(input: &Input, mesh: &Mesh) -> Result<QuantizedMesh, String> {
    let q = quantize(mesh, 14, input.units);
    Ok(spatially_ordered(&checked(&q)?).0)
}

/// The quantized input in metric units, the geometry both simplifiers see.
fn metric_mesh(q: &QuantizedMesh) -> Mesh {
    Mesh {
        positions: q
            .positions
            .iter()
            .map(|p| std::array::from_fn(|k| p[k] as f64 * q.metric[k]))
            .collect(),
        triangles: q.triangles.clone(),
    }
}

type OptionsFor<'a> = &'a dyn Fn(usize, Option<f64>) -> SimplifyOptions;

fn simplify(
    backend: Backend,
    q: &Checked<'_>,
    options: &SimplifyOptions,
) -> Result<Simplification, String> {
    simplify_on(backend, q, options, |_| {}).map_err(|e| e.to_string())
}

/// `q` checked for the simplifier, outside any timed span.
fn checked(q: &QuantizedMesh) -> Result<Checked<'_>, String> {
    Checked::new(q).map_err(|e| e.to_string())
}

/// One row of the quality table: which input, how far down, where to dump.
struct QualityRow<'a> {
    input: &'a Input,
    mesh: &'a Mesh,
    fraction: f64,
    dump: Option<&'a Path>,
}

/// Prints the row of the quality table and returns the row of the
/// largest-distances table.
fn quality_row(
    row: &QualityRow<'_>,
    options: OptionsFor<'_>,
    backend: Backend,
) -> Result<String, String> {
    let QualityRow {
        input,
        mesh,
        fraction,
        dump,
    } = *row;
    let q = quantized(input, mesh)?;
    let metric = QuantizedMesh {
        origin: [0.0; 3],
        scale: q.metric,
        ..q.clone()
    };
    let reference = metric_mesh(&q);
    let target = ((mesh.positions.len() as f64) * fraction).round() as usize;
    let c = checked(&q)?;
    let t = Instant::now();
    let s = simplify(backend, &c, &options(target, None))?;
    let parallel_seconds = t.elapsed().as_secs_f64();
    let parallel = s.to_mesh(&metric);
    let sequential = simplify_sequential(
        &reference,
        &BaselineOptions {
            target_vertices: target,
            ..BaselineOptions::default()
        },
    );
    if let Some(dir) = dump {
        let stem = format!(
            "{}-{}",
            input.name.replace(' ', "_"),
            format!("{:.2}", 100.0 * fraction)
                .trim_end_matches('0')
                .trim_end_matches('.')
        );
        for (name, m) in [
            ("reference", &reference),
            ("parallel", &parallel),
            ("sequential", &sequential.mesh),
        ] {
            let path = dir.join(format!("{stem}-{name}.ply"));
            write_mesh(&path, &m.positions, &m.triangles)?;
        }
    }
    let dp = surface_distance(&reference, &parallel, SAMPLES, 7);
    let ds = surface_distance(&reference, &sequential.mesh, SAMPLES, 7);
    let pct = |x: f64, d: f64| 100.0 * x / d;
    println!(
        "| {} | {:.2} % ({} v) | {:.4} | {:.4} | {:.2} | {:.5} | {:.5} | {:.2} | {:.2} | {:.2} | {:.1}x |",
        input.name,
        100.0 * fraction,
        parallel.positions.len(),
        pct(dp.hausdorff, dp.diagonal),
        pct(ds.hausdorff, ds.diagonal),
        dp.hausdorff / ds.hausdorff,
        pct(dp.rms, dp.diagonal),
        pct(ds.rms, ds.diagonal),
        dp.rms / ds.rms,
        parallel_seconds,
        sequential.seconds,
        sequential.seconds / parallel_seconds
    );
    Ok(format!(
        "| {} | {:.2} % | {:.4} | {:.4} | {:.2} | {} | {} |",
        input.name,
        100.0 * fraction,
        pct(dp.p999, dp.diagonal),
        pct(ds.p999, ds.diagonal),
        dp.p999 / ds.p999,
        farthest_cell(&dp),
        farthest_cell(&ds),
    ))
}

/// The farthest sample of a comparison against the reference (`a`): its
/// point, and whether it lies on the simplified surface (the simplified
/// mesh strays from the input there) or on the reference (the simplified
/// mesh lost input surface there).
fn farthest_cell(d: &DistanceReport) -> String {
    match d.farthest {
        Some(f) => format!(
            "({:.4}, {:.4}, {:.4}) on the {}",
            f.point[0],
            f.point[1],
            f.point[2],
            if f.on_a { "input" } else { "simplified" }
        ),
        None => "none".into(),
    }
}

fn equal_error_row(
    input: &Input,
    mesh: &Mesh,
    options: OptionsFor<'_>,
    backend: Backend,
) -> CliResult {
    let q = quantized(input, mesh)?;
    let reference = metric_mesh(&q);
    let target = mesh.positions.len() / 16;
    let c = checked(&q)?;
    let first = simplify(backend, &c, &options(target, None))?;
    let limit = first.max_error();
    let parallel = simplify(backend, &c, &options(0, Some(limit)))?;
    let sequential = simplify_sequential(
        &reference,
        &BaselineOptions {
            target_vertices: 0,
            max_error: Some(limit),
            ..BaselineOptions::default()
        },
    );
    let np = parallel.alive_count;
    let ns = sequential.mesh.positions.len();
    println!(
        "| {} | {:.4e} | {} | {} | {:+.1} % |",
        input.name,
        limit,
        np,
        ns,
        100.0 * (np as f64 / ns as f64 - 1.0)
    );
    Ok(())
}

fn throughput(side: usize, admit: f64, backend: Backend) -> CliResult {
    let mesh = fractal_terrain(side, 2012);
    let triangles = mesh.triangles.len() as f64;
    let t = Instant::now();
    let options = EncodeOptions {
        admit_quantile: admit,
        backend,
        ..EncodeOptions::default()
    };
    let encoded = encode(&mesh, &options, |_| {}).map_err(|e| e.to_string())?;
    let seconds = t.elapsed().as_secs_f64();
    println!(
        "- encode end to end: {:.2} s for {} triangles = {:.3} M triangles/s ({} rounds; simplify {:.2} s, emit {:.2} s; {} threads)",
        seconds,
        mesh.triangles.len(),
        triangles / seconds / 1e6,
        encoded.rounds,
        encoded.simplify_seconds,
        encoded.emit_seconds,
        rayon::current_num_threads()
    );
    let stream = &encoded.stream;
    let fail = |e: splitstream_decoder_core::Error| e.to_string();
    let mut ws = OwnedWorkspace::for_stream(stream).map_err(fail)?;
    let mut decoder = ws.decoder(stream).map_err(fail)?;
    let t = Instant::now();
    decoder.decode_available(stream).map_err(fail)?;
    let seconds = t.elapsed().as_secs_f64();
    let splits = decoder.positions().len() as f64;
    println!(
        "- decode (decoder-core, one thread, all levels): {:.1} ms = {:.2} M splits/s",
        seconds * 1e3,
        splits / seconds / 1e6
    );
    Ok(())
}
