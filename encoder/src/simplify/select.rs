//! Step a of §2: each vertex's best incident edge, with the sub-grid tie-break.
//!
//! Validity is checked lazily: a vertex points at its cheapest edge not known
//! to be invalid, and only the pairs that step c chooses are checked
//! (`check_collapse`, in `state`). A refused edge is stamped in its slot with
//! the state it was refused in and stays refused until a collapse changes the
//! 1-ring of one of its endpoints, the only thing that can make it valid.
//! Checking a few chosen pairs instead of every dirty vertex's candidates is
//! most of the simplifier's speed.

use std::sync::atomic::AtomicU32;
use std::sync::atomic::Ordering::Relaxed;

use super::state::State;
use crate::corner_table::{NONE, next, prev};
use crate::quadric::{Quadric, collapse_target};

/// A vertex's chosen collapse; `other == NONE` when it has none.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Best {
    pub other: u32,
    pub error: f64,
    /// Error rounded to f32 bits (flat regions flushed to 0) so that equal
    /// errors tie exactly and the tie-breaks decide.
    pub error_key: u32,
    /// A corner facing the edge (its slot in the Edge array); [`NONE`] where
    /// the chooser does not track slots (GPU backends).
    pub corner: u32,
}

impl Best {
    pub const NONE: Best = Best {
        other: NONE,
        error: f64::INFINITY,
        error_key: u32::MAX,
        corner: NONE,
    };
}

/// Total order of collapse requests: error first, then the lower id wins
/// (the paper's index priority).
pub fn pair_key(b: &Best, v: u32) -> u64 {
    ((b.error_key as u64) << 32) | v.min(b.other) as u64
}

/// Where the collapse of edge (v, u) puts the merged vertex, and its error
/// (`None` when locked boundaries forbid it). Computed from the lower id
/// first, so both endpoints get identical results.
pub fn evaluate(s: &State, v: u32, u: u32) -> Option<([u32; 3], f64)> {
    let (p, c) = (v.min(u), v.max(u));
    let (pi, ci) = (p as usize, c as usize);
    let q = s.quadrics[pi] + s.quadrics[ci];
    let (pp, pc) = (s.positions[pi], s.positions[ci]);
    if (s.lock_boundary && (s.boundary[pi] || s.boundary[ci])) || !s.constrained {
        return evaluate_otherwise(s, p, c, &q);
    }
    Some(constrained_placement(
        s,
        &q,
        (pp, s.to_metric(pp)),
        (pc, s.to_metric(pc)),
    ))
}

/// Constrained mode's placement of a collapse with merged quadric `q`,
/// given P's and C's grid positions and metric points, and its error.
#[inline(always)]
fn constrained_placement(
    s: &State,
    q: &Quadric,
    (pp, gp): ([u32; 3], [f64; 3]),
    (pc, gc): ([u32; 3], [f64; 3]),
) -> ([u32; 3], f64) {
    // P, C or their midpoint, in that order on ties (P's and C's errors
    // taken together).
    let [ep, ec] = q.error_pair(gp, gc);
    let mut best = (pp, ep);
    if ec < best.1 {
        best = (pc, ec);
    }
    let mid = midpoint(pp, pc);
    let e = q.error(s.to_metric(mid));
    if e < best.1 {
        best = (mid, e);
    }
    // The error is already known: a fourth evaluation of the quadric would
    // give the same bits.
    best
}

/// [`edge_slot`] of the edges of one vertex `r` in turn (a refresh's):
/// r's quadric, position and point are read once, not once an edge; the
/// same operations otherwise, so the same slots.
pub struct EdgesOf {
    r: u32,
    quadric: Quadric,
    position: [u32; 3],
    point: [f64; 3],
}

impl EdgesOf {
    pub fn new(s: &State, r: u32) -> EdgesOf {
        let position = s.positions[r as usize];
        EdgesOf {
            r,
            quadric: s.quadrics[r as usize],
            position,
            point: s.to_metric(position),
        }
    }

    /// The slot of the edge from `r` to `x`.
    #[inline]
    pub fn slot(&self, s: &State, x: u32) -> EdgeSlot {
        let (r, xi) = (self.r, x as usize);
        let locked = s.lock_boundary && (s.boundary[r as usize] || s.boundary[xi]);
        let placed = if locked || !s.constrained {
            evaluate(s, r, x).map(|(_, error)| error)
        } else {
            let end = (s.positions[xi], s.geometry(x));
            let own = (self.position, self.point);
            // The lower id is P, and its quadric the sum's left operand.
            let (q, p, c) = if r < x {
                (self.quadric + s.quadrics[xi], own, end)
            } else {
                (s.quadrics[xi] + self.quadric, end, own)
            };
            Some(constrained_placement(s, &q, p, c).1)
        };
        match placed {
            Some(error) => EdgeSlot {
                error,
                refused: 0,
                valid: 0,
            },
            None => EdgeSlot::FORBIDDEN,
        }
    }
}

/// [`evaluate`] of edge (p, c), p < c, with merged quadric `q`, where a
/// locked boundary holds an end or the placement is optimal. Out of line:
/// the constrained path, the one every raster and default encode takes,
/// then keeps the quadric in registers (taken by reference here, it went
/// through the stack on every evaluation).
#[inline(never)]
fn evaluate_otherwise(s: &State, p: u32, c: u32, q: &Quadric) -> Option<([u32; 3], f64)> {
    let (pi, ci) = (p as usize, c as usize);
    let (pp, pc) = (s.positions[pi], s.positions[ci]);
    let target = if s.lock_boundary && (s.boundary[pi] || s.boundary[ci]) {
        match (s.boundary[pi], s.boundary[ci]) {
            (true, true) => return None,
            (true, false) => pp,
            _ => pc,
        }
    } else {
        let (t, _) = collapse_target(q, s.geometry(p), s.geometry(c), false);
        let top = ((1u64 << s.bits) - 1) as f64;
        std::array::from_fn(|k| to_grid(t[k] / s.metric[k], top))
    };
    Some((target, q.error(s.to_metric(target))))
}

/// The placements a collapse of (v, u) may take instead of `first`, the
/// one [`evaluate`] gives, when that one folds a triangle: in constrained
/// mode, P or C where its error has `first`'s key under `scale` (on a flat
/// region, every error 0, both). Taking an equal keeps the collapse's rank
/// in its step. Not the midpoint: taken as a way out, it made the rasters
/// measured 0.3–2 % larger than the ends alone (encoder/BENCHMARKS.md,
/// "Flat and tilted rasters"). None in optimal mode, whose placement has
/// no equal.
pub fn other_placements(
    s: &State,
    v: u32,
    u: u32,
    first: [u32; 3],
    scale: Scale,
) -> impl Iterator<Item = [u32; 3]> {
    let (p, c) = (v.min(u), v.max(u));
    let (pi, ci) = (p as usize, c as usize);
    let locked = s.lock_boundary && (s.boundary[pi] || s.boundary[ci]);
    let mut out = [[0u32; 3]; 2];
    let mut len = 0;
    if s.constrained && !locked {
        let q = s.quadrics[pi] + s.quadrics[ci];
        let (pp, pc) = (s.positions[pi], s.positions[ci]);
        let key = error_key(q.error(s.to_metric(first)), scale);
        for place in [pp, pc] {
            if place != first
                && !out[..len].contains(&place)
                && error_key(q.error(s.to_metric(place)), scale) == key
            {
                out[len] = place;
                len += 1;
            }
        }
    }
    out.into_iter().take(len)
}

/// The integer midpoint `P + ((C − P) >> 1)` of constrained mode (SPEC
/// §7.4).
fn midpoint(pp: [u32; 3], pc: [u32; 3]) -> [u32; 3] {
    std::array::from_fn(|k| (pp[k] as i64 + ((pc[k] as i64 - pp[k] as i64) >> 1)) as u32)
}

/// `x.round().clamp(0.0, top) as u32` (round half away from zero) for a
/// grid top below 2^32, without the libm call `round` becomes on x86-64
/// without SSE4.1: three per edge evaluation.
#[inline]
fn to_grid(x: f64, top: f64) -> u32 {
    if x >= top {
        return top as u32;
    }
    // Below 0.5 (NaN included) `round` gives 0 or less.
    if x.is_nan() || x < 0.5 {
        return 0;
    }
    // 0.5 <= x < top: truncation and the exact fraction round it.
    let i = x as u32;
    i + u32::from(x - f64::from(i) >= 0.5)
}

/// Cached collapse error of the edge facing one corner (the paper's Edge
/// array), kept at the lower of the edge's two corners
/// ([`State::slot_index`]). The merged position is not kept: only the few
/// pairs a step checks need it, and [`evaluate`] gives it again exactly (the
/// slot is refreshed whenever an end changes). A slot is then 16 bytes, and
/// the Edge array is the one the passes read most, at random.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EdgeSlot {
    pub error: f64,
    /// State number (see [`Known`]) in which the collapse was checked and
    /// found invalid; 0 if it never was since the slot was evaluated.
    pub refused: u32,
    /// State number in which the collapse was last checked and found valid
    /// (0: never since the slot was evaluated). Kept in the slot's padding.
    pub valid: u32,
}

impl EdgeSlot {
    pub const FORBIDDEN: EdgeSlot = EdgeSlot {
        error: f64::INFINITY,
        refused: 0,
        valid: 0,
    };
}

/// The slot of the edge facing corner `c` (the edge from next(c) to prev(c)).
pub fn edge_slot(s: &State, c: u32) -> EdgeSlot {
    let (a, b) = (s.table.v(next(c)), s.table.v(prev(c)));
    if a == NONE {
        return EdgeSlot::FORBIDDEN;
    }
    match evaluate(s, a, b) {
        Some((_, error)) => EdgeSlot {
            error,
            refused: 0,
            valid: 0,
        },
        None => EdgeSlot::FORBIDDEN,
    }
}

/// Scale of the current mesh, for the tie-breaks.
#[derive(Clone, Copy, Debug)]
pub struct Scale {
    /// Sub-grid cell size (0: no sub-grid).
    pub cell: f64,
    /// Errors below this count as flat (exactly 0).
    pub flat: f64,
}

fn cell_of(p: [f64; 3], cell: f64) -> [i64; 3] {
    p.map(|x| floor_i64(x / cell))
}

/// `x.floor() as i64`, without the libm call `floor` becomes on x86-64
/// without SSE4.1 (the cell tie-break runs once per considered edge).
pub(super) fn floor_i64(x: f64) -> i64 {
    let i = x as i64;
    if (i as f64) > x {
        i.saturating_sub(1)
    } else {
        i
    }
}

/// What the chooser knows about validity and this step's blocked vertices.
/// States are numbered from 1: state k is the mesh step k - 1 selects on.
#[derive(Clone, Copy)]
pub struct Known<'a> {
    /// The current state.
    pub state: u32,
    /// Per vertex, the state since which its 1-ring is what it is now.
    pub changed: &'a [u32],
    /// Per vertex, `== state` when a winner of this step blocks it.
    pub blocked: &'a [AtomicU32],
}

impl Known<'_> {
    /// Whether a slot's refusal still holds: neither endpoint's 1-ring (fan
    /// and neighbour positions, all a check reads but the wings' valences,
    /// which only fall and so cannot make a refused edge valid) changed
    /// since the refusal.
    pub fn refused(&self, slot: &EdgeSlot, v: u32, u: u32) -> bool {
        slot.refused != 0
            && slot.refused >= self.changed[v as usize]
            && slot.refused >= self.changed[u as usize]
    }

    /// Whether a slot was found valid since the 1-rings of both endpoints
    /// last changed (a hint: falling wing valences can still make it
    /// invalid, so winners are checked again).
    pub fn valid(&self, slot: &EdgeSlot, v: u32, u: u32) -> bool {
        slot.valid != 0
            && slot.valid >= self.changed[v as usize]
            && slot.valid >= self.changed[u as usize]
    }
}

/// Order of one vertex's requests: error key, then same sub-grid cell
/// (Fig. 2), then the minimal coordinates of the other end, then its id.
/// The tie-break is computed only between equal keys (the sub-grid cell
/// costs three divisions a vertex).
struct Order<'a> {
    s: &'a State,
    v: u32,
    scale: Scale,
    home: std::cell::OnceCell<Option<[i64; 3]>>,
}

impl<'a> Order<'a> {
    fn new(s: &'a State, v: u32, scale: Scale) -> Order<'a> {
        Order {
            s,
            v,
            scale,
            home: std::cell::OnceCell::new(),
        }
    }

    fn tie(&self, u: u32) -> (bool, [u32; 3], u32) {
        let (s, cell) = (self.s, self.scale.cell);
        let home = self
            .home
            .get_or_init(|| (cell > 0.0).then(|| cell_of(s.geometry(self.v), cell)));
        let other_cell = home.is_some_and(|h| h != cell_of(s.geometry(u), cell));
        (other_cell, s.positions[u as usize], u)
    }

    /// Whether the edge to `u` with key `key` ranks before `b`. Real keys
    /// stay below u32::MAX, the key of no choice, so [`Best::NONE`] ranks
    /// last.
    fn before(&self, key: u32, u: u32, b: &Best) -> bool {
        if key != b.error_key {
            key < b.error_key
        } else {
            self.tie(u) < self.tie(b.other)
        }
    }
}

/// The key requests are ordered by: the error rounded to f32 (monotone),
/// 0 for flat ones.
pub fn error_key(error: f64, scale: Scale) -> u32 {
    if error <= scale.flat {
        0
    } else {
        (error as f32).to_bits()
    }
}

/// A vertex's two cheapest choices with different partners, in [`Order`];
/// `second` is `None` when it is not known (the best was taken from it
/// since the last full pick).
#[derive(Clone, Copy, Debug)]
pub struct Choices {
    pub best: Best,
    pub second: Option<Best>,
    /// A lower bound of the keys of the other candidates, those after
    /// `second` (after `best` where `second` is not known); `u32::MAX`
    /// when there are none. What a change of scale cannot reorder is
    /// told by it (`cpu::rescaled`).
    pub bound: u32,
}

/// The two cheapest candidates of one vertex seen so far, in [`Order`].
pub struct Ranking<'a> {
    order: Order<'a>,
    best: Best,
    second: Best,
    /// The smallest key after the two.
    third: u32,
}

impl<'a> Ranking<'a> {
    pub fn new(s: &'a State, v: u32, scale: Scale) -> Ranking<'a> {
        Ranking {
            order: Order::new(s, v, scale),
            best: Best::NONE,
            second: Best::NONE,
            third: u32::MAX,
        }
    }

    /// Considers the edge to `u` whose slot (held by corner `facing`) is
    /// `slot`.
    #[inline(always)]
    pub fn consider(&mut self, u: u32, facing: u32, slot: &EdgeSlot) {
        if slot.error == f64::INFINITY {
            return;
        }
        let key = error_key(slot.error, self.order.scale);
        if key > self.second.error_key || !self.order.before(key, u, &self.second) {
            self.third = self.third.min(key);
            return;
        }
        let choice = Best {
            other: u,
            error: slot.error,
            error_key: key,
            corner: facing,
        };
        self.third = self.third.min(self.second.error_key);
        if self.order.before(key, u, &self.best) {
            self.second = self.best;
            self.best = choice;
        } else {
            self.second = choice;
        }
    }

    pub fn choices(&self) -> Choices {
        Choices {
            best: self.best,
            second: Some(self.second),
            bound: self.third,
        }
    }
}

/// §2 step a: the cheapest edge of `v` to a neighbour that is not blocked,
/// skipping edges known to be invalid (their validity is checked only once
/// chosen), in [`Ranking`] order, and the runner-up with another partner.
///
/// `reopened` receives the neighbours `u` whose edge to `v` was refused before
/// `v`'s 1-ring last changed: that edge may be valid again and `u` should
/// choose again too.
pub fn pick_edge(
    s: &State,
    v: u32,
    scale: Scale,
    known: Known<'_>,
    reopened: &mut Vec<u32>,
) -> Choices {
    let mut ranking = Ranking::new(s, v, scale);
    if !s.alive[v as usize] {
        return ranking.choices();
    }
    let edges = PickEdges {
        s,
        v,
        known,
        changed_v: known.changed[v as usize],
    };
    // Every edge of v once: (v, next c) faces prev c for each corner c; on a
    // boundary the edge (v, prev c) of the fan's open end faces next c and
    // has no corner of its own.
    s.table.for_each_corner(v, |c| {
        edges.consider(&mut ranking, reopened, s.table.v(next(c)), prev(c));
        if s.table.o(next(c)) == NONE {
            edges.consider(&mut ranking, reopened, s.table.v(prev(c)), next(c));
        }
    });
    ranking.choices()
}

/// What [`pick_edge`] weighs each edge of `v` with.
struct PickEdges<'a> {
    s: &'a State,
    v: u32,
    known: Known<'a>,
    changed_v: u32,
}

impl PickEdges<'_> {
    /// Ranks the edge to `u` facing corner `facing`, unless `u` is blocked
    /// or the edge is known to be invalid. (Inlined: as a call, with the
    /// ranking's, it cost the picks about half their instructions again.)
    #[inline(always)]
    fn consider(&self, ranking: &mut Ranking<'_>, reopened: &mut Vec<u32>, u: u32, facing: u32) {
        let (s, known) = (self.s, &self.known);
        if known.blocked[u as usize].load(Relaxed) == known.state {
            return;
        }
        let slot = s.slot(facing);
        if slot.refused != 0 {
            if known.refused(slot, self.v, u) {
                return;
            }
            if slot.refused < self.changed_v {
                reopened.push(u);
            }
        }
        ranking.consider(u, facing, slot);
    }
}

/// Updates `choices` of `v` with its edge to `u` facing corner `facing`,
/// an edge whose slot was refreshed (no refusal, nothing blocked): the two
/// cheapest of the old candidates and the new one. An unknown runner-up
/// stays unknown unless the new edge beats the best (the old best is then
/// the runner-up).
pub fn offer(s: &State, v: u32, choices: &mut Choices, u: u32, facing: u32, scale: Scale) {
    let slot = s.slot(facing);
    if slot.error == f64::INFINITY {
        return;
    }
    let key = error_key(slot.error, scale);
    let last = choices
        .second
        .map_or(choices.best.error_key, |b| b.error_key);
    if key > last {
        choices.bound = choices.bound.min(key);
        return;
    }
    let order = Order::new(s, v, scale);
    let choice = Best {
        other: u,
        error: slot.error,
        error_key: key,
        corner: facing,
    };
    if order.before(key, u, &choices.best) {
        // A known runner-up falls behind; without one, everything behind
        // the old best stays behind the new runner-up.
        if let Some(second) = choices.second {
            choices.bound = choices.bound.min(second.error_key);
        }
        choices.second = Some(choices.best);
        choices.best = choice;
    } else if let Some(second) = choices.second
        && order.before(key, u, &second)
    {
        choices.bound = choices.bound.min(second.error_key);
        choices.second = Some(choice);
    } else {
        choices.bound = choices.bound.min(key);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn inline_rounding_matches_libm() {
        let top = 16383.0;
        let mut xs = vec![
            0.0,
            -0.0,
            0.5,
            -0.5,
            1.5,
            2.5,
            -1.5,
            0.49999999999999994,
            -0.49999999999999994,
            16382.5,
            16383.4999,
            16383.5,
            1e300,
            -1e300,
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::NAN,
            4.0e15 + 0.5,
            -3.2,
            7.9999999,
        ];
        let mut x = 0.1234f64;
        for _ in 0..10_000 {
            x = (x * 7919.0 + 0.377).rem_euclid(40_000.0) - 10_000.0;
            xs.push(x);
            xs.push(x.floor() + 0.5);
        }
        for &x in &xs {
            assert_eq!(to_grid(x, top), x.round().clamp(0.0, top) as u32, "{x}");
            let wide = ((1u64 << 31) - 1) as f64;
            for y in [x, x * 1e5, wide - 0.5, wide - 0.25, wide + 3.0] {
                assert_eq!(to_grid(y, wide), y.round().clamp(0.0, wide) as u32, "{y}");
            }
            assert_eq!(floor_i64(x), x.floor() as i64, "{x}");
        }
    }
}
