//! Emission by replay (issue: "correct by construction"): the refinement is
//! walked forward with decoder-core's own round procedure, and every flag and
//! split record is written exactly as that procedure asks for it.

mod deficits;
mod flags;
mod geometry;
mod levels;
mod policies;
mod positions_first;
mod replay;
mod transcode;
mod wings;

use splitstream_decoder_core::Framing;
use splitstream_decoder_core::limits::rans::MAX_LANES;
use splitstream_decoder_core::writer::{ChunkCodec, LevelPayload, StreamParams, assemble_stream};
use splitstream_decoder_core::{
    DeficitContexts, PlanePolicy, PositionMode, RecordOrder, Schedule, Ties, WingPolicy,
};

use crate::input::{MeshError, MeshStats, check_mesh};
use crate::mesh::Mesh;
use crate::quantize::{GridError, Lattice, Quantization, QuantizedMesh, Units, quantize_with};
use crate::simplify::{Backend, Checked, GpuError, SimplifyOptions, simplify_on};
use crate::spatial_order::spatially_ordered;
pub use levels::{LevelPlan, plan_levels};
pub use replay::{ReplayError, ReplayOptions, positions_first_allowed, replay};
use std::borrow::Cow;
pub use transcode::{TranscodeError, TranscodeOptions, Transcoded, transcode};

/// Vertices the simplification aims for below the base mesh: a seed just
/// large enough that closed shapes keep a valid manifold.
pub const SEED_VERTICES: usize = 16;

/// Everything `splitstream encode` can set.
#[derive(Clone, Debug)]
pub struct EncodeOptions {
    /// Quantization bits per axis (1..=31).
    pub bits: u8,
    /// Levels of detail including the base mesh (the paper uses 5).
    pub levels: usize,
    /// Base mesh size (level 0 ends at the round nearest to it); by default
    /// `vertices / 2^(levels - 1)`. No effect with one level, which holds
    /// the whole mesh.
    pub base_vertices: Option<usize>,
    /// Constrained by default: every merged vertex on P, C or their
    /// midpoint, one vector per split. Whole streams are 35–37 % smaller
    /// than in optimal mode on the scanned meshes; at equal bytes the
    /// decoded prefixes are about as accurate, except the first two of
    /// bunny00 (optimal 1.3–1.4x more accurate), and optimal mode is
    /// 1.3–2.2x more accurate at equal vertex counts: it suits clients
    /// bounded by vertices rather than bytes (encoder/BENCHMARKS.md,
    /// "Position modes: error against bytes"). Axes on a lattice are kept
    /// exactly in constrained mode ([`EncodeOptions::lattice`]).
    pub position_mode: PositionMode,
    /// Maximum quadric error of any collapse (stops simplification early).
    pub max_error: Option<f64>,
    pub codec: ChunkCodec,
    /// Largest stored or deflate chunk (raw bytes): the header's
    /// `max_chunk_len`, which bounds the decoder's buffers (SPEC §9).
    pub chunk_limit: u32,
    /// Largest rANS chunk (values); no effect on the decoder's memory
    /// (SPEC §5.2, format 3.4).
    pub rans_chunk_limit: u32,
    /// Whether rANS chunks may code a context with an adaptive table where
    /// that is smaller (SPEC §5.5.2, format 3.9); without, 3.8 decoders
    /// read the stream.
    pub adaptive_tables: bool,
    /// How the level table and level headers are laid out (SPEC §3.2 flag
    /// bits 2 and 3, §4.3, §5.1.1): by default `compact` (format 3.12);
    /// `compact-levels` keeps the stream readable by 3.11 decoders,
    /// `fixed` by 3.10 ones.
    pub framing: Framing,
    pub lock_boundary: bool,
    pub admit_quantile: f64,
    /// Units of the input coordinates, for the error metric.
    pub units: Units,
    /// One quantization step per axis (default) or one for all axes.
    pub quantization: Quantization,
    /// Whether axes on a regular lattice (a raster's x and y) keep it
    /// exactly; `None`: in constrained mode only, where every position is
    /// an input vertex or a midpoint (optimal mode's merged vertices would
    /// be rounded to the lattice's cells, and its coarse levels lose
    /// accuracy: on the jacksboro DEM the levels' errors grow 1.4x).
    pub lattice: Option<Lattice>,
    /// Where the simplification's data-parallel passes run.
    pub backend: Backend,
    /// The plane policy of every level (SPEC §7.4); `None`: per level, the
    /// one whose residuals take fewest bytes.
    pub plane: Option<PlanePolicy>,
    /// The wing policy of every level (SPEC §7.4, format 3.2); `None`: per
    /// level, the one whose wing ranks take fewest bytes.
    pub wings: Option<WingPolicy>,
    /// Level header byte 10 of every level (SPEC §5.1, §5.5.5): under
    /// `split-valences` the deficit contexts (format 3.3), `None`: per
    /// level, the ones whose split valences take fewest bytes; under
    /// `every-vertex` the flags' contexts, `Plain` by valence (3.6) or
    /// `SplitHistory` (3.10), `None`: `split-history`, and on a level of
    /// at most 65,536 flags the smaller of the two.
    pub deficits: Option<DeficitContexts>,
    /// How every level reads its records (SPEC §5.1, §7.4, format 3.7);
    /// `None`: per level, positions first where it is allowed (constrained
    /// mode, the plane policy and the wing policy not forced to others
    /// than `height` and `ranks`) and smaller.
    pub records: Option<RecordOrder>,
    /// How every positions-first level breaks its wing choices' ties
    /// (SPEC §5.1, §7.4, format 3.8); `None`: per level, the rule whose
    /// wings code smallest.
    pub ties: Option<Ties>,
    /// How the stream says which vertices split in which round (SPEC
    /// §3.2): by default `every-vertex` (format 3.6), the smaller.
    pub schedule: Schedule,
}

impl Default for EncodeOptions {
    fn default() -> Self {
        EncodeOptions {
            bits: 14,
            levels: 5,
            base_vertices: None,
            position_mode: PositionMode::Constrained,
            max_error: None,
            codec: ChunkCodec::Rans { lanes: 4 },
            chunk_limit: 16 * 1024,
            rans_chunk_limit: splitstream_decoder_core::writer::DEFAULT_RANS_CHUNK_LIMIT,
            adaptive_tables: true,
            framing: Framing::Compact,
            lock_boundary: false,
            admit_quantile: SimplifyOptions::default().admit_quantile,
            units: Units::Linear,
            quantization: Quantization::PerAxis,
            lattice: None,
            backend: Backend::Cpu,
            plane: None,
            wings: None,
            deficits: None,
            records: None,
            ties: None,
            schedule: Schedule::EveryVertex,
        }
    }
}

impl EncodeOptions {
    /// The part of these options that says how the stream is coded, not
    /// what is simplified: what [`transcode`] takes.
    pub fn coding(&self) -> TranscodeOptions {
        TranscodeOptions {
            codec: self.codec,
            chunk_limit: self.chunk_limit,
            rans_chunk_limit: self.rans_chunk_limit,
            adaptive_tables: self.adaptive_tables,
            framing: self.framing,
            plane: self.plane,
            wings: self.wings,
            deficits: self.deficits,
            records: self.records,
            ties: self.ties,
            schedule: self.schedule,
        }
    }

    /// These options with the coding of `coding` ([`EncodeOptions::coding`]).
    pub fn with_coding(self, coding: TranscodeOptions) -> Self {
        let TranscodeOptions {
            codec,
            chunk_limit,
            rans_chunk_limit,
            adaptive_tables,
            framing,
            plane,
            wings,
            deficits,
            records,
            ties,
            schedule,
        } = coding;
        EncodeOptions {
            codec,
            chunk_limit,
            rans_chunk_limit,
            adaptive_tables,
            framing,
            plane,
            wings,
            deficits,
            records,
            ties,
            schedule,
            ..self
        }
    }
}

/// A written stream and what went into it.
pub struct Encoded {
    pub stream: Vec<u8>,
    /// Input vertex id of each decoded vertex (decoded order).
    pub permutation: Vec<u32>,
    /// Rounds per level and vertex counts, for reports.
    pub level_vertex_counts: Vec<u32>,
    pub rounds: usize,
    pub simplify_seconds: f64,
    pub emit_seconds: f64,
    /// The axes quantized exactly on their own lattice
    /// ([`EncodeOptions::lattice`]).
    pub on_lattice: [bool; 3],
    /// What the input check counted (`input::check_mesh`).
    pub input: MeshStats,
    pub check_seconds: f64,
}

/// Why encoding failed.
#[derive(Debug)]
pub enum EncodeError {
    BadOption(String),
    /// The mesh is not one the encoder can take (`input::check_mesh`: the
    /// first offending element).
    Input(MeshError),
    Replay(ReplayError),
    Backend(GpuError),
}

impl std::fmt::Display for EncodeError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            EncodeError::BadOption(s) => write!(f, "{s}"),
            EncodeError::Input(e) => write!(f, "{e}"),
            EncodeError::Replay(e) => write!(f, "{e}"),
            EncodeError::Backend(e) => write!(f, "{e}"),
        }
    }
}

impl std::error::Error for EncodeError {}

/// Encodes a mesh into a stream. The options are checked first
/// ([`EncodeOptions::check`]), then the mesh (`input::check_mesh`: an
/// oriented 2-manifold with finite coordinates, every vertex used, no
/// degenerate or duplicate triangle), each refusal a typed error naming
/// the first offending element.
pub fn encode(
    mesh: &Mesh,
    options: &EncodeOptions,
    progress: impl FnMut(usize),
) -> Result<Encoded, EncodeError> {
    options.check()?;
    let (input, check_seconds) = timed_check(mesh)?;
    let quantized = quantize_for(mesh, options);
    encode_checked(
        Cow::Owned(quantized),
        options,
        progress,
        input,
        check_seconds,
    )
}

/// `check_mesh` of `mesh`, and how long it took.
fn timed_check(mesh: &Mesh) -> Result<(MeshStats, f64), EncodeError> {
    let started = std::time::Instant::now();
    let stats = check_mesh(mesh).map_err(EncodeError::Input)?;
    Ok((stats, started.elapsed().as_secs_f64()))
}

/// Largest number of levels [`EncodeOptions::levels`] may ask for: each
/// level about doubles the vertex count, so 64 levels cover any mesh.
pub const MAX_LEVELS: usize = 64;

impl EncodeOptions {
    /// What the stream writer is told for `mesh` under these options: its
    /// quantization and the options' coding and framing.
    pub fn stream_params(&self, mesh: &QuantizedMesh) -> StreamParams {
        StreamParams {
            position_mode: self.position_mode,
            bits: mesh.bits,
            origin: mesh.origin,
            scale: mesh.scale,
            codec: self.codec,
            chunk_limit: self.chunk_limit,
            rans_chunk_limit: self.rans_chunk_limit,
            schedule: self.schedule,
            adaptive_tables: self.adaptive_tables,
            framing: self.framing,
        }
    }

    /// Refuses what the types allow but the format or the encoder does not,
    /// with one message naming the `splitstream encode` option: [`encode`]
    /// and [`encode_quantized`] call it first (a library caller gets the
    /// same refusal as the command line, instead of a stream that no
    /// decoder accepts).
    pub fn check(&self) -> Result<(), EncodeError> {
        let bad = |s: String| Err(EncodeError::BadOption(s));
        if !(1..=31).contains(&self.bits) {
            return bad(format!("--bits {} is outside 1..=31", self.bits));
        }
        if !(1..=MAX_LEVELS).contains(&self.levels) {
            return bad(format!(
                "--levels {} is outside 1..={MAX_LEVELS}",
                self.levels
            ));
        }
        if !(self.admit_quantile > 0.0 && self.admit_quantile <= 1.0) {
            return bad(format!("--admit {} is outside (0, 1]", self.admit_quantile));
        }
        if let Some(e) = self.max_error
            && !(e >= 0.0 && e.is_finite())
        {
            return bad(format!(
                "--max-error {e} is not a finite error of 0 or more"
            ));
        }
        check_records(self.records, self.position_mode, self.plane, self.wings)
            .map_err(EncodeError::BadOption)?;
        check_coding(self.codec, self.chunk_limit, self.rans_chunk_limit)
            .map_err(EncodeError::BadOption)
    }
}

/// `--records positions-first` needs what a positions-first level
/// declares (SPEC §5.1, 3.7): constrained mode, the plane policy `height`
/// and the wing policy `ranks` (or neither forced).
pub fn check_records(
    records: Option<RecordOrder>,
    mode: PositionMode,
    plane: Option<PlanePolicy>,
    wings: Option<WingPolicy>,
) -> Result<(), String> {
    if records == Some(RecordOrder::PositionsFirst) && !positions_first_allowed(mode, plane, wings)
    {
        return Err(
            "--records positions-first needs --position constrained, --plane height or auto \
                    and --wings ranks or auto"
                .into(),
        );
    }
    Ok(())
}

/// Meshes with fewer vertices than this get one rANS lane from
/// [`lanes_for`].
pub const ONE_LANE_BELOW_VERTICES: usize = 1 << 18;

/// The rANS lane count `splitstream encode` and `transcode` write when
/// `--lanes` is not given: 1 for a mesh of fewer than
/// [`ONE_LANE_BELOW_VERTICES`] vertices, 4 for a larger one.
///
/// Lanes let a decoder split a chunk's entropy decoding over cores or GPU
/// lanes (SPEC §5.5.3); one thread reads 1 and 4 lanes alike (armadillo
/// decodes in 12.0–12.2 ms either way). Each lane costs a 4-byte state, a
/// length and a partly filled last byte in every chunk: 4 lanes instead of
/// 1 add 0.4 % to the 26k–139k-vertex real meshes (0.04–0.12 bits per
/// vertex) and 2.4 % to the 1,839-vertex bunny, whose levels nobody
/// would decode on several cores, and 0.13 % to the 1M-vertex terrain,
/// whose large levels are what lanes are for (encoder/BENCHMARKS.md,
/// "Lanes by mesh size"). The threshold is the demo's default terrain,
/// 512 × 512 vertices.
pub fn lanes_for(vertices: usize) -> u8 {
    if vertices < ONE_LANE_BELOW_VERTICES {
        1
    } else {
        4
    }
}

/// The fewest values the command line lets an rANS chunk be limited to.
/// Each chunk has tables of its own, and the writer keeps every chunk's
/// costed tables until the level is framed: a limit of 1 took armadillo's
/// encoding to 2.2 GB and 7.8 s for a stream no smaller than at 16 (204
/// MB). Below the cut search's 4,096-value steps a limit only cuts every
/// chunk that long, and the decoder's memory does not depend on it
/// (format 3.4). The library takes any limit from 1 on: tiny chunks are
/// how tests and conformance vectors reach chunk boundaries.
pub const MIN_RANS_CHUNK: u32 = 256;

/// The coding options' own rules, shared by [`EncodeOptions::check`] and
/// [`transcode()`]: chunks of at least one byte or value, and 1 to 32 rANS
/// lanes (SPEC §5.5.3; the writer would put any other count in a header
/// that every decoder refuses).
pub fn check_coding(
    codec: ChunkCodec,
    chunk_limit: u32,
    rans_chunk_limit: u32,
) -> Result<(), String> {
    if chunk_limit == 0 {
        return Err("--chunk-size must be at least 1".into());
    }
    if rans_chunk_limit == 0 {
        return Err("--rans-chunk must be at least 1".into());
    }
    if let ChunkCodec::Rans { lanes } | ChunkCodec::RansAlways { lanes } = codec
        && !(1..=MAX_LANES).contains(&lanes)
    {
        return Err(format!("--lanes {lanes} is outside 1..={MAX_LANES}"));
    }
    Ok(())
}

/// The quantized mesh [`encode`] codes: `options`' bits, units, steps and
/// lattice rule.
pub fn quantize_for(mesh: &Mesh, options: &EncodeOptions) -> QuantizedMesh {
    let lattice = options.lattice.unwrap_or(match options.position_mode {
        PositionMode::Constrained => Lattice::Keep,
        PositionMode::Optimal => Lattice::Ignore,
    });
    quantize_with(
        mesh,
        options.bits,
        options.units,
        options.quantization,
        lattice,
    )
}

/// Encodes an already quantized mesh (`options.bits` and the quantization
/// options are the mesh's own). It is checked as [`encode`] checks a mesh,
/// in its grid coordinates: a mesh built by hand gets the same typed
/// errors, never a panic.
pub fn encode_quantized(
    mesh: &QuantizedMesh,
    options: &EncodeOptions,
    progress: impl FnMut(usize),
) -> Result<Encoded, EncodeError> {
    options.check()?;
    let started = std::time::Instant::now();
    let input = mesh.check().map_err(|e| match e {
        GridError::Mesh(e) => EncodeError::Input(e),
        other => EncodeError::BadOption(other.to_string()),
    })?;
    let check_seconds = started.elapsed().as_secs_f64();
    encode_checked(Cow::Borrowed(mesh), options, progress, input, check_seconds)
}

/// [`encode_quantized`] of a mesh whose check passed with `input`; an
/// owned mesh is dropped once renumbered (about 35 bytes per vertex less
/// at the encoder's peak: 703,620 -> 668,936 KB encoding the 1M terrain
/// from a PLY file).
fn encode_checked(
    mesh: Cow<'_, QuantizedMesh>,
    options: &EncodeOptions,
    progress: impl FnMut(usize),
    input: MeshStats,
    check_seconds: f64,
) -> Result<Encoded, EncodeError> {
    let n = mesh.positions.len();
    let shift = (options.levels - 1).min(40) as u32;
    let base = options
        .base_vertices
        .unwrap_or(n >> shift)
        .clamp(4.min(n), n);
    // Simplify on to a small seed: level 0 codes the rounds from the seed
    // up to the base mesh, far more compactly than a plain base mesh.
    let seed_target = SEED_VERTICES.min(base);
    let simplify_options = SimplifyOptions {
        target_vertices: seed_target,
        max_error: options.max_error,
        constrained: options.position_mode == PositionMode::Constrained,
        lock_boundary: options.lock_boundary,
        admit_quantile: options.admit_quantile,
        ..SimplifyOptions::default()
    };
    let started = std::time::Instant::now();
    // Simplified and replayed in a spatial order (`spatial_order`: the
    // passes' neighbours then share cache lines); the permutation is mapped
    // back to the input's ids at the end.
    let (ordered, order) = spatially_ordered(&Checked::already(&mesh, input));
    drop(mesh);
    let mesh = &ordered;
    let checked = Checked::already(mesh, input);
    let simplification = simplify_on(options.backend, &checked, &simplify_options, progress)
        .map_err(EncodeError::Backend)?;
    let simplify_seconds = started.elapsed().as_secs_f64();
    let started = std::time::Instant::now();
    let plan = plan_levels(&simplification, options.levels, base);
    let params = options.stream_params(mesh);
    let replayed = replay(
        mesh,
        &simplification,
        &plan,
        &params,
        ReplayOptions {
            plane: options.plane,
            wings: options.wings,
            deficits: options.deficits,
            records: options.records,
            ties: options.ties,
            final_hash: false,
        },
    )
    .map_err(EncodeError::Replay)?;
    let level_vertex_counts = replayed
        .levels
        .iter()
        .map(|l: &LevelPayload| l.vertex_count)
        .collect();
    let rounds = replayed.levels.iter().map(|l| l.round_splits.len()).sum();
    // The replay framed (entropy coded, chunked) each level beside the
    // replay of the next one.
    let stream = assemble_stream(&params, &replayed.levels, replayed.framed);
    Ok(Encoded {
        stream,
        permutation: replayed
            .permutation
            .into_iter()
            .map(|v| order[v as usize])
            .collect(),
        level_vertex_counts,
        rounds,
        simplify_seconds,
        emit_seconds: started.elapsed().as_secs_f64(),
        on_lattice: mesh.on_lattice,
        input,
        check_seconds,
    })
}
