//! `splitstream gpu-bench`: the simplifier's backends timed in one run on
//! the synthetic fractal terrains (1M and 4M vertices by default): the CPU
//! encoder, the sequential baseline, and the wgpu and OpenCL backends. Each
//! encoded stream is checked (the encoder's replay, then a full decode with
//! decoder-core); ratios come from the same run. Figures go to
//! encoder/BENCHMARKS.md ("GPU backends") with the machine and date.

use std::time::Instant;

use splitstream_decoder_core::PositionMode;
use splitstream_decoder_core::owned::OwnedWorkspace;
use splitstream_encoder::Mesh;
use splitstream_encoder::baseline::{BaselineOptions, simplify_sequential};
use splitstream_encoder::emit::{EncodeOptions, SEED_VERTICES, encode};
use splitstream_encoder::input::{check_mesh, fractal_terrain};
use splitstream_encoder::quantize::{Units, quantize};
use splitstream_encoder::simplify::Backend;

use super::CliResult;

/// One contender of the benchmark.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Contender {
    /// The parallel encoder on the CPU threads.
    Cpu,
    /// The sequential QEM baseline (simplification only, same quadrics).
    Sequential,
    /// The parallel encoder with the wgpu backend.
    Wgpu,
    /// The parallel encoder with the OpenCL backend.
    Opencl,
}

/// `splitstream gpu-bench`'s arguments.
#[derive(clap::Args)]
pub struct Settings {
    /// Terrain sides in samples (1024 = 1M vertices, 2048 = 4M); smaller
    /// sides make quick runs.
    #[arg(long, value_delimiter = ',', default_values_t = [1024, 2048])]
    pub sides: Vec<usize>,
    /// Contenders, in order.
    #[arg(long, value_enum, value_delimiter = ',', default_values_t = [Contender::Cpu, Contender::Sequential, Contender::Wgpu, Contender::Opencl])]
    pub backends: Vec<Contender>,
    /// Fraction of candidate collapses admitted per step (0..1].
    #[arg(long, default_value_t = 0.5, allow_negative_numbers = true)]
    pub admit: f64,
    /// Fail (instead of reporting the row as unavailable) when a GPU
    /// backend has no adapter.
    #[arg(long)]
    pub require_gpu: bool,
    /// Leave out the GPU decoder's table (it re-encodes each terrain on the
    /// CPU and decodes it four times: at 4M vertices about half a minute).
    #[arg(long)]
    pub skip_decoder: bool,
}

/// What one contender measured.
struct Row {
    simplify_seconds: f64,
    total_seconds: f64,
    note: String,
}

pub fn run(settings: &Settings) -> CliResult {
    if let Some(&side) = settings.sides.iter().find(|&&s| !(2..=4096).contains(&s)) {
        return Err(format!("--sides: {side} is outside 2..=4096"));
    }
    println!("# splitstream GPU backends benchmark\n");
    println!(
        "{} CPU threads; simplify = the parallel simplification (or the sequential baseline), end to end = simplify + replay check + stream writing; every stream decoded fully with decoder-core.\n",
        rayon::current_num_threads()
    );
    for backend in [Backend::Wgpu, Backend::OpenCl] {
        let wanted = match backend {
            Backend::Wgpu => Contender::Wgpu,
            _ => Contender::Opencl,
        };
        if !settings.backends.contains(&wanted) {
            continue;
        }
        let api = backend.api().expect("a GPU backend");
        match splitstream_kernels::gpu::describe(api) {
            Ok(info) => println!("- {backend} device: {info}"),
            Err(e) => println!("- {backend} device: unavailable ({e})"),
        }
    }
    println!();
    println!(
        "| terrain | vertices | triangles | contender | simplify s | end to end s | M triangles/s end to end | simplify vs cpu | simplify vs sequential | notes |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|");
    for &side in &settings.sides {
        let mesh = fractal_terrain(side, 2012);
        check_mesh(&mesh).map_err(|e| format!("terrain {side}: {e}"))?;
        let mut rows = Vec::new();
        for &contender in &settings.backends {
            let row = match contender {
                Contender::Sequential => sequential(&mesh),
                Contender::Cpu => parallel(&mesh, Backend::Cpu, settings)?,
                Contender::Wgpu => parallel(&mesh, Backend::Wgpu, settings)?,
                Contender::Opencl => parallel(&mesh, Backend::OpenCl, settings)?,
            };
            rows.push((contender, row));
        }
        let time_of = |c: Contender| {
            rows.iter()
                .find(|(x, r)| *x == c && r.simplify_seconds.is_finite())
                .map(|(_, r)| r.simplify_seconds)
        };
        let (cpu, seq) = (time_of(Contender::Cpu), time_of(Contender::Sequential));
        let ratio = |base: Option<f64>, s: f64| match base {
            Some(b) if s.is_finite() => format!("{:.2}x", b / s),
            _ => "-".into(),
        };
        for (contender, row) in &rows {
            let finite = row.simplify_seconds.is_finite();
            let show = |x: f64| {
                if x.is_finite() {
                    format!("{x:.2}")
                } else {
                    "-".into()
                }
            };
            println!(
                "| {side}x{side} | {} | {} | {} | {} | {} | {} | {} | {} | {} |",
                mesh.positions.len(),
                mesh.triangles.len(),
                format!("{contender:?}").to_lowercase(),
                show(row.simplify_seconds),
                show(row.total_seconds),
                if finite && row.total_seconds.is_finite() {
                    format!(
                        "{:.3}",
                        mesh.triangles.len() as f64 / row.total_seconds / 1e6
                    )
                } else {
                    "-".into()
                },
                ratio(cpu, row.simplify_seconds),
                ratio(seq, row.simplify_seconds),
                row.note
            );
        }
    }
    if settings.skip_decoder {
        return Ok(());
    }
    // The WGSL decoder (sdk-native, feature `gpu`) on the same terrains.
    gpu_decoder(&settings.sides, settings.require_gpu)
}

/// Decoder splits per second, the GPU's refinement rounds (uploads
/// included) against decoder-core on one thread, on each terrain's stream
/// (CPU encoder); every GPU state hash is checked against decoder-core's
/// first. Phase 1: the records are still read on the CPU, the GPU applies
/// the rounds (sdk-native/README.md).
#[cfg(feature = "wgpu")]
fn gpu_decoder(sides: &[usize], require_gpu: bool) -> CliResult {
    use splitstream_sdk_native::gpu::{Api, GpuDevice, bench, verify};

    println!("\n## GPU decoder (WGSL refinement rounds, sdk-native `gpu`)\n");
    let ctx = match GpuDevice::open(Api::Wgpu) {
        Ok(ctx) => ctx,
        Err(e) if e.is_unavailable() && !require_gpu => {
            println!("unavailable: {e}");
            return Ok(());
        }
        Err(e) => return Err(format!("GPU decoder: {e}")),
    };
    println!("device: {}\n", ctx.info());
    println!(
        "| terrain | vertices | rounds | splits | decoder-core ms | decoder-core splits/s | GPU ms, uploads included | GPU splits/s | GPU rounds only ms | GPU / decoder-core |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|");
    for &side in sides {
        let mesh = fractal_terrain(side, 2012);
        // Optimal mode, as the recorded figures (the default until
        // 2026-12-03): two vectors per split.
        let options = EncodeOptions {
            position_mode: PositionMode::Optimal,
            ..EncodeOptions::default()
        };
        let encoded =
            encode(&mesh, &options, |_| {}).map_err(|e| format!("terrain {side}: {e}"))?;
        let stream = &encoded.stream;
        match verify(&ctx, stream, false).result {
            Err(e) if e.is_too_large() => {
                println!(
                    "| {side}x{side} | {} | | | | | | | | does not fit this device: {e} |",
                    encoded.permutation.len()
                );
                continue;
            }
            result => result.map_err(|e| format!("GPU decoder, terrain {side}: {e}"))?,
        }
        let r = bench(&ctx, stream, 3).map_err(|e| format!("GPU decoder, terrain {side}: {e}"))?;
        println!(
            "| {side}x{side} | {} | {} | {} | {:.1} | {:.0} | {:.1} | {:.0} | {:.1} | {:.2}x |",
            r.vertices,
            r.rounds,
            r.splits,
            r.cpu_decode * 1e3,
            r.cpu_splits_per_second(),
            r.gpu_total * 1e3,
            r.gpu_splits_per_second(),
            r.gpu_rounds * 1e3,
            r.gpu_splits_per_second() / r.cpu_splits_per_second()
        );
    }
    Ok(())
}

#[cfg(not(feature = "wgpu"))]
fn gpu_decoder(_sides: &[usize], _require_gpu: bool) -> CliResult {
    println!("\nGPU decoder: not in this build (cargo feature `wgpu` of splitstream-encoder)");
    Ok(())
}

fn sequential(mesh: &Mesh) -> Row {
    let q = quantize(mesh, 14, Units::Linear);
    let metric = Mesh {
        positions: q
            .positions
            .iter()
            .map(|p| std::array::from_fn(|k| p[k] as f64 * q.metric[k]))
            .collect(),
        triangles: q.triangles.clone(),
    };
    let t = Instant::now();
    let result = simplify_sequential(
        &metric,
        &BaselineOptions {
            target_vertices: SEED_VERTICES,
            ..BaselineOptions::default()
        },
    );
    Row {
        simplify_seconds: result.seconds,
        total_seconds: t.elapsed().as_secs_f64(),
        note: format!(
            "simplification only, to {} vertices",
            result.mesh.positions.len()
        ),
    }
}

fn parallel(mesh: &Mesh, backend: Backend, settings: &Settings) -> Result<Row, String> {
    let options = EncodeOptions {
        admit_quantile: settings.admit,
        backend,
        position_mode: PositionMode::Optimal,
        ..EncodeOptions::default()
    };
    let t = Instant::now();
    let encoded = match encode(mesh, &options, |_| {}) {
        Ok(e) => e,
        Err(splitstream_encoder::emit::EncodeError::Backend(e))
            if e.is_unavailable() && !settings.require_gpu =>
        {
            return Ok(Row {
                simplify_seconds: f64::INFINITY,
                total_seconds: f64::INFINITY,
                note: format!("unavailable: {e}"),
            });
        }
        Err(e) => return Err(format!("{backend}: {e}")),
    };
    let total = t.elapsed().as_secs_f64();
    let stream = &encoded.stream;
    let fail = |e: splitstream_decoder_core::Error| format!("{backend} stream: {e}");
    let mut ws = OwnedWorkspace::for_stream(stream).map_err(fail)?;
    let mut decoder = ws.decoder(stream).map_err(fail)?;
    decoder.decode_available(stream).map_err(fail)?;
    if decoder.positions().len() != mesh.positions.len() {
        return Err(format!(
            "{backend}: decoded {} vertices of {}",
            decoder.positions().len(),
            mesh.positions.len()
        ));
    }
    Ok(Row {
        simplify_seconds: encoded.simplify_seconds,
        total_seconds: total,
        note: format!(
            "{} rounds, {:.2} bits/vertex, decoded exactly",
            encoded.rounds,
            8.0 * stream.len() as f64 / mesh.positions.len() as f64
        ),
    })
}
