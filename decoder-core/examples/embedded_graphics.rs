//! The decoder on a microcontroller's budget, drawn with embedded-graphics.
//!
//! A stream is decoded into one fixed workspace (on a microcontroller a
//! `static` buffer: nothing is allocated while decoding), level by level,
//! and after each level its front-facing triangles are drawn as a
//! wireframe into a 1-bit framebuffer the size of a 200 × 200 display
//! (embedded-graphics' `Framebuffer`, what a panel driver flushes). Two
//! things decide how far it decodes, as on a real device:
//!
//! * the workspace: `Decoder::levels_that_fit` (SPEC §9) stops cleanly at
//!   the last level the buffer holds;
//! * the display: one pixel covers a known length of the model, so the
//!   levels whose geometric error is below a pixel add nothing visible;
//!   `LevelTable::level_within_error` names the last one worth decoding.
//!
//! Projection and drawing use integers only (no FPU needed). This host
//! build reads the stream from a file and writes each frame as a PBM image
//! (black lines on white); the decode-and-draw part is what a firmware runs
//! (`embedded-size/` shows the bare-metal build of the decoder itself).
//!
//! ```text
//! cargo run --release -p splitstream-decoder-core --example embedded_graphics -- \
//!     [STREAM.sps] [--budget BYTES] [--axes xy|xz|zy] [--out DIR]
//! ```
//!
//! Without a stream it draws the Stanford bunny of the newest conformance
//! vector set (`bunny-npm.sps`).

use std::path::{Path, PathBuf};

use embedded_graphics::framebuffer::{Framebuffer, buffer_size};
use embedded_graphics::pixelcolor::BinaryColor;
use embedded_graphics::pixelcolor::raw::{BigEndian, RawU1};
use embedded_graphics::prelude::*;
use embedded_graphics::primitives::{Line, PrimitiveStyle};
use splitstream_decoder_core::{Decoder, Inflater, MeshState, workspace_len};

const WIDTH: usize = 200;
const HEIGHT: usize = 200;
/// Pixels left free around the model.
const MARGIN: i64 = 8;

/// A 200 × 200 one-bit display's framebuffer (rows packed MSB first, as
/// SSD1306-class drivers and the PBM format both store them).
type Display = Framebuffer<
    BinaryColor,
    RawU1,
    BigEndian,
    WIDTH,
    HEIGHT,
    { buffer_size::<BinaryColor>(WIDTH, HEIGHT) },
>;

/// The two grid axes the display shows: horizontal, then vertical (up).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct Axes(usize, usize);

/// Grid positions to pixels, in integers: `pixel = MARGIN + (q − min) ·
/// num / den`, the model's larger extent fitting the display.
#[derive(Clone, Copy, Debug)]
struct View {
    axes: Axes,
    min: [i64; 2],
    num: i64,
    den: i64,
}

impl View {
    /// The view that fits `positions` (at least one), with 10 % of room
    /// for the vertices later levels add outside the coarse hull.
    fn fit(positions: &[[u32; 3]], axes: Axes) -> Option<View> {
        let (mut lo, mut hi) = ([i64::MAX; 2], [i64::MIN; 2]);
        for p in positions {
            for (k, axis) in [axes.0, axes.1].into_iter().enumerate() {
                lo[k] = lo[k].min(p[axis] as i64);
                hi[k] = hi[k].max(p[axis] as i64);
            }
        }
        let extent = (hi[0] - lo[0]).max(hi[1] - lo[1]).max(1);
        let room = extent / 10;
        let span = (WIDTH.min(HEIGHT) as i64 - 1 - 2 * MARGIN).max(1);
        (lo[0] <= hi[0]).then_some(View {
            axes,
            min: [lo[0] - room / 2, lo[1] - room / 2],
            num: span,
            den: extent + room,
        })
    }

    fn project(&self, p: [u32; 3]) -> Point {
        let u = MARGIN + (p[self.axes.0] as i64 - self.min[0]) * self.num / self.den;
        let v = MARGIN + (p[self.axes.1] as i64 - self.min[1]) * self.num / self.den;
        // Screen y grows downwards; the model's vertical axis goes up.
        Point::new(u as i32, (HEIGHT as i64 - 1 - v) as i32)
    }

    /// Grid units one pixel covers.
    fn grid_units_per_pixel(&self) -> f64 {
        self.den as f64 / self.num as f64
    }
}

/// Draws the triangles of `state` that face the viewer (counter-clockwise
/// on the screen's axes, SPEC §2) as a wireframe; returns how many.
fn draw<D: DrawTarget<Color = BinaryColor>>(
    state: &MeshState<'_>,
    view: &View,
    target: &mut D,
) -> Result<usize, D::Error> {
    let style = PrimitiveStyle::with_stroke(BinaryColor::On, 1);
    let positions = state.positions();
    let mut drawn = 0;
    for t in state.triangles() {
        let [a, b, c] = t.map(|v| view.project(positions[v as usize]));
        // Screen y points down, so counter-clockwise in the model is a
        // negative signed area here.
        let area = (b - a).x as i64 * (c - a).y as i64 - (b - a).y as i64 * (c - a).x as i64;
        if area >= 0 {
            continue;
        }
        for (p, q) in [(a, b), (b, c), (c, a)] {
            Line::new(p, q).into_styled(style).draw(target)?;
        }
        drawn += 1;
    }
    Ok(drawn)
}

/// One drawn level.
#[derive(Clone, Debug, PartialEq)]
struct Frame {
    level: u16,
    vertices: u32,
    triangles: u32,
    drawn: usize,
    lit_pixels: usize,
}

/// What limited the decode, and the frames.
#[derive(Debug)]
struct Run {
    needed_workspace: usize,
    levels_that_fit: u16,
    /// Levels up to the first whose geometric error is within a pixel.
    levels_visible: u16,
    /// A pixel's length in model units.
    pixel: f32,
    level_count: u16,
    frames: Vec<Frame>,
}

/// Decodes `stream` into a `budget`-byte workspace, only the levels that
/// fit and that the display resolves, drawing after each; `save` gets each
/// frame.
fn run(
    stream: &[u8],
    budget: usize,
    axes: Axes,
    mut save: impl FnMut(u16, &Display),
) -> Result<Run, String> {
    let needed_workspace = workspace_len(stream).map_err(|e| e.to_string())?;
    // On a device: a static buffer and a static inflater.
    let mut workspace = vec![0u8; budget];
    let mut inflater = Inflater::new();
    let mut decoder =
        Decoder::new(stream, &mut workspace, &mut inflater).map_err(|e| e.to_string())?;
    let header = *decoder.header();
    let level_count = header.level_count;
    let levels_that_fit = decoder.levels_that_fit();
    let mut display = Display::new();
    let mut frames = Vec::new();
    let mut view = None;
    let mut levels_visible = level_count;
    let mut pixel = 0.0;
    while let Some(k) = decoder.next_level().filter(|&k| k < levels_visible) {
        let bytes = decoder.level_bytes(k, stream).map_err(|e| e.to_string())?;
        decoder.decode_level(k, bytes).map_err(|e| e.to_string())?;
        // Fitted on the base level, kept for the finer ones.
        let view = match view {
            Some(v) => v,
            None => {
                let v =
                    View::fit(decoder.positions(), axes).ok_or("the base level has no vertex")?;
                // A pixel's length in model units: levels more exact than
                // that change nothing on this display.
                let step = header.scale[axes.0].max(header.scale[axes.1]);
                pixel = (v.grid_units_per_pixel() * step) as f32;
                levels_visible = decoder.level_table().level_within_error(pixel) + 1;
                *view.insert(v)
            }
        };
        display
            .clear(BinaryColor::Off)
            .expect("framebuffers do not fail");
        let drawn = draw(decoder.state(), &view, &mut display).expect("framebuffers do not fail");
        let lit_pixels = display.data().iter().map(|b| b.count_ones() as usize).sum();
        save(k, &display);
        frames.push(Frame {
            level: k,
            vertices: decoder.state().vertex_count(),
            triangles: decoder.state().triangle_count(),
            drawn,
            lit_pixels,
        });
    }
    Ok(Run {
        needed_workspace,
        levels_that_fit,
        levels_visible,
        pixel,
        level_count,
        frames,
    })
}

/// A frame as a binary PBM image: the framebuffer's rows are already in
/// PBM's layout (1 = black, most significant bit first, rows byte-padded).
fn pbm(display: &Display) -> Vec<u8> {
    let mut out = format!("P4\n{WIDTH} {HEIGHT}\n").into_bytes();
    out.extend_from_slice(display.data());
    out
}

/// `bunny-npm.sps` of the newest conformance vector set.
fn default_stream() -> Option<PathBuf> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../conformance/vectors");
    let mut sets: Vec<PathBuf> = std::fs::read_dir(root)
        .ok()?
        .filter_map(|e| Some(e.ok()?.path().join("valid/bunny-npm.sps")))
        .filter(|p| p.is_file())
        .collect();
    sets.sort_by_key(|p| {
        let version = p
            .parent()?
            .parent()?
            .file_name()?
            .to_string_lossy()
            .to_string();
        Some(
            version
                .split('.')
                .map(|n| n.parse::<u32>().unwrap_or(0))
                .collect::<Vec<_>>(),
        )
    });
    sets.pop()
}

fn main() {
    if let Err(e) = cli() {
        eprintln!("embedded_graphics: {e}");
        std::process::exit(2);
    }
}

fn cli() -> Result<(), String> {
    let mut path = None;
    let mut budget = 160 * 1024;
    let mut axes = Axes(0, 1);
    let mut out = PathBuf::from("embedded-frames");
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        let mut value = |name: &str| args.next().ok_or(format!("{name} needs a value"));
        match a.as_str() {
            "--budget" => {
                let v = value("--budget")?;
                budget = v
                    .parse()
                    .map_err(|_| format!("--budget {v} is not a byte count"))?;
            }
            "--axes" => {
                axes = match value("--axes")?.as_str() {
                    "xy" => Axes(0, 1),
                    "xz" => Axes(0, 2),
                    "zy" => Axes(2, 1),
                    other => return Err(format!("--axes {other}: expected xy, xz or zy")),
                }
            }
            "--out" => out = PathBuf::from(value("--out")?),
            _ if a.starts_with("--") => return Err(format!("unknown option {a}")),
            _ => path = Some(PathBuf::from(a)),
        }
    }
    let path = path
        .or_else(default_stream)
        .ok_or("no stream given and no conformance vector set found")?;
    let stream = std::fs::read(&path).map_err(|e| format!("{}: {e}", path.display()))?;
    std::fs::create_dir_all(&out).map_err(|e| format!("{}: {e}", out.display()))?;
    let mut written = Ok(());
    let result = run(&stream, budget, axes, |k, display| {
        let file = out.join(format!("level-{k}.pbm"));
        if written.is_ok() {
            written =
                std::fs::write(&file, pbm(display)).map_err(|e| format!("{}: {e}", file.display()));
        }
    })?;
    written?;
    println!(
        "{}: {} levels; a workspace of {} bytes (the whole stream needs {}) holds {} of them; \
         on a {WIDTH} x {HEIGHT} display a pixel is {:.3e} model units, and level {} is the \
         first within it",
        path.display(),
        result.level_count,
        budget,
        result.needed_workspace,
        result.levels_that_fit,
        result.pixel,
        result.levels_visible - 1,
    );
    println!("level  vertices  triangles  drawn  lit pixels  frame");
    for f in &result.frames {
        println!(
            "{:5}  {:8}  {:9}  {:5}  {:10}  {}",
            f.level,
            f.vertices,
            f.triangles,
            f.drawn,
            f.lit_pixels,
            out.join(format!("level-{}.pbm", f.level)).display()
        );
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn bunny() -> Vec<u8> {
        std::fs::read(default_stream().expect("the conformance vectors")).unwrap()
    }

    #[test]
    fn the_bunny_is_drawn_level_by_level_within_the_budget() {
        let stream = bunny();
        let needed = workspace_len(&stream).unwrap();
        let mut saved = Vec::new();
        let run = run(&stream, needed, Axes(0, 1), |k, d| saved.push((k, pbm(d)))).unwrap();
        assert_eq!(run.levels_that_fit, run.level_count);
        assert!(!run.frames.is_empty());
        assert_eq!(
            run.frames.len() as u16,
            run.levels_visible.min(run.level_count)
        );
        for (f, (k, image)) in run.frames.iter().zip(&saved) {
            assert_eq!(f.level, *k);
            assert!(f.drawn > 0 && f.lit_pixels > 0, "{f:?}");
            let header = format!("P4\n{WIDTH} {HEIGHT}\n").len();
            assert_eq!(image.len(), header + WIDTH.div_ceil(8) * HEIGHT);
        }
        // More detail, more triangles drawn.
        assert!(
            run.frames
                .windows(2)
                .all(|w| w[1].triangles > w[0].triangles)
        );
    }

    #[test]
    fn a_small_workspace_stops_at_the_last_level_that_fits() {
        let stream = bunny();
        let full = run(
            &stream,
            workspace_len(&stream).unwrap(),
            Axes(0, 1),
            |_, _| {},
        )
        .unwrap();
        // Between the base level's needs and the whole stream's.
        let mut budget = workspace_len(&stream).unwrap();
        let small = loop {
            budget = budget * 3 / 4;
            let r = run(&stream, budget, Axes(0, 1), |_, _| {});
            match r {
                Ok(r) if r.levels_that_fit < full.levels_that_fit => break r,
                Ok(_) => continue,
                Err(e) => panic!("no budget between one level and all: {e}"),
            }
        };
        assert!(small.levels_that_fit >= 1);
        assert_eq!(
            small.frames.len() as u16,
            small.levels_that_fit.min(small.levels_visible)
        );
    }

    #[test]
    fn the_view_maps_the_extent_into_the_margins() {
        let positions = [[0, 0, 0], [1000, 500, 7], [250, 1000, 3]];
        let view = View::fit(&positions, Axes(0, 1)).unwrap();
        for p in positions {
            let q = view.project(p);
            assert!(
                (MARGIN as i32..WIDTH as i32 - MARGIN as i32).contains(&q.x),
                "{q:?}"
            );
            assert!(
                (MARGIN as i32..HEIGHT as i32 - MARGIN as i32).contains(&q.y),
                "{q:?}"
            );
        }
        // Up is up: a larger y is higher on the screen.
        assert!(view.project([0, 1000, 0]).y < view.project([0, 0, 0]).y);
    }
}
