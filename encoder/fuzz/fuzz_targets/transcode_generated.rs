//! `transcode` on generated valid streams: decoder-core's fuzz generator
//! builds a stream from the first bytes (any base mesh, both position
//! modes, 8 to 31 bits per axis, every plane, wing and deficit policy and
//! record order,
//! leaves, boundaries, seeded level 0), the next bytes pick the coding to
//! write it in, and the transcoded stream must decode to the very same
//! state hash after every round. A replay that refuses a valid stream, or
//! reaches another state, is a finding; so is any panic.
#![no_main]

use libfuzzer_sys::fuzz_target;
use splitstream_decoder_core::writer::ChunkCodec;
use splitstream_decoder_core::{
    DeficitContexts, Framing, PlanePolicy, PositionMode, RecordOrder, Schedule, WingPolicy,
};
use splitstream_decoder_core_fuzz::streams::{self, Choices};
use splitstream_encoder::emit::{TranscodeOptions, positions_first_allowed, transcode};

/// The coding to write the stream in, from the bytes left.
fn options(choices: &mut Choices<'_>, input: Schedule, mode: PositionMode) -> TranscodeOptions {
    let codec = match choices.byte() % 6 {
        0 => ChunkCodec::Stored,
        1 => ChunkCodec::Deflate(1),
        2 => ChunkCodec::RansAlways {
            lanes: 1 + choices.byte() % 32,
        },
        _ => ChunkCodec::Rans {
            lanes: 1 + choices.byte() % 32,
        },
    };
    let pick = |b: u8, n: usize| (b as usize % (n + 1)).checked_sub(1);
    let plane = pick(choices.byte(), PlanePolicy::ALL.len()).map(|i| PlanePolicy::ALL[i]);
    let wings = pick(choices.byte(), WingPolicy::ALL.len()).map(|i| WingPolicy::ALL[i]);
    // `plain` or `valence` forced, or per level (`split-history`, 3.10,
    // comes with the default under `every-vertex`; two choices keep the
    // corpora's bytes meaning what they did).
    let deficits = pick(choices.byte(), 2).map(|i| DeficitContexts::ALL[i]);
    let schedule = match (choices.byte() & 1, input) {
        (0, s) => s,
        (_, Schedule::SplitValences) => Schedule::EveryVertex,
        (_, Schedule::EveryVertex) => Schedule::SplitValences,
    };
    // The record order (3.7): chosen per level, or forced where a level
    // could declare it.
    let records = pick(choices.byte(), RecordOrder::ALL.len())
        .map(|i| RecordOrder::ALL[i])
        .filter(|&r| r == RecordOrder::WingsFirst || positions_first_allowed(mode, plane, wings));
    TranscodeOptions {
        codec,
        chunk_limit: [16 * 1024, 1, 7, 64, 255][choices.below(5)],
        rans_chunk_limit: [16 * 1024, 1, 3, 64][choices.below(4)],
        plane,
        wings,
        deficits,
        // The input's schedule, or the other one (SPEC §3.2).
        schedule,
        records,
        // The tie rule (3.8): per level, the cheapest (no choice byte of its
        // own, so that existing corpora keep their meaning).
        ties: None,
        // Adaptive rANS tables where smaller (3.9), or static ones only:
        // read last, so that an input of the earlier corpora, whose bytes
        // ran out before, keeps the default (a zero byte).
        adaptive_tables: choices.byte() & 1 == 0,
        // The framing (3.11, 3.12): read after every earlier choice, for
        // the same reason (a zero byte: compact, the default).
        framing: match choices.byte() % 3 {
            0 => Framing::Compact,
            1 => Framing::Fixed,
            _ => Framing::CompactLevels,
        },
    }
}

fuzz_target!(|data: &[u8]| {
    let mut choices = Choices::new(data);
    let g = streams::generate(&mut choices, false);
    assert_eq!(g.error, None, "the generator builds valid streams");
    let options = options(&mut choices, g.params.schedule, g.params.position_mode);
    let same_schedule = options.schedule == g.params.schedule;
    let transcoded = transcode(&g.stream, &options).unwrap_or_else(|e| {
        panic!(
            "a valid stream ({} base, {options:?}) was refused: {e}",
            g.base
        )
    });
    let input = streams::decode_full(&g.stream);
    let output = streams::decode_full(&transcoded.stream);
    assert_eq!(output.error, None, "the transcoded stream decodes");
    // The hashes cover the per-vertex byte, which follows the schedule
    // (SPEC §6.2, §8): equal within one schedule, the mesh equal always.
    if same_schedule {
        assert_eq!(
            output.hashes, input.hashes,
            "the same state after every round"
        );
        assert_eq!(
            transcoded.final_hash,
            *input.hashes.last().expect("a base state")
        );
    } else {
        assert_eq!(output.hashes.len(), input.hashes.len(), "the same rounds");
    }
    assert_eq!(output.triangles, input.triangles);
    assert_eq!(output.positions, input.positions);
});
