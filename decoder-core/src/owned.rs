//! Allocating conveniences (`alloc` feature): a decoder that owns its
//! workspace, and whole-stream decoding to plain vectors.

use alloc::boxed::Box;
use alloc::vec::Vec;

use crate::{Decoder, Error, Header, Inflater, LevelTable};

/// Largest workspace [`OwnedWorkspace::for_stream`] allocates per byte of
/// stream.
pub const MAX_WORKSPACE_PER_STREAM_BYTE: u64 = 1024;

/// A decoded mesh, detached from any workspace.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct DecodedMesh {
    pub positions: Vec<[u32; 3]>,
    pub triangles: Vec<[u32; 3]>,
    pub deficits: Vec<u8>,
    /// State hash after the base mesh and after every round, in order.
    pub round_hashes: Vec<u64>,
    pub levels: u16,
}

/// Memory for one decoder: an 8-aligned workspace and a boxed inflater.
pub struct OwnedWorkspace {
    words: Vec<u64>,
    inflater: Box<Inflater>,
}

impl OwnedWorkspace {
    /// Sized for the whole stream whose head is `head`.
    ///
    /// A stream's header could ask for any amount of memory; this refuses
    /// (with [`Error::CapacityExceeded`]) workspaces more than
    /// [`MAX_WORKSPACE_PER_STREAM_BYTE`] times the stream's length, far above
    /// what real streams need (about 11 times for a 1M-vertex terrain), and
    /// allocations the system refuses. Callers with other needs size a
    /// workspace themselves (see [`crate::Layout`]).
    pub fn for_stream(head: &[u8]) -> Result<OwnedWorkspace, Error> {
        OwnedWorkspace::within(head, u64::MAX)
    }

    /// Sized for the longest prefix of levels whose workspace (SPEC §9,
    /// alignment included) is at most `max_bytes`: the decoder then decodes
    /// those levels and stops cleanly ([`Decoder::levels_that_fit`]), the
    /// way a device with a memory budget does. [`Error::WorkspaceTooSmall`]
    /// when not even the base level fits; the limits of
    /// [`OwnedWorkspace::for_stream`] apply too.
    pub fn within(head: &[u8], max_bytes: u64) -> Result<OwnedWorkspace, Error> {
        let header = Header::parse(head)?;
        let table = LevelTable::parse(head, &header)?;
        crate::decoder::declared_layout(&header, &table)?;
        // The words below are 8-aligned, so a layout needs no slack for
        // alignment: its total, in whole words.
        let bytes = |last: u16| {
            crate::layout_for(&header, &table, last)
                .total
                .div_ceil(8)
                .saturating_mul(8)
        };
        let Some(last) = (0..header.level_count)
            .rev()
            .find(|&k| bytes(k) <= max_bytes)
        else {
            return Err(Error::WorkspaceTooSmall {
                needed: usize::try_from(bytes(0)).unwrap_or(usize::MAX),
                available: usize::try_from(max_bytes).unwrap_or(usize::MAX),
            });
        };
        let len = usize::try_from(bytes(last)).map_err(|_| Error::CapacityExceeded)?;
        let limit = table
            .stream_len()
            .saturating_mul(MAX_WORKSPACE_PER_STREAM_BYTE)
            .saturating_add(1 << 20);
        if len as u64 > limit {
            return Err(Error::CapacityExceeded);
        }
        let mut words = Vec::new();
        words
            .try_reserve_exact(len.div_ceil(8))
            .map_err(|_| Error::CapacityExceeded)?;
        words.resize(len.div_ceil(8), 0u64);
        Ok(OwnedWorkspace {
            words,
            inflater: Box::new(Inflater::new()),
        })
    }

    /// Bytes of the workspace (the inflater not included).
    pub fn len(&self) -> usize {
        self.words.len() * 8
    }

    /// Whether the workspace is empty (never, for one made by this type).
    pub fn is_empty(&self) -> bool {
        self.words.is_empty()
    }

    /// A decoder over this memory.
    pub fn decoder<'h, 'ws>(&'ws mut self, head: &'h [u8]) -> Result<Decoder<'h, 'ws>, Error> {
        let bytes: &mut [u8] = bytemuck::cast_slice_mut(&mut self.words);
        Decoder::new(head, bytes, &mut self.inflater)
    }
}

/// Decodes a whole stream; with `hash_rounds`, records the state hash after
/// the base and after every round (the conformance protocol).
pub fn decode_all(stream: &[u8], hash_rounds: bool) -> Result<DecodedMesh, Error> {
    let mut ws = OwnedWorkspace::for_stream(stream)?;
    let mut decoder = ws.decoder(stream)?;
    let mut round_hashes = Vec::new();
    while let Some(k) = decoder.next_level() {
        let bytes = decoder.level_bytes(k, stream)?;
        let mut level = decoder.begin_level(k, bytes)?;
        if k == 0 && hash_rounds {
            round_hashes.push(level.state().state_hash());
        }
        while level.next_round()?.is_some() {
            if hash_rounds {
                round_hashes.push(level.state().state_hash());
            }
        }
    }
    Ok(DecodedMesh {
        positions: decoder.positions().to_vec(),
        triangles: decoder.triangles().to_vec(),
        deficits: decoder.state().deficits().to_vec(),
        round_hashes,
        levels: decoder.levels_done(),
    })
}
