//! The contexts of the rANS codec (SPEC §5.5.5): which frequency table each
//! value is coded with, from what the decoder already knows. Encoders call
//! the same functions, so both sides agree by construction.

use crate::limits::LEAF;

/// Wing distance, by ring length: rings of 3..=9 each, then 10 and above.
#[inline]
pub fn wing_distance(ring_len: usize) -> u8 {
    (ring_len.clamp(3, 10) - 3) as u8
}

/// Deficit of C, by the deficit of P just read: 0, 1, 2, or 3 and above
/// (a leaf counts as 3).
#[inline]
pub fn deficit_c(deficit_p: u8) -> u8 {
    if deficit_p == LEAF {
        3
    } else {
        deficit_p.min(3)
    }
}

/// Position residuals and seed positions: the axis (0 x, 1 y, 2 z).
#[inline]
pub fn axis(k: usize) -> u8 {
    k as u8
}

/// Every other value: its substream's single table.
pub const SINGLE: u8 = 0;
