//! The decoder state of SPEC §6: positions, triangles, adjacency, deficits.
//!
//! Triangles are stored as a corner table: corner `c` is slot `c % 3` of
//! triangle `c / 3`. The adjacency is kept as a *swing* table: `swing[c]` is
//! the corner of the same vertex in the next triangle counter-clockwise
//! around it, `next(opposite(next(c)))` in terms of the classic opposite
//! table, or [`NONE`] when the edge `prev(c) → c` is a boundary edge. A
//! ring walk is then one load per wedge, with no `% 3` on its chain of
//! dependent loads. `vertex_corner[v]` is any corner of `v`. Both are packed
//! in 3 or 4 bytes per entry ([`CornerRefs`]). Only the positions,
//! triangles and deficits are normative; the adjacency is this decoder's way
//! of walking rings quickly.

use crate::corner_refs::CornerRefs;
use crate::header::Schedule;
use crate::limits::LEAF;

/// Whether `x` is a multiple of 3: multiplying by the inverse of 3 modulo
/// 2^32 maps the multiples of 3 exactly onto `0 ..= (2^32 − 1) / 3`.
#[inline(always)]
fn multiple_of_3(x: u32) -> bool {
    x.wrapping_mul(0xAAAA_AAAB) <= u32::MAX / 3
}

/// Next corner of the same triangle (counter-clockwise): `3t → 3t+1 →
/// 3t+2 → 3t`. (Branch-free and without a division: corner walks run on
/// it.)
#[inline(always)]
pub fn next(c: u32) -> u32 {
    let after = c.wrapping_add(1);
    if multiple_of_3(after) {
        c.wrapping_sub(2)
    } else {
        after
    }
}

/// Previous corner of the same triangle.
#[inline(always)]
pub fn prev(c: u32) -> u32 {
    if multiple_of_3(c) {
        c.wrapping_add(2)
    } else {
        c.wrapping_sub(1)
    }
}

/// The mutable mesh a decoder refines, over caller-owned memory.
pub struct MeshState<'ws> {
    pub(crate) positions: &'ws mut [[u32; 3]],
    pub(crate) corners: &'ws mut [u32],
    pub(crate) swing: CornerRefs<'ws>,
    pub(crate) vertex_corner: CornerRefs<'ws>,
    pub(crate) deficit: &'ws mut [u8],
    pub(crate) candidates: &'ws mut [u64],
    pub(crate) vertex_count: u32,
    pub(crate) triangle_count: u32,
    /// Triangle count the current level may reach (SPEC §7.6).
    pub(crate) triangle_limit: u32,
    /// Rounds starting with this many vertices or more walk their fans
    /// ahead (`round.rs`).
    pub(crate) fans_ahead_from: u32,
    /// What the memory holds, fixed when the state is made (a split checks
    /// them, so they are not recomputed from the array lengths each time).
    vertex_capacity: u32,
    triangle_capacity: u32,
    /// Words of each of the three bitmaps in `candidates` (a third of it),
    /// fixed when the state is made. A round's flags ask for it twice a
    /// candidate (`is_blocked`, `split_bit`), where a division by 3 is a
    /// multiply and shifts; the colder uses still divide (reading this
    /// there too measured more instructions, and more Cortex-M4 code).
    pub(crate) bitmap_words: usize,
    pub(crate) bits: u8,
    /// Which vertices are candidates, and what `deficit` holds (SPEC §6.2,
    /// format 3.6): deficits under `SplitValences`, valences under
    /// `EveryVertex`.
    pub(crate) schedule: Schedule,
}

/// The caller-owned arrays a [`MeshState`] lives in (see [`crate::Layout`]).
pub struct StateMemory<'ws> {
    pub positions: &'ws mut [[u32; 3]],
    /// 3 per triangle.
    pub corners: &'ws mut [u32],
    /// The swing table (see the module documentation): at least 3 entries
    /// per triangle, in SPEC §9's region 3 ("opposite corners"), which
    /// [`crate::Layout`] sizes for base-mesh scratch too (`4 × (6 T0 + V0 + 1)`
    /// bytes).
    pub swing: CornerRefs<'ws>,
    pub vertex_corner: CornerRefs<'ws>,
    pub deficit: &'ws mut [u8],
    /// Three bitmaps of one bit per vertex, one after the other: the current
    /// candidates (deficit 0), the candidates at the start of the current
    /// round (under `every-vertex`, where every vertex is a candidate: the
    /// split-history bits, SPEC §6.1, 3.10), and the candidates whose flag
    /// is inferred because a neighbour was flagged.
    pub candidates: &'ws mut [u64],
}

impl<'ws> MeshState<'ws> {
    /// An empty state over `memory`, for coordinates of `bits` bits and the
    /// stream's schedule (SPEC §3.2: which vertices are candidates and what
    /// the per-vertex byte holds, §6.2).
    pub fn new(memory: StateMemory<'ws>, bits: u8, schedule: Schedule) -> MeshState<'ws> {
        let StateMemory {
            positions,
            corners,
            swing,
            vertex_corner,
            deficit,
            candidates,
        } = memory;
        let bitmap_words = candidates.len() / 3;
        let vertex_capacity = {
            let by_bits = bitmap_words as u64 * 64;
            let n = positions.len().min(vertex_corner.len()).min(deficit.len()) as u64;
            n.min(by_bits).min(u32::MAX as u64 - 1) as u32
        };
        let triangle_capacity = {
            let n = (corners.len().min(swing.len()) / 3) as u64;
            n.min(crate::limits::MAX_TRIANGLES as u64) as u32
        };
        MeshState {
            positions,
            corners,
            swing,
            vertex_corner,
            deficit,
            candidates,
            vertex_count: 0,
            triangle_count: 0,
            triangle_limit: u32::MAX,
            fans_ahead_from: crate::round::FANS_AHEAD_FROM_VERTICES,
            vertex_capacity,
            triangle_capacity,
            bitmap_words,
            bits,
            schedule,
        }
    }

    /// The stream's schedule ([`MeshState::new`]).
    pub fn schedule(&self) -> Schedule {
        self.schedule
    }

    pub fn vertex_count(&self) -> u32 {
        self.vertex_count
    }

    pub fn triangle_count(&self) -> u32 {
        self.triangle_count
    }

    /// Largest vertex count the memory holds.
    #[inline]
    pub fn vertex_capacity(&self) -> u32 {
        self.vertex_capacity
    }

    /// Largest triangle count the memory holds.
    #[inline]
    pub fn triangle_capacity(&self) -> u32 {
        self.triangle_capacity
    }

    /// Bounds the triangle count of the level being decoded: a split that
    /// would pass it fails with [`crate::Error::LevelCountMismatch`]
    /// (SPEC §7.5), whatever the workspace could hold.
    pub fn set_triangle_limit(&mut self, limit: u32) {
        self.triangle_limit = limit;
    }

    /// Starts a level whose table entry allows `triangle_limit` triangles
    /// ([`MeshState::set_triangle_limit`]): under `every-vertex` every
    /// vertex's split-history bit is cleared (SPEC §6.1, 3.10). Whoever
    /// drives the rounds calls it before each level, level 0's seed
    /// included.
    pub fn start_level(&mut self, triangle_limit: u32) {
        self.triangle_limit = triangle_limit;
        if self.schedule == Schedule::EveryVertex {
            let third = self.candidates.len() / 3;
            self.candidates[third..2 * third].fill(0);
        }
    }

    /// Whether `v` has split (as R) since the current level started: its
    /// split-history bit (SPEC §6.1, 3.10; `every-vertex` only, `false`
    /// otherwise).
    #[inline]
    pub fn split_in_level(&self, v: u32) -> bool {
        self.schedule == Schedule::EveryVertex && v < self.vertex_count && self.split_bit(v) != 0
    }

    /// [`MeshState::split_in_level`] as 0 or 1, without the checks, for
    /// a vertex below `vertex_count()` under `every-vertex`: one load, no
    /// branch (the flags of a `split-history` level read it about five
    /// times per vertex, twice each with the fans walked ahead).
    #[inline]
    pub(crate) fn split_bit(&self, v: u32) -> u8 {
        let third = self.bitmap_words;
        let word = self
            .candidates
            .get(third + (v / 64) as usize)
            .copied()
            .unwrap_or(0);
        (word >> (v % 64) & 1) as u8
    }

    /// Makes rounds that start with at least `vertices` vertices walk the
    /// fans of their upcoming splits ahead, many at once, so that their
    /// cache misses overlap (default [`crate::FANS_AHEAD_FROM_VERTICES`];
    /// 0: always, `u32::MAX`: never). A speed setting only: the decoded
    /// state is the same whatever it is.
    pub fn set_fans_ahead_from(&mut self, vertices: u32) {
        self.fans_ahead_from = vertices;
    }

    /// Quantized positions of the current vertices, in decoded order.
    pub fn positions(&self) -> &[[u32; 3]] {
        &self.positions[..self.vertex_count as usize]
    }

    /// Current triangles (counter-clockwise), ready for an index buffer.
    pub fn triangles(&self) -> &[[u32; 3]] {
        bytemuck::cast_slice(&self.corners[..3 * self.triangle_count as usize])
    }

    /// Current triangles as a flat index list.
    pub fn indices(&self) -> &[u32] {
        &self.corners[..3 * self.triangle_count as usize]
    }

    /// The byte SPEC §6.2 keeps per vertex, which the state hash covers
    /// (§8). Under the schedule `split-valences`, the valence deficit: split
    /// valence minus current valence, or [`LEAF`] for a vertex that never
    /// splits again. Under `every-vertex` (format 3.6), the valence, capped
    /// at 255.
    pub fn deficits(&self) -> &[u8] {
        &self.deficit[..self.vertex_count as usize]
    }

    pub fn bits(&self) -> u8 {
        self.bits
    }

    /// The candidates of the next round (SPEC §7.3 step 1: the vertices of
    /// deficit 0) as a bitmap, bit `v % 64` of word `v / 64`, kept up to
    /// date by the splits: `vertex_count().div_ceil(64)` words, whose bits
    /// at or above `vertex_count()` mean nothing.
    pub fn candidate_words(&self) -> &[u64] {
        let third = self.candidates.len() / 3;
        let words = (self.vertex_count as usize).div_ceil(64);
        &self.candidates[..third.min(words)]
    }

    /// The candidates of the next round, ascending ([`MeshState::candidate_words`]),
    /// so that a caller need not scan [`MeshState::deficits`].
    pub fn candidates(&self) -> impl Iterator<Item = u32> + '_ {
        let n = self.vertex_count as usize;
        self.candidate_words()
            .iter()
            .enumerate()
            .flat_map(move |(w, &word)| {
                let below_n = if (w + 1) * 64 <= n {
                    u64::MAX
                } else {
                    (1u64 << (n - w * 64)) - 1
                };
                BitsOf(word & below_n).map(move |b| (64 * w) as u32 + b)
            })
    }

    /// Whether `v` is a leaf (`false` for a vertex that does not exist).
    pub fn is_leaf(&self, v: u32) -> bool {
        self.schedule == Schedule::SplitValences
            && v < self.vertex_count
            && self.deficit[v as usize] == LEAF
    }

    /// The candidate, round-start candidate and blocked bitmaps (SPEC §7.3, §7.4).
    pub(crate) fn bitmaps(&mut self) -> (&mut [u64], &mut [u64], &mut [u64]) {
        let third = self.candidates.len() / 3;
        let (candidates, rest) = self.candidates.split_at_mut(third);
        let (flagged, blocked) = rest.split_at_mut(third);
        (candidates, flagged, blocked)
    }

    /// Records whether `v` is a candidate for the next round: its deficit
    /// is 0, or the schedule is `every-vertex` (SPEC §6.2).
    #[inline]
    pub(crate) fn set_candidate(&mut self, v: u32, deficit: u8) {
        let word = &mut self.candidates[(v / 64) as usize];
        let bit = 1u64 << (v % 64);
        if deficit == 0 || self.schedule == Schedule::EveryVertex {
            *word |= bit;
        } else {
            *word &= !bit;
        }
    }

    #[inline]
    pub(crate) fn vertex_at(&self, corner: u32) -> u32 {
        self.corners[corner as usize]
    }
}

/// The set bits of a word, lowest first.
struct BitsOf(u64);

impl Iterator for BitsOf {
    type Item = u32;

    #[inline]
    fn next(&mut self) -> Option<u32> {
        if self.0 == 0 {
            return None;
        }
        let b = self.0.trailing_zeros();
        self.0 &= self.0 - 1;
        Some(b)
    }
}

#[cfg(test)]
mod tests {
    use super::{next, prev};

    #[test]
    fn next_and_prev_stay_in_their_triangle() {
        let triangles = [0u32, 1, 2, 1000, 0x1555_5554, 0x5555_5553, 0x5555_5554];
        for t in triangles {
            let c = 3 * t;
            assert_eq!([next(c), next(c + 1), next(c + 2)], [c + 1, c + 2, c]);
            assert_eq!([prev(c), prev(c + 1), prev(c + 2)], [c + 2, c, c + 1]);
        }
    }
}
