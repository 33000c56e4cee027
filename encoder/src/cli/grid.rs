//! `splitstream grid`: client-side grid-tile simplification (quad-tree
//! split/merge with edge straightening, `splitstream-sdk-native`), and with
//! `--bench` its figures on tiles cut from the input next to the QEM
//! simplifier at the same triangle count.

use std::path::PathBuf;
use std::time::Instant;

use splitstream_sdk_native::grid_tile::{Params, Simplifier, Tile};

use splitstream_encoder::Mesh;
use splitstream_encoder::input::{Grid, ReadOptions, grid_to_mesh, read_grid};
use splitstream_encoder::metrics::surface_distance;
use splitstream_encoder::quantize::{Units, quantize};
use splitstream_encoder::simplify::{Checked, SimplifyOptions, simplify};

use super::CliResult;
use super::output::write_mesh;

/// `splitstream grid`'s arguments.
#[derive(clap::Args)]
pub struct Args {
    pub input: PathBuf,
    /// Viewing height H, in the units of the elevations.
    #[arg(long, allow_negative_numbers = true)]
    pub height: f64,
    /// Resolution of the neighbouring tile on each side, N,E,S,W (a
    /// number or - for none; in the units of the spacing, metres with
    /// --geographic); a coarser one sets that border's threshold.
    #[arg(long)]
    pub neighbour_res: Option<String>,
    #[arg(short, long)]
    pub output: Option<PathBuf>,
    /// x and y are longitude and latitude in degrees: convert the
    /// spacing to metres (~111 km per degree, times cos(latitude) for x).
    #[arg(long)]
    pub geographic: bool,
    /// .npz only: the array with the elevations.
    #[arg(long)]
    pub npz_array: Option<String>,
    /// Multiply z by this.
    #[arg(long, default_value_t = 1.0, allow_negative_numbers = true)]
    pub z_scale: f64,
    /// How many tiles share each side, N,E,S,W (default 1,1,1,1): 2 when
    /// two tiles of half this tile's extent line that side.
    #[arg(long)]
    pub neighbour_tiles: Option<String>,
    /// Cut tiles of this many cells a side, time them and compare with
    /// QEM at the same triangle count (see encoder/BENCHMARKS.md).
    #[arg(long)]
    pub bench: Option<usize>,
}

/// Parses `N,E,S,W`, each a resolution or `-` for none.
pub fn parse_neighbour_res(text: &str) -> Result<[Option<f64>; 4], String> {
    let parts: Vec<&str> = text.split(',').map(str::trim).collect();
    if parts.len() != 4 {
        return Err(format!(
            "--neighbour-res wants four values N,E,S,W (a resolution or -), got '{text}'"
        ));
    }
    let mut out = [None; 4];
    for (slot, p) in out.iter_mut().zip(&parts) {
        if *p == "-" || p.is_empty() {
            continue;
        }
        let v: f64 = p
            .parse()
            .map_err(|_| format!("--neighbour-res: '{p}' is not a number or -"))?;
        if !(v.is_finite() && v > 0.0) {
            return Err(format!("--neighbour-res: {v} must be finite and positive"));
        }
        *slot = Some(v);
    }
    Ok(out)
}

/// Parses `N,E,S,W`, each a positive tile count.
pub fn parse_neighbour_tiles(text: &str) -> Result<[u32; 4], String> {
    let parts: Vec<&str> = text.split(',').map(str::trim).collect();
    let mut out = [1; 4];
    if parts.len() != 4 {
        return Err(format!(
            "--neighbour-tiles wants four counts N,E,S,W, got '{text}'"
        ));
    }
    for (slot, p) in out.iter_mut().zip(&parts) {
        *slot = p
            .parse()
            .ok()
            .filter(|&n: &u32| n > 0)
            .ok_or_else(|| format!("--neighbour-tiles: '{p}' is not a positive count"))?;
    }
    Ok(out)
}

pub fn run(args: Args) -> CliResult {
    if !(args.height.is_finite() && args.height > 0.0) {
        return Err(format!(
            "--height {} must be finite and positive",
            args.height
        ));
    }
    if !(args.z_scale.is_finite() && args.z_scale != 0.0) {
        return Err(format!(
            "--z-scale {} must be finite and non-zero",
            args.z_scale
        ));
    }
    let neighbour_res = match &args.neighbour_res {
        Some(t) => parse_neighbour_res(t)?,
        None => [None; 4],
    };
    if args.output.is_none() && args.bench.is_none() {
        return Err("an output file is needed: -o OUT.ply (or --bench TILE)".into());
    }
    if let Some(o) = &args.output {
        super::output::mesh_extension(o)?;
    }
    let options = ReadOptions {
        npz_array: args.npz_array.clone(),
        grid_spacing: None,
        z_scale: args.z_scale,
    };
    let mut grid = read_grid(&args.input, &options).map_err(|e| e.to_string())?;
    if grid.coordinates.is_some() {
        // The tiles are squares of samples at one spacing.
        return Err(format!(
            "{}: the samples are not evenly spaced (the file lists their coordinates); \
             the tile simplifier needs a regular grid",
            args.input.display()
        ));
    }
    if args.geographic {
        to_metres(&mut grid);
    }
    for z in grid.elevations.iter_mut() {
        if grid.nodata.is_some_and(|nd| *z == nd) {
            *z = f64::NAN;
        }
    }
    let neighbour_tiles = match &args.neighbour_tiles {
        Some(t) => parse_neighbour_tiles(t)?,
        None => [1; 4],
    };
    let params = Params {
        viewing_height: args.height,
        neighbour_res,
        neighbour_tiles,
    };
    if let Some(side) = args.bench {
        return bench(&grid, &params, side);
    }
    let tile = Tile {
        rows: grid.rows,
        cols: grid.cols,
        heights: &grid.elevations,
        spacing: grid.spacing,
        origin: grid.origin,
    };
    let mut simplifier = Simplifier::new(grid.rows, grid.cols);
    let start = Instant::now();
    let (out, stats) = simplifier
        .simplify(&tile, &params)
        .map_err(|e| format!("{}: {e}", args.input.display()))?;
    let elapsed = start.elapsed();
    println!(
        "grid {} rows x {} columns, spacing {:.3} (x) x {:.3} (y), H {}, T {:.4}",
        grid.rows, grid.cols, grid.spacing[0], grid.spacing[1], args.height, stats.threshold
    );
    println!(
        "facets {} -> {} ({:.1} % fewer), triangles {} -> {}, vertices {}",
        stats.cells,
        stats.rectangles,
        100.0 * stats.facet_reduction(),
        stats.triangles_before,
        stats.triangles_after,
        stats.vertices_after
    );
    println!(
        "max vertical error {:.4} ({:.2} T; at most 1 T of each sample's own threshold: {:.3}), \
         {} refinement rounds, {:.3} ms",
        stats.max_vertical_error,
        stats.max_vertical_error / stats.threshold,
        stats.max_error_ratio,
        stats.refinements,
        elapsed.as_secs_f64() * 1e3
    );
    let output = args.output.as_ref().expect("checked above");
    write_mesh(output, &out.positions, &out.triangles)
}

/// Degrees to metres: ~111 km per degree of latitude, times cos(latitude)
/// per degree of longitude at the grid's middle latitude.
fn to_metres(grid: &mut Grid) {
    let mid_lat = grid.origin[1] + 0.5 * (grid.rows as f64 - 1.0) * grid.spacing[1];
    let mx = 111_320.0 * mid_lat.to_radians().cos();
    let my = 110_574.0;
    grid.origin = [grid.origin[0] * mx, grid.origin[1] * my];
    grid.spacing = [grid.spacing[0] * mx, grid.spacing[1] * my];
}

/// Max |h - surface| over the tile's samples under `mesh` (triangles
/// located in grid coordinates), and how many samples no triangle covers.
fn vertical_error(mesh: &Mesh, tile: &Tile) -> (f64, usize) {
    const EPS: f64 = 1e-7;
    let (rows, cols) = (tile.rows, tile.cols);
    let to_grid = |p: [f64; 3]| {
        [
            (p[0] - tile.origin[0]) / tile.spacing[0],
            (p[1] - tile.origin[1]) / tile.spacing[1],
        ]
    };
    let mut worst: f64 = 0.0;
    let mut covered = vec![false; rows * cols];
    for t in &mesh.triangles {
        let p = t.map(|v| mesh.positions[v as usize]);
        let [a, b, c] = p.map(to_grid);
        let area = (b[0] - a[0]) * (c[1] - a[1]) - (c[0] - a[0]) * (b[1] - a[1]);
        if area.abs() < 1e-12 {
            continue;
        }
        // Positions went through origin + index * spacing: allow rounding.
        let lo = |k: usize| (a[k].min(b[k]).min(c[k]) - 1e-6).ceil().max(0.0) as usize;
        let hi = |k: usize, n: usize| {
            ((a[k].max(b[k]).max(c[k]) + 1e-6).floor().max(0.0) as usize).min(n - 1)
        };
        for y in lo(1)..=hi(1, rows) {
            for x in lo(0)..=hi(0, cols) {
                let q = [x as f64, y as f64];
                let wa = ((b[0] - q[0]) * (c[1] - q[1]) - (c[0] - q[0]) * (b[1] - q[1])) / area;
                let wb = ((c[0] - q[0]) * (a[1] - q[1]) - (a[0] - q[0]) * (c[1] - q[1])) / area;
                let wc = 1.0 - wa - wb;
                if wa < -EPS || wb < -EPS || wc < -EPS {
                    continue;
                }
                let z = wa * p[0][2] + wb * p[1][2] + wc * p[2][2];
                worst = worst.max((tile.heights[y * cols + x] - z).abs());
                covered[y * cols + x] = true;
            }
        }
    }
    (worst, covered.iter().filter(|&&c| !c).count())
}

/// Cuts `side x side`-cell tiles (sharing their border samples) and prints
/// the simplifier's figures next to QEM at the same triangle count.
fn bench(grid: &Grid, params: &Params, side: usize) -> CliResult {
    if side < 1 || side + 1 > grid.rows || side + 1 > grid.cols {
        return Err(format!(
            "--bench {side}: tiles must fit the {} x {} grid",
            grid.rows, grid.cols
        ));
    }
    let n = side + 1;
    let mut simplifier = Simplifier::new(n, n);
    let mut heights = Vec::with_capacity(n * n);
    let (mut tiles, mut skipped) = (0usize, 0usize);
    let (mut cells, mut rects, mut tris_after) = (0usize, 0usize, 0usize);
    let mut reductions = Vec::new();
    let mut time_total = 0.0f64;
    let mut worst_ms: f64 = 0.0;
    let mut refinements = 0usize;
    let (mut grid_err_sum, mut grid_err_max, mut grid_err_over_t) = (0.0f64, 0.0f64, 0.0f64);
    let (mut qem_err_sum, mut qem_err_max, mut qem_tris, mut qem_uncovered) =
        (0.0f64, 0.0f64, 0usize, 0usize);
    let (mut grid_haus, mut qem_haus) = (0.0f64, 0.0f64);
    let mut qem_tiles = 0usize;
    const REPS: usize = 20;
    println!(
        "tile  facets(before->after)  reduction  triangles  ms/tile  max err (T)  | QEM triangles  QEM max err  grid/QEM Hausdorff"
    );
    for ty in (0..grid.rows - side).step_by(side) {
        for tx in (0..grid.cols - side).step_by(side) {
            heights.clear();
            for r in ty..ty + n {
                heights.extend_from_slice(
                    &grid.elevations[r * grid.cols + tx..r * grid.cols + tx + n],
                );
            }
            if heights.iter().any(|h| !h.is_finite()) {
                skipped += 1;
                continue;
            }
            let tile = Tile {
                rows: n,
                cols: n,
                heights: &heights,
                spacing: grid.spacing,
                origin: [
                    grid.origin[0] + tx as f64 * grid.spacing[0],
                    grid.origin[1] + ty as f64 * grid.spacing[1],
                ],
            };
            // The error check is part of the simplification (it bounds
            // the error), so there is no faster variant without it.
            let start = Instant::now();
            for _ in 0..REPS {
                simplifier
                    .simplify(&tile, params)
                    .map_err(|e| e.to_string())?;
            }
            let ms = start.elapsed().as_secs_f64() * 1e3 / REPS as f64;
            let (out, stats) = simplifier
                .simplify(&tile, params)
                .map_err(|e| e.to_string())?;
            tiles += 1;
            time_total += ms;
            worst_ms = worst_ms.max(ms);
            cells += stats.cells;
            rects += stats.rectangles;
            tris_after += stats.triangles_after;
            reductions.push(stats.facet_reduction());
            grid_err_sum += stats.max_vertical_error;
            grid_err_max = grid_err_max.max(stats.max_vertical_error);
            grid_err_over_t = grid_err_over_t.max(stats.max_error_ratio);
            refinements += stats.refinements;
            let ours = Mesh {
                positions: out.positions.clone(),
                triangles: out.triangles.clone(),
            };

            // QEM at (about) the same triangle count.
            let full = grid_to_mesh(&Grid {
                rows: n,
                cols: n,
                elevations: heights.clone(),
                origin: tile.origin,
                spacing: grid.spacing,
                nodata: None,
                coordinates: None,
            });
            let q = quantize(&full, 14, Units::Linear);
            let checked =
                Checked::new(&q).map_err(|e| format!("tile at row {ty}, column {tx}: {e}"))?;
            let goal = stats.triangles_after;
            let run_qem = |target: usize| {
                let s = simplify(
                    &checked,
                    &SimplifyOptions {
                        target_vertices: target.max(4),
                        ..SimplifyOptions::default()
                    },
                    |_| {},
                );
                s.to_mesh(&q)
            };
            let mut target = goal / 2 + 2;
            let mut qem = run_qem(target);
            for _ in 0..3 {
                let diff = goal as i64 - qem.triangles.len() as i64;
                if diff.abs() <= 2 {
                    break;
                }
                target = (target as i64 + diff / 2).max(4) as usize;
                qem = run_qem(target);
            }
            let (qerr, unc) = vertical_error(&qem, &tile);
            let gh = surface_distance(&full, &ours, 20_000, 1).hausdorff;
            let qh = surface_distance(&full, &qem, 20_000, 1).hausdorff;
            qem_tiles += 1;
            qem_tris += qem.triangles.len();
            qem_err_sum += qerr;
            qem_err_max = qem_err_max.max(qerr);
            qem_uncovered += unc;
            grid_haus = grid_haus.max(gh);
            qem_haus = qem_haus.max(qh);
            println!(
                "({tx},{ty})  {} -> {}  {:.1} %  {}  {:.3}  {:.3} ({:.2})  | {}  {:.3}  {:.3}/{:.3}",
                stats.cells,
                stats.rectangles,
                100.0 * stats.facet_reduction(),
                stats.triangles_after,
                ms,
                stats.max_vertical_error,
                stats.max_vertical_error / stats.threshold,
                qem.triangles.len(),
                qerr,
                gh,
                qh
            );
        }
    }
    if tiles == 0 {
        return Err("--bench: no tile without missing samples".into());
    }
    reductions.sort_by(f64::total_cmp);
    println!(
        "\n{tiles} tiles of {side} x {side} cells ({skipped} skipped for missing samples), \
         spacing {:.2} x {:.2} m, H {}, T {:.3}",
        grid.spacing[0].abs(),
        grid.spacing[1].abs(),
        params.viewing_height,
        splitstream_sdk_native::grid_tile::threshold(
            params.viewing_height,
            splitstream_sdk_native::grid_tile::tile_resolution(grid.spacing)
        )
    );
    println!(
        "facets {cells} -> {rects}: reduction {:.1} % overall, per tile min {:.1} % median {:.1} % max {:.1} %",
        100.0 * (1.0 - rects as f64 / cells as f64),
        100.0 * reductions[0],
        100.0 * reductions[reductions.len() / 2],
        100.0 * reductions[reductions.len() - 1]
    );
    println!(
        "time per tile: mean {:.3} ms, worst {:.3} ms (one thread, {REPS} runs each, error \
         check included); {:.2} refinement rounds per tile",
        time_total / tiles as f64,
        worst_ms,
        refinements as f64 / tiles as f64
    );
    println!(
        "grid simplifier: {tris_after} triangles, max vertical error mean {:.3} max {:.3} m ({:.2} T), Hausdorff max {:.3} m",
        grid_err_sum / tiles as f64,
        grid_err_max,
        grid_err_over_t,
        grid_haus
    );
    println!(
        "QEM (14-bit, same triangle count): {qem_tris} triangles, max vertical error mean {:.3} max {:.3} m \
         ({qem_uncovered} samples off the shrunk border), Hausdorff max {:.3} m, {qem_tiles} tiles",
        qem_err_sum / qem_tiles.max(1) as f64,
        qem_err_max,
        qem_haus
    );
    Ok(())
}
