//! The canonical 1-ring of a vertex (SPEC §6.1, §7.1).
//!
//! The ring lists the neighbours of `R` counter-clockwise. A boundary vertex
//! gets the ghost vertex ([`NONE`]) in the gap of its open fan, so that every
//! ring is a cycle and the ring length is the valence. The ring starts at the
//! smallest neighbour index, the ghost counting as smaller than every vertex:
//! that start depends only on the mesh, never on the order in which the
//! independent splits of a round were applied.

use crate::Error;
use crate::limits::{MAX_SPLIT_VALENCE, NONE};
use crate::state::{MeshState, next, prev};

/// The ring of a vertex and the corner of that vertex in each wedge.
#[derive(Clone)]
pub struct Ring {
    len: usize,
    /// `vertices[i]` is neighbour `r_i`; [`NONE`] for the ghost.
    vertices: [u32; MAX_SPLIT_VALENCE],
    /// `corners[i]` is the corner of `R` in wedge `W_i = (R, r_i, r_{i+1})`,
    /// [`NONE`] when the wedge is virtual (it touches the ghost).
    corners: [u32; MAX_SPLIT_VALENCE],
    /// Fans walked ahead of their splits (see [`FansAhead`]).
    pub(crate) ahead: FansAhead,
}

impl Default for Ring {
    fn default() -> Self {
        Ring {
            len: 0,
            vertices: [NONE; MAX_SPLIT_VALENCE],
            corners: [NONE; MAX_SPLIT_VALENCE],
            ahead: FansAhead::default(),
        }
    }
}

/// Fans of a round's upcoming splits, walked together before those splits
/// (`round.rs`): walking many fans in lockstep lets their cache misses
/// overlap, where one fan's walk is a chain of dependent loads. A fan walked
/// ahead is still the fan its vertex has when it splits: a split only
/// changes the fans of its own ring, whose vertices do not split in the
/// same round (SPEC §7.2). Only closed fans of up to [`FAN_LEN`] wedges are
/// kept; any other ring is walked when its vertex splits.
#[derive(Clone)]
pub(crate) struct FansAhead {
    /// Vertices whose fans are held, ascending, [`NONE`] past the last.
    pub(crate) owner: [u32; FANS],
    /// Wedges of each fan held; 0 when it was not kept.
    pub(crate) len: [u8; FANS],
    /// Each fan's neighbours and the owner's corner in each wedge, in walk
    /// order (not yet rotated to the canonical start).
    pub(crate) vertices: [[u32; FAN_LEN]; FANS],
    pub(crate) corners: [[u32; FAN_LEN]; FANS],
    /// The first slot that may hold a vertex not yet asked for.
    pub(crate) cursor: usize,
}

/// Fans walked ahead at once (`walk_fans` follows them in a 64-bit mask).
pub(crate) const FANS: usize = 48;
const _: () = assert!(FANS <= 64);
/// Longest fan kept when walked ahead (typical valences; longer rings are
/// walked when their vertex splits).
pub(crate) const FAN_LEN: usize = 12;

impl Default for FansAhead {
    fn default() -> Self {
        FansAhead {
            owner: [NONE; FANS],
            len: [0; FANS],
            vertices: [[NONE; FAN_LEN]; FANS],
            corners: [[NONE; FAN_LEN]; FANS],
            cursor: 0,
        }
    }
}

impl Ring {
    /// A ring of the given neighbours, without corners (unit tests).
    #[cfg(test)]
    pub(crate) fn of_vertices(vertices: &[u32]) -> Ring {
        let mut ring = Ring::default();
        assert!(ring.set_vertices(vertices));
        ring
    }

    /// Makes this the ring of the given neighbours in ring order ([`NONE`]
    /// for the ghost), without corners: for computations on a split's
    /// entries away from the mesh state, with the entries renumbered (an
    /// encoder hands them to another thread). `false`, and nothing changed,
    /// when there are more than [`MAX_SPLIT_VALENCE`].
    pub fn set_vertices(&mut self, vertices: &[u32]) -> bool {
        let Some(slots) = self.vertices.get_mut(..vertices.len()) else {
            return false;
        };
        slots.copy_from_slice(vertices);
        self.corners[..vertices.len()].fill(NONE);
        self.len = vertices.len();
        true
    }

    /// Makes this a ring walked before, entries and corners as the walk
    /// gave them (`pipe.rs` keeps them while a record is read elsewhere).
    /// Both slices have the same length, at most [`MAX_SPLIT_VALENCE`].
    pub(crate) fn set_walked(&mut self, vertices: &[u32], corners: &[u32]) {
        let k = vertices.len().min(corners.len()).min(MAX_SPLIT_VALENCE);
        self.vertices[..k].copy_from_slice(&vertices[..k]);
        self.corners[..k].copy_from_slice(&corners[..k]);
        self.len = k;
    }

    /// Valence: ring length, the ghost counted (SPEC §6.1).
    pub fn len(&self) -> usize {
        self.len
    }

    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// Neighbours in canonical order ([`NONE`] is the ghost).
    pub fn vertices(&self) -> &[u32] {
        &self.vertices[..self.len]
    }

    /// Corner of the centre vertex in each wedge ([`NONE`] when virtual).
    pub fn corners(&self) -> &[u32] {
        &self.corners[..self.len]
    }

    /// Whether the centre is a boundary vertex.
    pub fn is_boundary(&self) -> bool {
        self.len > 0 && self.vertices[0] == NONE
    }
}

impl Ring {
    /// Takes the ring of `r` from the fans walked ahead, if it is there:
    /// rotated to its canonical start (SPEC §7.1, the smallest neighbour).
    /// Vertices are asked for in ascending order.
    fn take_ahead(&mut self, r: u32) -> bool {
        let a = &mut self.ahead;
        while a.cursor < FANS && a.owner[a.cursor] < r {
            a.cursor += 1;
        }
        if a.cursor == FANS || a.owner[a.cursor] != r {
            return false;
        }
        let i = a.cursor;
        let k = (a.len[i] as usize).min(FAN_LEN);
        if k == 0 {
            return false;
        }
        let (vertices, corners) = (&a.vertices[i][..k], &a.corners[i][..k]);
        let mut first = 0;
        for (j, &v) in vertices.iter().enumerate() {
            if v < vertices[first] {
                first = j;
            }
        }
        // Element-wise copies: a handful of entries, where `copy_from_slice`
        // would call `memcpy`.
        let mut j = first;
        for (v, c) in self.vertices[..k].iter_mut().zip(&mut self.corners[..k]) {
            *v = vertices[j];
            *c = corners[j];
            j = if j + 1 == k { 0 } else { j + 1 };
        }
        self.len = k;
        true
    }
}

impl MeshState<'_> {
    /// Fills `ring` with the canonical ring of `r` (SPEC §7.1). Fails with
    /// [`Error::ValenceOverflow`] when the ring is longer than 255.
    pub fn ring(&self, r: u32, ring: &mut Ring) -> Result<(), Error> {
        if r >= self.vertex_count {
            return Err(Error::NoSuchVertex);
        }
        if ring.take_ahead(r) {
            return Ok(());
        }
        let start = self.vertex_corner.get(r);
        let mut c = start;
        let mut n = 0usize;
        loop {
            if n == MAX_SPLIT_VALENCE {
                return Err(Error::ValenceOverflow);
            }
            ring.corners[n] = c;
            ring.vertices[n] = self.vertex_at(next(c));
            n += 1;
            c = self.swing.get(c);
            if c == NONE {
                return self.boundary_ring(start, ring);
            }
            if c == start {
                break;
            }
        }
        let first = (0..n).min_by_key(|&i| ring.vertices[i]).unwrap_or(0);
        rotate_left(&mut ring.vertices[..n], &mut ring.corners[..n], first);
        ring.len = n;
        Ok(())
    }

    fn boundary_ring(&self, start: u32, ring: &mut Ring) -> Result<(), Error> {
        // Walk clockwise to the first wedge after the gap: the wedge before
        // the one at corner c is at next(swing[next(c)]) (state.rs).
        let mut first = start;
        let mut steps = 0;
        loop {
            let s = self.swing.get(next(first));
            if s == NONE {
                break;
            }
            first = next(s);
            steps += 1;
            if steps == MAX_SPLIT_VALENCE {
                return Err(Error::ValenceOverflow);
            }
        }
        ring.vertices[0] = NONE;
        ring.corners[0] = NONE;
        let mut c = first;
        let mut m = 1usize;
        loop {
            // m real wedges need m + 2 ring entries.
            if m + 1 >= MAX_SPLIT_VALENCE {
                return Err(Error::ValenceOverflow);
            }
            ring.corners[m] = c;
            ring.vertices[m] = self.vertex_at(next(c));
            let s = self.swing.get(c);
            if s == NONE {
                ring.vertices[m + 1] = self.vertex_at(prev(c));
                ring.corners[m + 1] = NONE;
                ring.len = m + 2;
                return Ok(());
            }
            c = s;
            m += 1;
        }
    }
}

/// `v.rotate_left(k)` and `c.rotate_left(k)` (slices of one length) by
/// their cycles: each entry moves once, and both arrays in one loop. The
/// standard rotation calls `memmove`, which costs more than a ring of a
/// handful of entries; three reversals (before 2026-12-07) swapped each
/// entry about twice: about 50 instructions a ring more under callgrind.
#[inline]
fn rotate_left(v: &mut [u32], c: &mut [u32], k: usize) {
    let n = v.len().min(c.len());
    if k == 0 || k >= n {
        return;
    }
    // The entry at i takes the one at i + k (mod n); the cycles of that
    // map start at 0, 1, …, gcd(n, k) − 1, one after another.
    let (mut moved, mut start) = (0, 0);
    while moved < n {
        let (held_v, held_c) = (v[start], c[start]);
        let mut i = start;
        loop {
            let j = if i + k >= n { i + k - n } else { i + k };
            moved += 1;
            if j == start {
                break;
            }
            v[i] = v[j];
            c[i] = c[j];
            i = j;
        }
        v[i] = held_v;
        c[i] = held_c;
        start += 1;
    }
}

#[cfg(test)]
mod tests {
    use super::rotate_left;

    #[test]
    fn rotation_by_cycles_is_rotate_left() {
        for n in 0..12u32 {
            for k in 0..n as usize {
                let mut a: [u32; 12] = core::array::from_fn(|i| i as u32);
                let mut c: [u32; 12] = core::array::from_fn(|i| 100 + i as u32);
                let (mut b, mut d) = (a, c);
                rotate_left(&mut a[..n as usize], &mut c[..n as usize], k);
                b[..n as usize].rotate_left(k);
                d[..n as usize].rotate_left(k);
                assert_eq!((a, c), (b, d), "n {n}, k {k}");
            }
        }
    }
}
