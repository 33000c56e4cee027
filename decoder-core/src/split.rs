//! Applying one vertex split (SPEC §7.4, §7.5).

use crate::Error;
use crate::header::Schedule;
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
    /// Deficit of P right after the split, or [`LEAF`]. Under the schedule
    /// `every-vertex` (format 3.6), P's valence right after the split,
    /// capped at 255 (the split sets it from the ring whatever this says).
    pub deficit_p: u8,
    /// Deficit of C right after the split, or [`LEAF`]; under
    /// `every-vertex`, C's valence (as for P).
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
        let every_vertex = self.schedule == Schedule::EveryVertex;
        // Under `every-vertex` no vertex has a split valence to overflow
        // (SPEC §7.5, 3.6).
        if !every_vertex {
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
            if every_vertex {
                // The wing gains a neighbour: its valence grows by one.
                if w != NONE {
                    let byte = &mut self.deficit[w as usize];
                    *byte = byte.saturating_add(1);
                }
            } else if w != NONE && self.deficit[w as usize] != LEAF {
                self.deficit[w as usize] -= 1;
                // A wing reaching deficit 0 is a candidate from the next
                // round on (the round's candidates were fixed at its start).
                let d = self.deficit[w as usize];
                self.set_candidate(w, d);
            }
        }
        // P (index r) owns arc 1 (from a to b), C arc 2, which runs from
        // wedge o + d around to wedge o - 1 (mod k).
        let corners = ring.corners();
        for &corner in corners[o + d..].iter().chain(&corners[..o]) {
            if corner != NONE {
                self.corners[corner as usize] = c;
            }
        }
        // R's corners in the wedges on either side of each wing: before_a
        // is C's now (arc 2), after_a P's, before_b P's, after_b C's.
        let before_a = corners[if o == 0 { k - 1 } else { o - 1 }];
        let after_a = corners[o];
        let before_b = corners[o + d - 1];
        let after_b = corners[o + d];
        let (ta, tb) = match (a != NONE, b != NONE) {
            (true, true) => (Some(t), Some(t + 1)),
            (true, false) => (Some(t), None),
            _ => (None, Some(t)),
        };
        // The new triangles are (P, C, a) and (C, P, b). Their swings, and
        // the swings into them, follow from the wedges around them
        // (state.rs: swing[x] is the corner of x's vertex in the next
        // triangle counter-clockwise, NONE across a boundary edge):
        //   around P: before_b → (C, P, b) → ... ; (P, C, a) → after_a
        //   around C: before_a → (P, C, a) → (C, P, b) → after_b
        //   around a: ... → (P, C, a) → the wedge before_a's triangle
        //   around b: the wedge before_b's triangle → (C, P, b) → ...
        let swing_of = |corner: u32, f: fn(u32) -> u32| {
            if corner == NONE { NONE } else { f(corner) }
        };
        if let Some(ta) = ta {
            let (p, cc, w) = (3 * ta, 3 * ta + 1, 3 * ta + 2);
            self.corners[p as usize..p as usize + 3].copy_from_slice(&[r, c, a]);
            self.swing.set(p, after_a);
            self.swing.set(cc, tb.map_or(NONE, |tb| 3 * tb));
            self.swing.set(w, swing_of(before_a, prev));
            if before_a != NONE {
                self.swing.set(before_a, cc);
            }
            if after_a != NONE {
                self.swing.set(next(after_a), w);
            }
        }
        if let Some(tb) = tb {
            let (cc, p, w) = (3 * tb, 3 * tb + 1, 3 * tb + 2);
            self.corners[cc as usize..cc as usize + 3].copy_from_slice(&[c, r, b]);
            self.swing.set(cc, after_b);
            self.swing.set(p, ta.map_or(NONE, |ta| 3 * ta));
            self.swing.set(w, swing_of(before_b, prev));
            if before_b != NONE {
                self.swing.set(before_b, p);
            }
            if after_b != NONE {
                self.swing.set(next(after_b), w);
            }
        }
        let next_t = t + added;
        let (corner_x, corner_y) = match (ta, tb) {
            (Some(ta), _) => (3 * ta, 3 * ta + 1),
            (None, Some(tb)) => (3 * tb + 1, 3 * tb),
            (None, None) => return Err(Error::RingOffsetOutOfRange),
        };
        self.vertex_corner.set(r, corner_x);
        self.vertex_corner.set(c, corner_y);
        self.positions[r as usize] = rec.position_p;
        self.positions[c as usize] = rec.position_c;
        let (byte_p, byte_c) = if every_vertex {
            (
                valence_p.min(MAX_SPLIT_VALENCE) as u8,
                valence_c.min(MAX_SPLIT_VALENCE) as u8,
            )
        } else {
            (rec.deficit_p, rec.deficit_c)
        };
        self.deficit[r as usize] = byte_p;
        self.deficit[c as usize] = byte_c;
        self.set_candidate(r, byte_p);
        self.set_candidate(c, byte_c);
        if every_vertex {
            // R's split-history bit (SPEC §6.1, §7.5, 3.10); C's stays 0,
            // as every bit above the level's first vertex count is.
            let third = self.candidates.len() / 3;
            if let Some(word) = self.candidates[third..2 * third].get_mut((r / 64) as usize) {
                *word |= 1u64 << (r % 64);
            }
        }
        self.vertex_count += 1;
        self.triangle_count = next_t;
        Ok(SplitOutcome {
            triangles_added: added,
            valence_p: valence_p as u32,
            valence_c: valence_c as u32,
        })
    }
}
