//! The raw-deflate inflater state, kept in caller-owned memory (SPEC §5.2).
//!
//! miniz_oxide's `DecompressorOxide` is about 10.5 KB and its constructor is
//! not `const`, so the caller decides where it lives (a static cell on a
//! microcontroller, a `Box` with the `alloc` feature, the stack on a desktop).

use miniz_oxide::inflate::TINFLStatus;
use miniz_oxide::inflate::core::{DecompressorOxide, decompress, inflate_flags};

use crate::Error;

/// Reusable inflater for deflate chunks.
pub struct Inflater {
    state: DecompressorOxide,
}

impl Default for Inflater {
    fn default() -> Self {
        Inflater::new()
    }
}

impl Inflater {
    pub fn new() -> Inflater {
        Inflater {
            state: DecompressorOxide::new(),
        }
    }

    /// Inflates the whole raw-deflate stream `input` into `out`, which must be
    /// exactly the declared raw length: anything else is [`Error::CorruptChunk`].
    pub fn inflate_exact(&mut self, input: &[u8], out: &mut [u8]) -> Result<(), Error> {
        self.state.init();
        let flags = inflate_flags::TINFL_FLAG_USING_NON_WRAPPING_OUTPUT_BUF;
        let (status, consumed, written) = decompress(&mut self.state, input, out, 0, flags);
        if status == TINFLStatus::Done && consumed == input.len() && written == out.len() {
            Ok(())
        } else {
            Err(Error::CorruptChunk)
        }
    }
}
