//! `GrowingCodedLen` costs a substream chunk by chunk while it is written;
//! whenever it is advanced, its finished cost must be `coded_len_in` of the
//! whole substream, under every codec, for value and bit substreams alike.

use proptest::prelude::*;
use splitstream_decoder_core::DeficitContexts;
use splitstream_decoder_core::limits::substream;
use splitstream_decoder_core::writer::{
    ChunkCodec, GrowingCodedLen, StreamParams, SubstreamWriter, coded_len_in,
};

fn codec(choice: u8) -> ChunkCodec {
    match choice % 5 {
        0 => ChunkCodec::Stored,
        1 => ChunkCodec::Deflate(1),
        2 => ChunkCodec::Deflate(10),
        3 => ChunkCodec::RansAlways { lanes: 3 },
        _ => ChunkCodec::Rans { lanes: 2 },
    }
}

/// One write: a signed value in an edge context, or a flag bit.
#[derive(Clone, Debug)]
enum Write {
    Value(u8, i32),
    Bit(bool),
}

fn write(sub: &mut SubstreamWriter, w: &Write) {
    match *w {
        Write::Value(ctx, v) => sub.signed_in(ctx % 3, v),
        Write::Bit(b) => sub.bit_in(0, b),
    }
}

proptest! {
    #[test]
    fn the_growing_cost_is_the_whole_cost(
        bits in any::<bool>(),
        values in proptest::collection::vec((any::<u8>(), -300i32..300, any::<bool>()), 0..400),
        advance_every in 1usize..40,
        codec_choice in any::<u8>(),
        chunk_limit in 1u32..64,
        rans_chunk_limit in 1u32..64,
    ) {
        // Edge values (three contexts) or flag bits (one), never both: a
        // substream holds one field.
        let (id, writes): (u8, Vec<Write>) = if bits {
            (substream::FLAGS, values.iter().map(|&(_, _, b)| Write::Bit(b)).collect())
        } else {
            (substream::EDGE, values.iter().map(|&(c, v, _)| Write::Value(c, v)).collect())
        };
        let params = StreamParams {
            codec: codec(codec_choice),
            chunk_limit,
            rans_chunk_limit,
            ..StreamParams::default()
        };
        let deficits = DeficitContexts::Plain;
        let mut sub = SubstreamWriter::default();
        let mut growing = GrowingCodedLen::default();
        for (i, w) in writes.iter().enumerate() {
            write(&mut sub, w);
            if i % advance_every == 0 {
                growing.advance(&sub, id, deficits, &params);
                // Advancing twice at one point costs nothing twice.
                growing.advance(&sub, id, deficits, &params);
            }
        }
        prop_assert_eq!(
            growing.finish(&mut sub.clone(), id, deficits, &params),
            coded_len_in(&mut sub, id, deficits, &params)
        );
    }
}
