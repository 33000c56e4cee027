//! The contexts of the rANS codec (SPEC §5.5.5): which frequency table each
//! value is coded with, from what the decoder already knows. Encoders call
//! the same functions, so both sides agree by construction.

use crate::limits::LEAF;
use crate::predict::{ArcMeans, PlanePolicy, placement_context};

/// Wing offset and wing distance, by the number `m` of ring entries that
/// may be wings (SPEC §7.4): 2 or fewer, 3, …, 8, then 9 and more.
#[inline]
pub fn wing(eligible: usize) -> u8 {
    (eligible.clamp(2, 9) - 2) as u8
}

/// C's split valence, by P's deficit and C's valence right after the split:
/// 4 when P is a leaf, otherwise C's valence 3 (or less), 4, 5, or 6 and
/// more as 0..=3.
#[inline]
pub fn deficit_c(deficit_p: u8, valence_c: usize) -> u8 {
    if deficit_p == LEAF {
        4
    } else {
        (valence_c.clamp(3, 6) - 3) as u8
    }
}

/// Constrained mode's placement code, by where R lies between the two arcs
/// (SPEC §7.4): 0..=4.
#[inline]
pub fn placement(means: &ArcMeans) -> u8 {
    placement_context(means)
}

/// Position residuals: under the `dominant` plane policy 1 for the
/// predicted axis and 0 for the two others; otherwise the axis (0 x, 1 y,
/// 2 z).
#[inline]
pub fn residual(policy: PlanePolicy, axis: usize, predicted: Option<usize>) -> u8 {
    match policy {
        PlanePolicy::Dominant => (predicted == Some(axis)) as u8,
        _ => axis as u8,
    }
}

/// Seed positions: the axis (0 x, 1 y, 2 z).
#[inline]
pub fn axis(k: usize) -> u8 {
    k as u8
}

/// Every other value: its substream's single table.
pub const SINGLE: u8 = 0;
