//! Under the rANS codec a substream's chunks are rANS-coded or deflated at
//! level 10, whichever is smaller (`writer`); a level-1 deflate first rules
//! level 10 out where it is far behind. Both outcomes stay reachable, and
//! on these inputs the choice is the smaller codec.

use splitstream_decoder_core::limits::substream;
use splitstream_decoder_core::writer::{ChunkCodec, StreamParams, SubstreamWriter, coded_len};

const RANS: ChunkCodec = ChunkCodec::Rans { lanes: 4 };
const RANS_ONLY: ChunkCodec = ChunkCodec::RansAlways { lanes: 4 };
const DEFLATE: ChunkCodec = ChunkCodec::Deflate(10);

fn len(sub: &SubstreamWriter, codec: ChunkCodec) -> usize {
    let params = StreamParams {
        codec,
        ..StreamParams::default()
    };
    coded_len(&mut sub.clone(), substream::EDGE, &params)
}

fn pseudo_random() -> impl FnMut() -> u64 {
    let mut x = 0x2545_F491_4F6C_DD1Du64;
    move || {
        x ^= x << 13;
        x ^= x >> 7;
        x ^= x << 17;
        x
    }
}

/// One block of 64 two-byte varints repeated: deflate codes each repeat as
/// one match, rANS pays about 6 bits per value.
#[test]
fn repeated_blocks_are_deflated() {
    let mut next = pseudo_random();
    let block: Vec<i32> = (0..64).map(|_| 200 + (next() % 64) as i32).collect();
    let mut sub = SubstreamWriter::default();
    for _ in 0..2000 {
        for &v in &block {
            sub.signed_in(0, v);
        }
    }
    let (rans, deflate) = (len(&sub, RANS_ONLY), len(&sub, DEFLATE));
    assert!(deflate * 10 < rans, "deflate {deflate}, rANS {rans}");
    assert_eq!(len(&sub, RANS), deflate);
}

/// Skewed values without repeats: rANS codes each in about a bit, deflate's
/// quick pass is far larger and level 10 is not tried.
#[test]
fn skewed_values_stay_rans() {
    let mut next = pseudo_random();
    let mut sub = SubstreamWriter::default();
    for _ in 0..100_000 {
        let v = if next().is_multiple_of(8) {
            (next() % 40) as i32 - 20
        } else {
            0
        };
        sub.signed_in(0, v);
    }
    let (rans, deflate) = (len(&sub, RANS_ONLY), len(&sub, DEFLATE));
    assert!(rans < deflate, "rANS {rans}, deflate {deflate}");
    assert_eq!(len(&sub, RANS), rans);
}

/// Values where the two codecs come closer: the choice is the smaller of
/// the two (the quick pass is a heuristic, so this holds for these inputs
/// as for every real one measured, not for any bytes).
#[test]
fn the_choice_is_the_smaller_codec() {
    let mut next = pseudo_random();
    for modulus in [2u64, 5, 17, 300, 70_000] {
        let mut sub = SubstreamWriter::default();
        for i in 0..30_000u64 {
            let v = if i.is_multiple_of(3) {
                next() % modulus
            } else {
                i % modulus
            };
            sub.signed_in((i % 3) as u8, v as i32);
        }
        let (rans, deflate) = (len(&sub, RANS_ONLY), len(&sub, DEFLATE));
        assert_eq!(len(&sub, RANS), rans.min(deflate), "modulus {modulus}");
    }
}
