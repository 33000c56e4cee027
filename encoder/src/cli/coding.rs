//! How a stream's substreams are coded: the options `encode` and
//! `transcode` share.

use splitstream_decoder_core::writer::ChunkCodec;
use splitstream_decoder_core::{
    DeficitContexts, Framing, PlanePolicy, RecordOrder, Schedule, Ties, WingPolicy,
};

use super::{
    CliResult, Codec, DeficitsArg, FlagsArg, PlaneArg, RecordsArg, ScheduleArg, TiesArg, WingsArg,
};
use splitstream_encoder::emit::{MIN_RANS_CHUNK, TranscodeOptions, check_coding, lanes_for};

/// `--tables`: how rANS chunks code their contexts (SPEC §5.5.2).
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum TablesArg {
    /// Adaptive tables where smaller (format 3.9).
    Adaptive,
    /// A frequency table for every context (3.8 decoders read the stream).
    Static,
}

/// `--framing`: how the level table and level headers are laid out (SPEC
/// §4.3, §5.1.1).
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum FramingArg {
    /// Varint counts and lengths in the level table (format 3.12: 8–12
    /// bytes a level instead of 32) and in the level headers (3.11: 7–10
    /// bytes a chunk and 1–2 a round instead of 16 and 4).
    Compact,
    /// Compact level headers and the fixed level table (3.11 decoders read
    /// the stream).
    CompactLevels,
    /// Fixed-width fields (3.10 decoders read the stream).
    Fixed,
}

#[derive(clap::Args)]
pub struct CodingArgs {
    #[arg(long, value_enum, default_value_t = Codec::Rans)]
    pub codec: Codec,
    /// rANS lanes per chunk (1..=32): independent streams a decoder may
    /// decode in parallel [default: 1 for a mesh of fewer than 262,144
    /// vertices, 4 for a larger one: each lane costs a few bytes a chunk,
    /// and only large levels gain from decoding them apart]
    #[arg(long, value_parser = clap::value_parser!(u8).range(1..=32))]
    pub lanes: Option<u8>,
    /// Largest stored or deflate chunk in bytes: bounds the decoder's
    /// buffers (7 chunks, or 1,856 bytes each at least, SPEC §9).
    #[arg(long, default_value_t = 16384)]
    pub chunk_size: u32,
    /// Longest rANS chunk in values. Each chunk has its own tables: the
    /// encoder cuts a substream where tables fitted to its parts cost less
    /// than one table for the whole (at 4,096-value steps; a limit of
    /// 4,096 or less cuts every chunk that long; at least 256). No effect
    /// on the decoder's memory (format 3.4).
    #[arg(long, default_value_t = splitstream_decoder_core::writer::DEFAULT_RANS_CHUNK_LIMIT)]
    pub rans_chunk: u32,
    /// How rANS chunks code each context: `adaptive` lets a context whose
    /// values take few tokens be coded by probabilities that follow them,
    /// with no table sent, where that is smaller (format 3.9); `static`
    /// sends a frequency table for every context (read by 3.8 decoders)
    /// (SPEC §5.5.2).
    #[arg(long, value_enum, default_value_t = TablesArg::Adaptive)]
    pub tables: TablesArg,
    /// How the level table and each level header are laid out: `compact`,
    /// their counts and lengths as varints (format 3.12; 480–1,000 bytes
    /// less a 5-level stream, a sixth of a 33 × 33 terrain tile),
    /// `compact-levels`, the level headers only (3.11 decoders read the
    /// stream), or `fixed`, 32-bit fields (3.10 decoders read the stream)
    /// (SPEC §4.3, §5.1.1).
    #[arg(long, value_enum, default_value_t = FramingArg::Compact)]
    pub framing: FramingArg,
    /// Which axis of each position residual the split's plane predicts, or
    /// `height`: z from the surface of the split vertex's fan (terrain,
    /// format 3.1) (SPEC §7.4); `auto` picks the cheapest per level.
    #[arg(long, value_enum, default_value_t = PlaneArg::Auto)]
    pub plane: PlaneArg,
    /// How each level names its splits' wings: `ranks` in ring order, or
    /// `near`/`near-xy`, in the order of their distance to the ring's
    /// centre (format 3.2) (SPEC §7.4); `auto` picks the cheapest per level.
    #[arg(long, value_enum, default_value_t = WingsArg::Auto)]
    pub wings: WingsArg,
    /// Which contexts code each level's split valences: `plain`, or
    /// `valence`, by the valences of P and C right after the split (format
    /// 3.3) (SPEC §5.5.5); `auto` picks the cheaper per level.
    #[arg(long, value_enum, default_value_t = DeficitsArg::Auto)]
    pub deficits: DeficitsArg,
    /// Which contexts code each level's flags under the schedule
    /// `every-vertex`: `valence`, by the vertex's valence (format 3.6), or
    /// `split-history`, also by whether the vertex has split in the level
    /// (format 3.10) (SPEC §5.5.5); `auto` takes `split-history`, and on a
    /// level of at most 65,536 flags the smaller of the two.
    #[arg(long, value_enum, default_value_t = FlagsArg::Auto)]
    pub flags: FlagsArg,
    /// How each level reads its split records: `wings-first` (every 3.x
    /// decoder, the fastest to decode), or `positions-first`, the new
    /// vertex as a rank among its fan's free lattice points, then the
    /// wings among the pairs that keep the triangles up (rasters on their
    /// lattice, constrained mode, format 3.7) (SPEC §7.4); `auto` picks the
    /// smaller per level.
    #[arg(long, value_enum, default_value_t = RecordsArg::Auto)]
    pub records: RecordsArg,
    /// How a positions-first level orders wing choices that see the new
    /// edge under the same angle: `ring` by ring position (format 3.7), or
    /// `rising`/`falling`, choices whose new edges would run along the
    /// other diagonal of the raster's cells last (format 3.8) (SPEC §7.4);
    /// `auto` picks the cheapest per level.
    #[arg(long, value_enum, default_value_t = TiesArg::Auto)]
    pub ties: TiesArg,
    /// How the stream says which vertices split in which round:
    /// `every-vertex`, a flag for every vertex (format 3.6, smaller), or
    /// `split-valences`, the paper's split valences (read by every 3.x
    /// decoder) (SPEC §3.2, §7.3). `--deficits` applies to
    /// `split-valences` only, `--flags` to `every-vertex` only.
    #[arg(long, value_enum, default_value_t = ScheduleArg::EveryVertex)]
    pub schedule: ScheduleArg,
}

impl CodingArgs {
    /// Refuses what clap cannot (a chunk size of 0) before any input is
    /// read, by the library's own rules.
    pub fn check(&self) -> CliResult {
        // Any mesh size gives a valid lane count: check with the smallest.
        if self.rans_chunk < MIN_RANS_CHUNK {
            return Err(format!(
                "--rans-chunk {} is below {MIN_RANS_CHUNK} values (smaller chunks only add tables)",
                self.rans_chunk
            ));
        }
        check_coding(self.chunk_codec(0), self.chunk_size, self.rans_chunk)
    }

    /// The coding the flags ask for, for a mesh of `vertices` vertices
    /// (the lane count when `--lanes` is not given: [`lanes_for`]), as the
    /// library takes it (`encode` sets it into its `EncodeOptions` with
    /// `with_coding`).
    pub fn options(&self, vertices: usize) -> TranscodeOptions {
        TranscodeOptions {
            codec: self.chunk_codec(vertices),
            chunk_limit: self.chunk_size,
            rans_chunk_limit: self.rans_chunk,
            adaptive_tables: self.tables == TablesArg::Adaptive,
            framing: match self.framing {
                FramingArg::Compact => Framing::Compact,
                FramingArg::CompactLevels => Framing::CompactLevels,
                FramingArg::Fixed => Framing::Fixed,
            },
            plane: self.plane(),
            wings: self.wings(),
            deficits: self.deficits(),
            records: self.records(),
            ties: self.ties(),
            schedule: self.schedule(),
        }
    }

    /// The codec for a mesh of `vertices` vertices.
    pub fn chunk_codec(&self, vertices: usize) -> ChunkCodec {
        let lanes = self.lanes.unwrap_or_else(|| lanes_for(vertices));
        match self.codec {
            Codec::Rans => ChunkCodec::Rans { lanes },
            Codec::Deflate => ChunkCodec::Deflate(9),
            Codec::Stored => ChunkCodec::Stored,
        }
    }

    pub fn plane(&self) -> Option<PlanePolicy> {
        self.plane.policy()
    }

    pub fn wings(&self) -> Option<WingPolicy> {
        self.wings.policy()
    }

    /// Level header byte 10 (SPEC §5.1): the deficit contexts under
    /// `split-valences`, the flags' under `every-vertex`.
    pub fn deficits(&self) -> Option<DeficitContexts> {
        match self.schedule() {
            Schedule::SplitValences => self.deficits.contexts(),
            Schedule::EveryVertex => self.flags.contexts(),
        }
    }

    pub fn records(&self) -> Option<RecordOrder> {
        self.records.order()
    }

    pub fn ties(&self) -> Option<Ties> {
        self.ties.ties()
    }

    pub fn schedule(&self) -> Schedule {
        self.schedule.into()
    }
}
