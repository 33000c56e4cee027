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
const DEFLATE_QUICK_RATIO: (usize, usize) = (3, 2);

/// The chunks a deflate trial of a substream coded, at level 1 and at level
/// 10, as many as it needed: kept with the substream
/// (`writer::SubstreamWriter`), so that a substream costed and then framed,
/// or two substreams of the same bytes (a level's flags under either choice
/// of contexts), take them instead of coding them again. Chunks are coded
/// the same whatever the rANS size they are weighed against; a later trial
/// codes only the chunks it needs beyond them.
#[derive(Clone, Debug)]
pub(crate) struct DeflateTrial {
    /// The substream's value count when its chunks were coded (values are
    /// only appended: the same count, the same bytes), and their limit.
    values: usize,
    limit: usize,
    /// The first chunks at level 1 and at level 10.
    coded: [Vec<Chunk>; 2],
}

impl DeflateTrial {
    /// A trial of a substream of `values` values in chunks of at most
    /// `limit` raw bytes, with no chunk coded yet.
    pub(crate) fn new(values: usize, limit: usize) -> DeflateTrial {
        DeflateTrial {
            values,
            limit,
            coded: [Vec::new(), Vec::new()],
        }
    }

    /// Whether its chunks are those of a substream of `values` values in
    /// chunks of at most `limit` raw bytes.
    pub(crate) fn holds(&self, values: usize, limit: usize) -> bool {
        (self.values, self.limit) == (values, limit)
    }

    /// The level-10 deflate chunks of `bytes` (the substream's, as
    /// `byte_chunks` cuts them), where the rANS codec writes the substream
    /// with them instead of its rANS chunks of `rans` payload bytes; `None`
    /// where it writes rANS.
    pub(crate) fn deflate_instead(&mut self, bytes: &[u8], rans: usize) -> Option<&[Chunk]> {
        let quick_loses =
            |quick: usize| quick * DEFLATE_QUICK_RATIO.1 >= rans * DEFLATE_QUICK_RATIO.0;
        let [quick, deep] = &mut self.coded;
        deflate_until(bytes, self.limit, 1, quick, quick_loses)?;
        // rANS is kept only where it is strictly smaller: a tie goes to
        // deflate.
        deflate_until(bytes, self.limit, 10, deep, |deflate| rans < deflate)?;
        Some(deep)
    }
}

/// Codes the chunks of `bytes` deflated at `level` after those `chunks`
/// holds already, one after the other, into `chunks`, and returns their
/// payload bytes; `None` as soon as the payloads so far make `loses` true
/// (it must stay true as the sum grows), or where the whole sum does.
fn deflate_until(
    bytes: &[u8],
    limit: usize,
    level: u8,
    chunks: &mut Vec<Chunk>,
    loses: impl Fn(usize) -> bool,
) -> Option<usize> {
    let count = bytes.len().div_ceil(limit);
    let mut payloads = 0;
    for i in 0..count {
        if i == chunks.len() {
            chunks.push(byte_chunk(bytes, limit, Some(level), i));
        }
        payloads += chunks[i].stored_len();
        if loses(payloads) {
            return None;
        }
    }
    // No chunk at all: the empty sum is weighed too.
    (!loses(payloads)).then_some(payloads)
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
        /// `rans` on and around the passes' own sizes); so does a trial
        /// that continues one kept from another rANS size.
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
            let deep_payloads = deep.1;
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
            let stored = |c: &[Chunk]| c.iter().map(Chunk::stored_len).collect::<Vec<_>>();
            let expected = expected.map(|(chunks, _)| stored(&chunks));
            let mut fresh = DeflateTrial::new(0, limit);
            let got = fresh.deflate_instead(&bytes, rans).map(stored);
            prop_assert_eq!(&got, &expected);
            // A trial kept from one weighed against another rANS size (more
            // or fewer chunks coded) answers the same.
            for other in [0, quick / 2, quick, deep_payloads, usize::MAX / 4] {
                let mut kept = DeflateTrial::new(0, limit);
                kept.deflate_instead(&bytes, other);
                prop_assert_eq!(&kept.deflate_instead(&bytes, rans).map(stored), &expected);
            }
        }
    }
}
