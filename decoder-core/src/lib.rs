//! Reference decoder of the splitstream progressive mesh format.
//!
//! `#![no_std]`, no allocation, no `unsafe`: the caller hands in every byte
//! the decoder uses, sized from the stream header ([`Layout`]), and the
//! decoder never panics, reads out of bounds or loops without bound on any
//! input. With `SPEC.md` beside it, this crate *defines* the format; each
//! module names the SPEC section it implements.
//!
//! ```no_run
//! use splitstream_decoder_core::{Decoder, Inflater, Layout};
//! # let stream: &[u8] = &[];
//! let mut inflater = Inflater::new();
//! let needed = splitstream_decoder_core::workspace_len(stream).unwrap();
//! let mut workspace = vec![0u8; needed];
//! let mut decoder = Decoder::new(stream, &mut workspace, &mut inflater).unwrap();
//! decoder.decode_available(stream).unwrap();
//! println!("{} triangles, hash {:016x}", decoder.triangles().len(), decoder.state_hash());
//! ```
#![no_std]
#![forbid(unsafe_code)]

#[cfg(feature = "alloc")]
extern crate alloc;

mod base;
mod bytes;
pub mod context;
pub mod corner_refs;
mod decoder;
#[cfg(feature = "alloc")]
mod deflate_trial;
mod error;
#[cfg(feature = "alloc")]
pub mod handmade;
mod hash;
mod header;
mod inflate;
mod layout;
mod level_header;
mod level_table;
pub mod limits;
#[cfg(feature = "alloc")]
pub mod owned;
pub mod pipe;
pub mod positions_first;
pub mod predict;
mod rans;
#[cfg(feature = "alloc")]
mod rans_segments;
#[cfg(feature = "alloc")]
mod rans_writer;
pub mod record;
mod ring;
mod round;
mod split;
mod state;
pub mod substream;
pub mod symbols;
pub mod wing_order;
#[cfg(feature = "alloc")]
pub mod writer;

pub use bytes::crc32;
pub use context::DeficitContexts;
pub use corner_refs::CornerRefs;
pub use decoder::{Decoder, LevelDecoder, RoundInfo, SplitObserver, declared_layout, layout_for};
pub use error::{ChecksumScope, Error};
pub use hash::Fnv1a;
pub use header::{Framing, Header, PositionMode, Schedule};
pub use inflate::Inflater;
pub use layout::Layout;
pub use level_header::{ChunkEntry, LevelHeader, LevelRules, SplitCounts};
pub use level_table::{
    LevelInfo, LevelTable, fixed_head_len, level_within_error, write_level_table,
};
pub use positions_first::{RecordOrder, Ties};
pub use predict::{
    ArcMeans, Plane, PlanePolicy, SplitFan, Target, add_residual, arc_means, constrained_positions,
    height_prediction, predict, residual, surface_height,
};
pub use rans::{table_kinds, token_of};
pub use ring::Ring;
pub use round::{FANS_AHEAD_FROM_VERTICES, RecordSource, RoundStats};
pub use split::{SplitOutcome, SplitRecord};
pub use state::{MeshState, StateMemory, next, prev};
pub use symbols::WingCandidates;
pub use wing_order::WingPolicy;
#[cfg(feature = "alloc")]
pub use writer::compact_level_table;

// The README's Rust examples run as doctests, so they follow the API.
#[cfg(doctest)]
#[doc = include_str!("../README.md")]
struct ReadmeExamples;

/// Bytes of workspace (with alignment slack) needed to decode all of
/// `stream`, from its header and level table alone (SPEC §9).
pub fn workspace_len(head: &[u8]) -> Result<usize, Error> {
    let header = Header::parse(head)?;
    let table = LevelTable::parse(head, &header)?;
    let bytes = layout_for(&header, &table, header.level_count - 1).bytes_unaligned();
    usize::try_from(bytes).map_err(|_| Error::CapacityExceeded)
}
