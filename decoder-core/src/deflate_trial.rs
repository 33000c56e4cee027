//! The rANS codec's deflate trial (SPEC §5.2: any codec per chunk): a
//! substream is written with deflate at level 10 where that is no larger
//! than its rANS chunks, and level 10 is tried only where a quick level-1
//! pass comes under 3/2 of the rANS size ([`DEFLATE_QUICK_RATIO`]).
//!
//! Level 10 is slow (up to 1,500 match probes per byte), and most trials
//! lose. Both passes only ask whether a sum of chunk payloads crosses a
//! bound, and a payload is never negative: once the chunks coded so far
//! cross it, the rest cannot bring the sum back, so the pass stops there.
//! The answer is the one the whole pass gives, and each chunk is coded as
//! `writer::byte_chunks` codes it, so the stream's bytes are the same. The
//! chunks are coded one after the other (not with the framing's
//! `ChunkMap`) so that the pass can stop: a substream has few of them.

use alloc::vec::Vec;

use crate::writer::{Chunk, byte_chunk};

/// Under the rANS codec a substream is deflated at level 10 too, and the
/// smaller kept; the level-10 trial is skipped when a level-1 deflate is at
/// least this ratio (3/2) of the rANS size. Measured on 2026-12-04 over the
/// real meshes, the DEM and the 1M demo terrain (encoder/BENCHMARKS.md,
/// "Serial work off the critical path"): level 10 was at most 1.34 times
/// smaller than level 1, and it beat
/// rANS only where level 1 came within 1.07 of the rANS size (the seed's
/// substreams, incompressible flags). At 5/3 the trial still ran on the
/// last level's largest substreams, after its replay, on the emission's
/// critical path. Were level 10 ever 1.62 times smaller than level 1 (the
/// largest gain seen on earlier formats), a skipped trial would cost at most
/// 8 % of that substream's bytes; the stream stays valid either way.
pub(crate) const DEFLATE_QUICK_RATIO: (usize, usize) = (3, 2);

/// The level-10 deflate chunks of `bytes` (chunks of at most `limit` raw
/// bytes, as `byte_chunks` cuts them) and their payload bytes, where the
/// rANS codec writes the substream with them instead of its rANS chunks of
/// `rans` payload bytes; `None` where it writes rANS.
pub(crate) fn deflate_instead(
    bytes: &[u8],
    limit: usize,
    rans: usize,
) -> Option<(Vec<Chunk>, usize)> {
    let quick_loses = |quick: usize| quick * DEFLATE_QUICK_RATIO.1 >= rans * DEFLATE_QUICK_RATIO.0;
    deflate_until(bytes, limit, 1, quick_loses)?;
    // rANS is kept only where it is strictly smaller: a tie goes to deflate.
    deflate_until(bytes, limit, 10, |deflate| rans < deflate)
}

/// The chunks of `bytes` deflated at `level` and their payload bytes, coded
/// one after the other; `None` as soon as the payloads so far make `loses`
/// true (it must stay true as the sum grows), or where the whole sum does.
fn deflate_until(
    bytes: &[u8],
    limit: usize,
    level: u8,
    loses: impl Fn(usize) -> bool,
) -> Option<(Vec<Chunk>, usize)> {
    let count = bytes.len().div_ceil(limit);
    let mut chunks = Vec::with_capacity(count);
    let mut payloads = 0;
    for i in 0..count {
        let chunk = byte_chunk(bytes, limit, Some(level), i);
        payloads += chunk.stored_len();
        if loses(payloads) {
            return None;
        }
        chunks.push(chunk);
    }
    // No chunk at all: the empty sum is weighed too.
    (!loses(payloads)).then_some((chunks, payloads))
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(64))]

        /// The trial stopped early takes the choice of the whole passes:
        /// rANS where a level-1 deflate is at least 3/2 of its size or
        /// level 10 is larger, else level 10's chunks (ties included, with
        /// `rans` on and around the passes' own sizes).
        #[test]
        fn stopping_early_changes_no_choice(
            values in proptest::collection::vec(0u8..255, 0..3000),
            spread in 1u8..255,
            limit in 1usize..1200,
            rans_at in 0usize..5,
        ) {
            let bytes: Vec<u8> = values.iter().map(|v| v % spread).collect();
            let whole = |level: u8| -> (Vec<Chunk>, usize) {
                let chunks: Vec<Chunk> = (0..bytes.len().div_ceil(limit))
                    .map(|i| byte_chunk(&bytes, limit, Some(level), i))
                    .collect();
                let payloads = chunks.iter().map(Chunk::stored_len).sum();
                (chunks, payloads)
            };
            let (quick, deep) = (whole(1).1, whole(10));
            let rans = match rans_at {
                0 => deep.1,
                1 => deep.1.saturating_sub(1),
                2 => (2 * quick).div_ceil(3),
                3 => (2 * quick / 3).saturating_sub(1),
                _ => deep.1 + 1,
            };
            let expected = if quick * 2 >= rans * 3 || rans < deep.1 {
                None
            } else {
                Some(deep)
            };
            let got = deflate_instead(&bytes, limit, rans);
            let key = |c: &Option<(Vec<Chunk>, usize)>| {
                c.as_ref().map(|(chunks, payloads)| {
                    let stored: Vec<usize> = chunks.iter().map(Chunk::stored_len).collect();
                    (stored, *payloads)
                })
            };
            prop_assert_eq!(key(&got), key(&expected));
        }
    }
}
