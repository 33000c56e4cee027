//! Shared code of the splitstream decoder fuzz targets.

pub mod streams;

use splitstream_decoder_core::{Decoder, Error, Inflater, workspace_len};

/// Largest workspace the byte-level target hands the decoder.
pub const WORKSPACE_CAP: usize = 16 << 20;

/// What one no-alloc decode did.
#[derive(Debug, PartialEq, Eq)]
pub struct Outcome {
    pub result: Result<u16, Error>,
    pub levels_that_fit: u16,
    pub hash: u64,
    /// State hash after each complete level.
    pub level_hashes: Vec<u64>,
}

/// The no-alloc path of the decoder, as an embedded caller runs it:
/// `Decoder::new` over `workspace`, then every level that fits, then the
/// state hash.
pub fn decode_into(stream: &[u8], workspace: &mut [u8], inflater: &mut Inflater) -> Outcome {
    let mut decoder = match Decoder::new(stream, workspace, inflater) {
        Ok(d) => d,
        Err(e) => {
            return Outcome {
                result: Err(e),
                levels_that_fit: 0,
                hash: 0,
                level_hashes: Vec::new(),
            };
        }
    };
    let fit = decoder.levels_that_fit();
    assert!(fit >= 1 && fit <= decoder.header().level_count);
    let mut level_hashes = Vec::new();
    let result = loop {
        let Some(k) = decoder.next_level() else {
            break Ok(decoder.levels_done());
        };
        let range = decoder.level_range(k);
        let Some(bytes) = stream.get(range.start as usize..range.end as usize) else {
            break Err(Error::Truncated);
        };
        if let Err(e) = decoder.decode_level(k, bytes) {
            // A failed decoder is poisoned and says so.
            assert_eq!(decoder.next_level(), None);
            assert_eq!(decoder.decode_level(k, bytes), Err(Error::Poisoned));
            break Err(e);
        }
        level_hashes.push(decoder.state_hash());
    };
    let hash = decoder.state_hash();
    // The public views stay consistent whatever happened.
    let st = decoder.state();
    assert_eq!(st.positions().len(), st.vertex_count() as usize);
    assert_eq!(st.triangles().len(), st.triangle_count() as usize);
    assert_eq!(st.deficits().len(), st.vertex_count() as usize);
    Outcome {
        result,
        levels_that_fit: fit,
        hash,
        level_hashes,
    }
}

/// Bytes of workspace the stream asks for, if its head parses.
pub fn needed(stream: &[u8]) -> Option<usize> {
    workspace_len(stream).ok()
}

mod fix_checksums;
pub use fix_checksums::{fix_checksums, fix_head_checksums};
