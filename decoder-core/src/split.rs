//! Applying one vertex split (SPEC §7.4, §7.5).

use crate::Error;
use crate::limits::{LEAF, MAX_SPLIT_VALENCE, NONE};
use crate::ring::Ring;
use crate::state::{MeshState, next, prev};

/// Everything a split needs besides the ring: the paper's split record with
/// positions already resolved (SPEC §7.4).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SplitRecord {
    /// Ring position of the first wing `a = r_o`.
    pub wing_offset: u8,
    /// Ring distance from the first wing to the second, `b = r_{o+d}`.
    pub wing_distance: u8,
    /// Deficit of P right after the split, or [`LEAF`].
    pub deficit_p: u8,
    /// Deficit of C right after the split, or [`LEAF`].
    pub deficit_c: u8,
    pub position_p: [u32; 3],
    pub position_c: [u32; 3],
}

/// What a split changed, for callers that track it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SplitOutcome {
    /// Triangles added (1 or 2: none for a ghost wing).
    pub triangles_added: u32,
    /// Valence of P and C right after the split.
    pub valence_p: u32,
    pub valence_c: u32,
}

impl MeshState<'_> {
    /// Splits `r` (whose canonical ring is `ring`) into P (keeping index `r`)
    /// and C (index `c`), appending its new triangles from index
    /// `triangle_count()` (SPEC §7.5). All checks run before anything changes.
    pub fn apply_split(
        &mut self,
        r: u32,
        ring: &Ring,
        rec: &SplitRecord,
        c: u32,
    ) -> Result<SplitOutcome, Error> {
        let k = ring.len();
        let o = rec.wing_offset as usize;
        let d = rec.wing_distance as usize;
        if d == 0 || o + d >= k {
            return Err(Error::RingOffsetOutOfRange);
        }
        let a = ring.vertices()[o];
        let b = ring.vertices()[o + d];
        // Arc 1 is wedges o .. o+d (d wedges) and goes to P, arc 2 (the
        // other k - d) to C.
        let (len_p, len_c) = (d, k - d);
        let valence_p = len_p + 2;
        let valence_c = len_c + 2;
        for (deficit, valence) in [(rec.deficit_p, valence_p), (rec.deficit_c, valence_c)] {
            if deficit != LEAF && valence + deficit as usize > MAX_SPLIT_VALENCE {
                return Err(Error::ValenceOverflow);
            }
        }
        for w in [a, b] {
            if w != NONE && self.deficit[w as usize] == 0 {
                return Err(Error::ValenceOverflow);
            }
        }
        let limit = 1u64 << self.bits;
        for p in [rec.position_p, rec.position_c] {
            if p.iter().any(|&v| v as u64 >= limit) {
                return Err(Error::PositionOutOfRange);
            }
        }
        let added = (a != NONE) as u32 + (b != NONE) as u32;
        if added == 0 {
            // Unreachable for a state built by this crate: a ring holds the
            // ghost at most once. Checked so that no input can panic.
            return Err(Error::RingOffsetOutOfRange);
        }
        let t = self.triangle_count;
        if c >= self.vertex_capacity() || c != self.vertex_count {
            return Err(Error::CapacityExceeded);
        }
        if t as u64 + added as u64 > self.triangle_limit as u64 {
            return Err(Error::LevelCountMismatch);
        }
        if t as u64 + added as u64 > self.triangle_capacity() as u64 {
            return Err(Error::CapacityExceeded);
        }

        // From here on nothing can fail.
        for w in [a, b] {
            if w != NONE && self.deficit[w as usize] != LEAF {
                self.deficit[w as usize] -= 1;
                // A wing reaching deficit 0 is a candidate from the next
                // round on (the round's candidates were fixed at its start).
                let d = self.deficit[w as usize];
                self.set_candidate(w, d);
            }
        }
        // P (index r) owns arc 1 (from a to b), C arc 2.
        let (x, y) = (r, c);
        // Arc 2 runs from wedge o + d around to wedge o - 1 (mod k).
        let corners = ring.corners();
        for &corner in corners[o + d..].iter().chain(&corners[..o]) {
            if corner != NONE {
                self.corners[corner as usize] = c;
            }
        }
        let wedge = |i: usize| corners[if i >= k { i - k } else { i }];
        let before_a = wedge(o + k - 1);
        let after_a = wedge(o);
        let before_b = wedge(o + d - 1);
        let after_b = wedge(o + d);
        let mut next_t = t;
        let ta = (a != NONE).then(|| {
            let ta = next_t;
            next_t += 1;
            ta
        });
        let tb = (b != NONE).then(|| {
            let tb = next_t;
            next_t += 1;
            tb
        });
        let facing = |corner: u32, f: fn(u32) -> u32| if corner == NONE { NONE } else { f(corner) };
        if let Some(ta) = ta {
            let base = 3 * ta as usize;
            self.corners[base..base + 3].copy_from_slice(&[x, y, a]);
            self.link(3 * ta, facing(before_a, next));
            self.link(3 * ta + 1, facing(after_a, prev));
        }
        if let Some(tb) = tb {
            let base = 3 * tb as usize;
            self.corners[base..base + 3].copy_from_slice(&[y, x, b]);
            self.link(3 * tb, facing(before_b, next));
            self.link(3 * tb + 1, facing(after_b, prev));
        }
        match (ta, tb) {
            (Some(ta), Some(tb)) => self.link(3 * ta + 2, 3 * tb + 2),
            (Some(ta), None) => self.opposite.set(3 * ta + 2, NONE),
            (None, Some(tb)) => self.opposite.set(3 * tb + 2, NONE),
            (None, None) => {}
        }
        let (corner_x, corner_y) = match (ta, tb) {
            (Some(ta), _) => (3 * ta, 3 * ta + 1),
            (None, Some(tb)) => (3 * tb + 1, 3 * tb),
            (None, None) => return Err(Error::RingOffsetOutOfRange),
        };
        self.vertex_corner.set(x, corner_x);
        self.vertex_corner.set(y, corner_y);
        self.positions[r as usize] = rec.position_p;
        self.positions[c as usize] = rec.position_c;
        self.deficit[r as usize] = rec.deficit_p;
        self.deficit[c as usize] = rec.deficit_c;
        self.set_candidate(r, rec.deficit_p);
        self.set_candidate(c, rec.deficit_c);
        self.vertex_count += 1;
        self.triangle_count = next_t;
        Ok(SplitOutcome {
            triangles_added: added,
            valence_p: valence_p as u32,
            valence_c: valence_c as u32,
        })
    }
}
