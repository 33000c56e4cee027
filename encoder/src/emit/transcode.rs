//! Transcoding: a stream written again from its own refinement, without
//! the input mesh.
//!
//! The stream is decoded with decoder-core, every split record is kept as
//! the collapse it reverses (in the stream's own vertex ids), and the
//! emission replays those collapses as it replays a simplification
//! ([`replay`]). The rounds, splits and positions are the stream's, so the
//! new stream reaches the same state after every round (the same state
//! hashes, SPEC §8); what changes is how they are coded: another codec,
//! lane count or chunk size (smaller chunks lower the decoder's buffers,
//! SPEC §9), and each level's plane, wing and deficit coding chosen again,
//! so that a stream written by an older encoder gets the newest coding
//! (SPEC §1).

use splitstream_decoder_core::Framing;
use splitstream_decoder_core::limits::LEAF;
use splitstream_decoder_core::owned::OwnedWorkspace;
use splitstream_decoder_core::writer::{ChunkCodec, StreamParams, assemble_stream};
use splitstream_decoder_core::{
    DeficitContexts, MeshState, PlanePolicy, RecordOrder, Ring, Schedule, SplitObserver,
    SplitRecord, Ties, WingPolicy,
};

use super::levels::LevelPlan;
use super::replay::{ReplayError, ReplayOptions, replay};
use super::{EncodeOptions, check_coding, check_records};
use crate::corner_table::{CornerTable, Fan};
use crate::quantize::QuantizedMesh;
use crate::simplify::{Collapse, NO_SPLIT, Simplification};

/// How [`transcode`] codes the stream it writes.
#[derive(Clone, Copy, Debug)]
pub struct TranscodeOptions {
    pub codec: ChunkCodec,
    /// Largest stored or deflate chunk (raw bytes): the header's
    /// `max_chunk_len`, which bounds the decoder's buffers (SPEC §9).
    pub chunk_limit: u32,
    /// Largest rANS chunk (values); no effect on the decoder's memory
    /// (SPEC §5.2, format 3.4).
    pub rans_chunk_limit: u32,
    /// Whether rANS chunks may code a context with an adaptive table where
    /// that is smaller (SPEC §5.5.2, format 3.9).
    pub adaptive_tables: bool,
    /// How the level headers are laid out (SPEC §3.2 flag bit 2, §5.1.1):
    /// by default `compact` (format 3.11); `fixed` keeps the stream
    /// readable by 3.10 decoders.
    pub framing: Framing,
    /// The plane policy of every level; `None`: chosen per level by size.
    pub plane: Option<PlanePolicy>,
    /// The wing policy of every level; `None`: chosen per level by size.
    pub wings: Option<WingPolicy>,
    /// Level header byte 10 of every level (as [`super::EncodeOptions`]'s
    /// `deficits`): the deficit contexts, or under `every-vertex` the flags'
    /// contexts; `None`: chosen per level.
    pub deficits: Option<DeficitContexts>,
    /// The record order of every level (format 3.7); `None`: chosen per
    /// level by size where positions first is allowed.
    pub records: Option<RecordOrder>,
    /// The tie rule of every positions-first level (format 3.8); `None`:
    /// chosen per level by size.
    pub ties: Option<Ties>,
    /// The schedule of the stream written (SPEC §3.2), whatever the
    /// input's.
    pub schedule: Schedule,
}

impl Default for TranscodeOptions {
    /// The reference encoder's defaults: rANS in 4 lanes, byte-codec chunks
    /// of 16 KiB, rANS chunks of up to 262,144 values
    /// (`DEFAULT_RANS_CHUNK_LIMIT`), every policy chosen by size: those of
    /// [`EncodeOptions::default`], which holds them.
    fn default() -> Self {
        EncodeOptions::default().coding()
    }
}

/// A transcoded stream.
#[derive(Debug)]
pub struct Transcoded {
    pub stream: Vec<u8>,
    /// The state hash after the last round, the same for both streams when
    /// their schedules are (SPEC §8 hashes the per-vertex byte, §6.2).
    pub final_hash: u64,
    pub levels: usize,
    pub rounds: usize,
}

/// Why a stream could not be transcoded.
#[derive(Debug)]
pub enum TranscodeError {
    /// The input stream does not decode (SPEC §10).
    Decode(splitstream_decoder_core::Error),
    /// The replay refused the refinement, or reached another state: a bug.
    Replay(ReplayError),
    BadOption(String),
}

impl std::fmt::Display for TranscodeError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            TranscodeError::Decode(e) => write!(f, "the stream does not decode: {e}"),
            TranscodeError::Replay(e) => write!(f, "{e}"),
            TranscodeError::BadOption(s) => write!(f, "{s}"),
        }
    }
}

impl std::error::Error for TranscodeError {}

impl From<splitstream_decoder_core::Error> for TranscodeError {
    fn from(e: splitstream_decoder_core::Error) -> Self {
        TranscodeError::Decode(e)
    }
}

/// Writes `stream` again under `options` (see the module documentation).
pub fn transcode(stream: &[u8], options: &TranscodeOptions) -> Result<Transcoded, TranscodeError> {
    check_coding(options.codec, options.chunk_limit, options.rans_chunk_limit)
        .map_err(TranscodeError::BadOption)?;
    let mut refinement = Refinement::decode(stream)?;
    check_records(
        options.records,
        refinement.position_mode,
        options.plane,
        options.wings,
    )
    .map_err(TranscodeError::BadOption)?;
    let params = StreamParams {
        position_mode: refinement.position_mode,
        bits: refinement.mesh.bits,
        origin: refinement.mesh.origin,
        scale: refinement.mesh.scale,
        codec: options.codec,
        chunk_limit: options.chunk_limit,
        rans_chunk_limit: options.rans_chunk_limit,
        schedule: options.schedule,
        adaptive_tables: options.adaptive_tables,
        framing: options.framing,
    };
    let simplification = refinement.simplification();
    let replayed = replay(
        &refinement.mesh,
        &simplification,
        &refinement.plan,
        &params,
        ReplayOptions {
            plane: options.plane,
            wings: options.wings,
            deficits: options.deficits,
            records: options.records,
            ties: options.ties,
            final_hash: true,
        },
    )
    .map_err(TranscodeError::Replay)?;
    let final_hash = replayed.final_hash.expect("asked for");
    // Under another schedule the per-vertex byte the hash covers differs
    // (SPEC §6.2, §8); the replay has checked positions and triangles.
    if options.schedule == refinement.schedule && final_hash != refinement.final_hash {
        return Err(TranscodeError::Replay(ReplayError(format!(
            "the transcoded stream ends in state {final_hash:016x}, the input in {:016x}",
            refinement.final_hash
        ))));
    }
    let rounds = replayed.levels.iter().map(|l| l.round_splits.len()).sum();
    let levels = replayed.levels.len();
    Ok(Transcoded {
        stream: assemble_stream(&params, &replayed.levels, replayed.framed),
        final_hash,
        levels,
        rounds,
    })
}

/// What a decoded stream holds: its seed, its rounds as collapses (in
/// decoding order), its level structure and its final mesh.
struct Refinement {
    position_mode: splitstream_decoder_core::PositionMode,
    /// The input stream's schedule (SPEC §3.2).
    schedule: Schedule,
    /// The final mesh, in the stream's vertex ids (the replay's input ids).
    mesh: QuantizedMesh,
    seed_positions: Vec<[u32; 3]>,
    seed_triangles: Vec<[u32; 3]>,
    seed_deficits: Vec<u8>,
    /// The seed's split valences where the stream codes none (the schedule
    /// `every-vertex`: [`derive_split_valences`]); otherwise they follow
    /// from `seed_deficits`.
    seed_split_valences: Option<Vec<u8>>,
    /// Every round's collapses, in decoding order.
    rounds: Vec<Vec<Collapse>>,
    plan: LevelPlan,
    final_hash: u64,
}

/// The split valence of a vertex with `deficit` at `valence` (SPEC §7.4:
/// valence + deficit), or [`NO_SPLIT`] for a leaf. The decoder holds every
/// vertex to valence + deficit ≤ 255 (SPEC §6.2, `valence-overflow`), so
/// every split valence of a decoded stream fits the encoder's `u8`.
fn split_valence(deficit: u8, valence: usize) -> u8 {
    if deficit == LEAF {
        return NO_SPLIT;
    }
    u8::try_from(deficit as usize + valence).unwrap_or(u8::MAX)
}

/// The split valences of a stream under the schedule `every-vertex`, which
/// codes none (SPEC §6.2): a vertex's split valence is its valence when it
/// next splits, the ring length of that split, or [`NO_SPLIT`] when it
/// never splits again. Sets them on the collapses (`rounds`, whose splits
/// have the ring lengths `ring_lengths` in order) and returns those of the
/// `v0` seed vertices.
fn derive_split_valences(rounds: &mut [Vec<Collapse>], ring_lengths: &[u8], v0: usize) -> Vec<u8> {
    #[derive(Clone, Copy)]
    enum Owner {
        Seed,
        P(usize),
        C(usize),
    }
    let splits: usize = rounds.iter().map(Vec::len).sum();
    let mut owner = vec![Owner::Seed; v0 + splits];
    let mut seed_split_valence = vec![NO_SPLIT; v0];
    let (mut sv_p, mut sv_c) = (vec![NO_SPLIT; splits], vec![NO_SPLIT; splits]);
    for (f, col) in rounds.iter().flatten().enumerate() {
        let k = ring_lengths.get(f).copied().unwrap_or(NO_SPLIT);
        match owner.get(col.p as usize) {
            Some(Owner::Seed) => seed_split_valence[col.p as usize] = k,
            Some(&Owner::P(g)) => sv_p[g] = k,
            Some(&Owner::C(g)) => sv_c[g] = k,
            None => {}
        }
        if let Some(o) = owner.get_mut(col.p as usize) {
            *o = Owner::P(f);
        }
        if let Some(o) = owner.get_mut(col.c as usize) {
            *o = Owner::C(f);
        }
    }
    for (f, col) in rounds.iter_mut().flatten().enumerate() {
        col.split_valence_p = sv_p[f];
        col.split_valence_c = sv_c[f];
    }
    seed_split_valence
}

/// Keeps each split record of a round as the collapse it reverses: P is
/// the split vertex (it keeps its id), C the vertex the split adds (the
/// next id), the wings the ring entries at `o` and `o + d` (SPEC §7.4).
#[derive(Default)]
struct Recorder {
    round: Vec<Collapse>,
    /// Each split's ring length (its vertex's valence when it splits), in
    /// decoding order: the split valences of a stream that codes none.
    ring_lengths: Vec<u8>,
}

impl SplitObserver for Recorder {
    fn record(&mut self, state: &MeshState<'_>, r: u32, ring: &Ring, rec: &SplitRecord) {
        let entries = ring.vertices();
        let (k, o, d) = (
            entries.len(),
            rec.wing_offset as usize,
            rec.wing_distance as usize,
        );
        let c = state.vertex_count();
        self.ring_lengths.push(k.min(255) as u8);
        // Split valence = valence right after the split + deficit (§7.4);
        // under `every-vertex` the bytes are valences, and the split
        // valences are derived after the decode (`derive_split_valences`).
        let split_valence_p = split_valence(rec.deficit_p, d + 2);
        let split_valence_c = split_valence(rec.deficit_c, k - d + 2);
        self.round.push(Collapse {
            p: r,
            c,
            wing_a: entries[o],
            wing_b: entries[o + d],
            position_p: rec.position_p,
            position_c: rec.position_c,
            position_r: state.positions()[r as usize],
            split_valence_p,
            split_valence_c,
            error: 0.0,
            distance: 0.0,
        });
    }
}

impl Refinement {
    /// Decodes the whole stream with decoder-core, keeping its records.
    fn decode(stream: &[u8]) -> Result<Refinement, TranscodeError> {
        let mut workspace = OwnedWorkspace::for_stream(stream)?;
        let mut decoder = workspace.decoder(stream)?;
        let header = *decoder.header();
        let table = decoder.level_table();
        let errors: Vec<f32> = (0..table.len())
            .map(|k| table.get(k).geometric_error)
            .collect();
        let mut recorder = Recorder::default();
        let mut rounds = Vec::new();
        let mut plan_rounds = Vec::new();
        let mut seed = None;
        while let Some(k) = decoder.next_level() {
            let bytes = decoder.level_bytes(k, stream)?;
            let mut level = decoder.begin_level(k, bytes)?;
            if k == 0 {
                // The seed is decoded by `begin_level`.
                let state = level.state();
                let (v0, t0) = (
                    state.vertex_count() as usize,
                    state.triangle_count() as usize,
                );
                seed = Some((
                    state.positions()[..v0].to_vec(),
                    state.triangles()[..t0].to_vec(),
                    state.deficits()[..v0].to_vec(),
                ));
            }
            let mut level_rounds = Vec::new();
            while level.next_round_observed(&mut recorder)?.is_some() {
                level_rounds.push(rounds.len());
                rounds.push(std::mem::take(&mut recorder.round));
            }
            plan_rounds.push(level_rounds);
        }
        // `for_stream` sizes the workspace for every level, so all decode.
        let (seed_positions, seed_triangles, seed_deficits) = seed.ok_or(
            TranscodeError::Decode(splitstream_decoder_core::Error::Truncated),
        )?;
        // Simplification steps run in the opposite order to the rounds.
        let last = rounds.len().saturating_sub(1);
        let plan = LevelPlan {
            rounds: plan_rounds
                .into_iter()
                .map(|level| level.into_iter().map(|t| last - t).collect())
                .collect(),
            errors,
        };
        let seed_split_valences = (header.schedule == Schedule::EveryVertex).then(|| {
            derive_split_valences(&mut rounds, &recorder.ring_lengths, seed_positions.len())
        });
        let mesh = QuantizedMesh {
            positions: decoder.positions().to_vec(),
            triangles: decoder.triangles().to_vec(),
            bits: header.bits,
            origin: header.origin,
            scale: header.scale,
            metric: header.scale,
            on_lattice: [false; 3],
        };
        Ok(Refinement {
            position_mode: header.position_mode,
            schedule: header.schedule,
            mesh,
            seed_positions,
            seed_triangles,
            seed_deficits,
            seed_split_valences,
            rounds,
            plan,
            final_hash: decoder.state_hash(),
        })
    }

    /// The simplification these rounds reverse: the seed mesh is what it
    /// left, its steps are the rounds in reverse order. Takes the rounds (they become the steps: no copy of the collapse
    /// records, 72 bytes each).
    fn simplification(&mut self) -> Simplification {
        let n = self.mesh.positions.len();
        let v0 = self.seed_positions.len();
        let table = CornerTable::new(n, &self.seed_triangles);
        // The seed's split valences: deficit + valence, the ghost counted
        // on a boundary (SPEC §6.2), as the replay computes them back.
        let mut split_valences = vec![NO_SPLIT; n];
        if let Some(derived) = &self.seed_split_valences {
            split_valences[..derived.len()].copy_from_slice(derived);
        } else {
            let mut fan = Fan::default();
            for (v, &deficit) in self.seed_deficits.iter().enumerate() {
                table.fan(v as u32, &mut fan);
                let valence = fan.corners.len() + if fan.boundary { 2 } else { 0 };
                split_valences[v] = split_valence(deficit, valence);
            }
        }
        let mut positions = self.mesh.positions.clone();
        positions[..v0].copy_from_slice(&self.seed_positions);
        let mut steps = std::mem::take(&mut self.rounds);
        steps.reverse();
        let step_errors = vec![0.0; steps.len()];
        Simplification {
            steps,
            table,
            positions,
            split_valence: split_valences,
            alive: (0..n).map(|v| v < v0).collect(),
            alive_count: v0,
            step_errors,
        }
    }
}
