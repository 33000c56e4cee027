//! Packed arrays of corner references: the swing table (the next corner
//! of the same vertex around its fan, see `state.rs`) and the corner of each
//! vertex (SPEC §9).
//!
//! A corner reference is a corner index or [`NONE`]. When every corner index
//! of a layout fits in 24 bits (three times the triangle capacity at most
//! 2^24 − 1), entries take 3 bytes instead of 4: on a 1M-vertex terrain that
//! is 7 bytes per vertex less memory (SPEC §9's budget), and more entries per
//! cache line for the fan walks. Every access loads or stores 4 bytes and
//! masks them, so one extra byte at the end keeps the last access in bounds.

use crate::limits::NONE;

/// Largest corner count whose references fit in 3 bytes: indices stay below
/// the 3-byte `NONE`, `0xFF_FFFF`.
pub const NARROW_CORNERS: u64 = 0xFF_FFFF;

/// Bytes per reference for a layout holding `corners` corners (SPEC §9).
pub const fn width_for(corners: u64) -> usize {
    if corners <= NARROW_CORNERS { 3 } else { 4 }
}

/// Bytes of an array of `entries` references of `width` bytes (SPEC §9).
pub const fn bytes_for(entries: u64, width: usize) -> u64 {
    width as u64 * entries + 1
}

/// An array of corner references in caller-owned bytes.
pub struct CornerRefs<'ws> {
    bytes: &'ws mut [u8],
    width: usize,
    /// The bits an entry keeps: all of a `u32`, or the low 24.
    mask: u32,
}

impl<'ws> CornerRefs<'ws> {
    /// References of `width` (3 or 4; anything else is taken as 4) bytes
    /// over `bytes`.
    pub fn new(bytes: &'ws mut [u8], width: usize) -> CornerRefs<'ws> {
        let (width, mask) = if width == 3 {
            (3, 0xFF_FFFF)
        } else {
            (4, u32::MAX)
        };
        CornerRefs { bytes, width, mask }
    }

    /// Bytes per entry.
    pub fn width(&self) -> usize {
        self.width
    }

    /// Entries the bytes hold.
    pub fn len(&self) -> usize {
        self.bytes.len().saturating_sub(1) / self.width
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Entry `i`; [`NONE`] past the end.
    #[inline]
    pub fn get(&self, i: u32) -> u32 {
        let at = self.width * i as usize;
        match self.bytes.get(at..at + 4) {
            Some(b) => {
                let v = u32::from_le_bytes([b[0], b[1], b[2], b[3]]) & self.mask;
                if v == self.mask { NONE } else { v }
            }
            None => NONE,
        }
    }

    /// Sets entry `i` (ignored past the end). `value` is a corner below the
    /// layout's corner count, or [`NONE`].
    #[inline]
    pub fn set(&mut self, i: u32, value: u32) {
        let at = self.width * i as usize;
        if let Some(b) = self.bytes.get_mut(at..at + 4) {
            let old = u32::from_le_bytes([b[0], b[1], b[2], b[3]]);
            let new = (old & !self.mask) | (value & self.mask);
            b.copy_from_slice(&new.to_le_bytes());
        }
    }

    /// The whole array as `u32` scratch (the base-mesh build, SPEC §9),
    /// with [`CornerRefs::pack`] to turn its first entries into references.
    pub(crate) fn scratch(&mut self) -> &mut [u32] {
        let words = self.bytes.len() / 4;
        bytemuck::try_cast_slice_mut(&mut self.bytes[..4 * words]).unwrap_or(&mut [])
    }

    /// Turns the first `3 n` `u32`s of [`CornerRefs::scratch`] into the
    /// first `3 n` entries, in place, triangle by triangle: the three
    /// entries of a triangle are `f` of its three `u32`s. (Entry i's bytes
    /// never pass u32 i's, and a triangle's three u32s are read before its
    /// entries are written, so a forward pass reads every `u32` first.)
    pub(crate) fn pack_triangles(&mut self, n: usize, f: impl Fn([u32; 3]) -> [u32; 3]) {
        for t in 0..n.min(self.bytes.len() / 12) {
            let b = &self.bytes[12 * t..12 * t + 12];
            let word =
                |i: usize| u32::from_le_bytes([b[4 * i], b[4 * i + 1], b[4 * i + 2], b[4 * i + 3]]);
            let entries = f([word(0), word(1), word(2)]);
            for (i, &e) in entries.iter().enumerate() {
                self.set((3 * t + i) as u32, e);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn narrow_and_wide_round_trip_every_value_kind() {
        for width in [3, 4] {
            let mut bytes = [0xA5u8; 4 * 4 + 1];
            let len = bytes_for(4, width) as usize;
            let mut refs = CornerRefs::new(&mut bytes[..len], width);
            assert_eq!(refs.len(), 4);
            let values = [0, NONE, 0xFF_FFFE, 7];
            for (i, &v) in values.iter().enumerate() {
                refs.set(i as u32, v);
            }
            for (i, &v) in values.iter().enumerate() {
                assert_eq!(refs.get(i as u32), v, "width {width}, entry {i}");
            }
            assert_eq!(refs.get(4), NONE);
            refs.set(9, 1); // past the end: ignored, no panic
        }
    }

    #[test]
    fn pack_turns_u32s_into_entries() {
        for width in [3, 4] {
            let mut bytes = [0u8; 4 * 6 + 1];
            let mut refs = CornerRefs::new(&mut bytes, width);
            let values = [5, NONE, 0, 0xFF_FFFE, 3, 9];
            refs.scratch()[..6].copy_from_slice(&values);
            refs.pack_triangles(2, |[a, b, c]| [b, c, a]);
            let expected = [NONE, 0, 5, 3, 9, 0xFF_FFFE];
            for (i, &v) in expected.iter().enumerate() {
                assert_eq!(refs.get(i as u32), v, "width {width}, entry {i}");
            }
        }
    }

    #[test]
    fn widths_follow_the_corner_count() {
        assert_eq!(width_for(0), 3);
        assert_eq!(width_for(NARROW_CORNERS), 3);
        assert_eq!(width_for(NARROW_CORNERS + 1), 4);
    }
}
