//! Records read positions first (SPEC §7.4 "Positions first", format 3.7).
//!
//! On a terrain whose x and y lie on a lattice, a split vertex's fan is, in
//! the xy projection, a star of triangles with no other vertex inside, and
//! the split's new vertex lies on a free lattice point in it. A record of a
//! level whose record order is `positions-first` names that point by its
//! rank among the fan's free points (nearest first to the ring's centroid),
//! then the wings by their ranks among the pairs of ring entries that keep
//! every new triangle counter-clockwise in xy, widest angle first. The
//! decoder and the encoder share this module, so both sides count the same
//! points and pairs.
//!
//! Every quantity is relative to R in x and y, and the cap on the fan's
//! bounding box (1,024 lattice points) keeps coordinates below 2^10, so
//! 64-bit arithmetic is exact throughout (SPEC §7.4 "Bounds").

use core::cmp::Ordering;

use crate::limits::{MAX_SPLIT_VALENCE, NONE};
use crate::ring::Ring;
use crate::symbols::WingCandidates;

/// How a level's split records are read (SPEC §5.1, level header byte 11,
/// format 3.7).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum RecordOrder {
    /// Formats 3.0 to 3.6: the wings, the split valences, then the
    /// placement code and the residual vector.
    #[default]
    WingsFirst,
    /// 3.7, constrained mode under the plane policy `height` only: the new
    /// vertex as a lattice rank, then the wings among the pairs that keep
    /// the new triangles counter-clockwise in xy; an escape reads the
    /// record as `WingsFirst` does.
    PositionsFirst,
}

impl RecordOrder {
    /// Every choice.
    pub const ALL: [RecordOrder; 2] = [RecordOrder::WingsFirst, RecordOrder::PositionsFirst];

    /// The order of a level header's byte 11 (SPEC §5.1): 0 `wings-first`,
    /// 1 to 3 `positions-first` (with the [`Ties`] of
    /// [`Ties::from_record_byte`]).
    pub fn from_byte(b: u8) -> Option<RecordOrder> {
        match b {
            0 => Some(RecordOrder::WingsFirst),
            1..=3 => Some(RecordOrder::PositionsFirst),
            _ => None,
        }
    }

    /// Byte 11 of a level header for this order and, positions first, its
    /// ties (SPEC §5.1).
    pub fn to_byte(self, ties: Ties) -> u8 {
        match self {
            RecordOrder::WingsFirst => 0,
            RecordOrder::PositionsFirst => 1 + ties as u8,
        }
    }

    /// The name `splitstream info` and the SPEC use.
    pub fn name(self) -> &'static str {
        match self {
            RecordOrder::WingsFirst => "wings-first",
            RecordOrder::PositionsFirst => "positions-first",
        }
    }

    /// The SPEC's name of byte 11 for this order and, positions first,
    /// its ties (SPEC §5.1): `wings-first`, `positions-first`,
    /// `positions-first-rising`, `positions-first-falling`.
    pub fn name_with(self, ties: Ties) -> &'static str {
        match (self, ties) {
            (RecordOrder::WingsFirst, _) => "wings-first",
            (RecordOrder::PositionsFirst, Ties::Ring) => "positions-first",
            (RecordOrder::PositionsFirst, Ties::Rising) => "positions-first-rising",
            (RecordOrder::PositionsFirst, Ties::Falling) => "positions-first-falling",
        }
    }
}

/// How a positions-first level orders wing choices that see the new edge
/// under the same angle (SPEC §5.1, §7.4 `before`; format 3.8). On a
/// raster whose cells the mesh splits along one diagonal, four lattice
/// points on one circle are common (the corners of a cell), and the
/// finest levels' edges never run along the other diagonal: a choice
/// whose new edges would is most likely not the wing.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Ties {
    /// By ring position alone (3.7's `positions-first`).
    #[default]
    Ring,
    /// First the choice with fewer new edges along the falling diagonal
    /// (`dx = −dy ≠ 0`): the cells are split along the rising one.
    Rising,
    /// First the choice with fewer new edges along the rising diagonal
    /// (`dx = dy ≠ 0`): the cells are split along the falling one.
    Falling,
}

impl Ties {
    /// Every rule, in byte order.
    pub const ALL: [Ties; 3] = [Ties::Ring, Ties::Rising, Ties::Falling];

    /// The ties of a positions-first level's byte 11 (SPEC §5.1): 1
    /// `ring`, 2 `rising`, 3 `falling`.
    pub fn from_record_byte(b: u8) -> Option<Ties> {
        Ties::ALL.get((b as usize).wrapping_sub(1)).copied()
    }

    /// The name `splitstream info` and the SPEC use.
    pub fn name(self) -> &'static str {
        match self {
            Ties::Ring => "ring",
            Ties::Rising => "rising",
            Ties::Falling => "falling",
        }
    }

    /// Whether an edge of direction `d` runs along the diagonal this rule
    /// disfavours.
    #[inline]
    fn off_diagonal(self, d: [i64; 2]) -> bool {
        match self {
            Ties::Ring => false,
            Ties::Rising => d[0] != 0 && d[0] == -d[1],
            Ties::Falling => d[0] != 0 && d[0] == d[1],
        }
    }
}

/// Most lattice points a fan's bounding box may hold (SPEC §7.4
/// `free_points`): past it the record is an escape.
pub const POINT_CAP: i64 = 1024;
/// Most free points a fan may have: past it the record is an escape.
pub const LIST_CAP: usize = 255;

/// The placement substream's context of the kind (SPEC §5.5.5).
pub const KIND_CONTEXT: u8 = 5;
/// The placement substream's context of a midpoint's offset.
pub const OFFSET_CONTEXT: u8 = 6;
/// The edge substream's context of the z residual.
pub const Z_CONTEXT: u8 = 2;
/// The kind that escapes to the wings-first record.
pub const KIND_ESCAPE: u8 = 2;

/// The edge substream's context of the lattice rank, by the number of free
/// points `f` (SPEC §5.5.5): 1, 2, 3–4, 5–8, 9 or more.
#[inline]
pub fn rank_context(f: usize) -> u8 {
    3 + match f {
        0 | 1 => 0,
        2 => 1,
        3..=4 => 2,
        5..=8 => 3,
        _ => 4,
    }
}

/// The wing substreams' context of a rank among `choices` choices.
#[inline]
pub fn choice_context(choices: usize) -> u8 {
    (choices.clamp(1, 8) - 1) as u8
}

/// `orient(a, b, c)` of SPEC §7.4: twice the signed area of `a b c` in xy.
#[inline]
fn orient(a: [i64; 2], b: [i64; 2], c: [i64; 2]) -> i64 {
    (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])
}

/// `incircle(a, b, c, p)` of SPEC §7.4: positive when `p` lies inside the
/// circle through `a`, `b`, `c` (counter-clockwise). The decoder orders the
/// wing choices by [`angle_of`] instead, which gives the same order (a test
/// below holds them equal).
#[cfg(test)]
fn incircle(a: [i64; 2], b: [i64; 2], c: [i64; 2], p: [i64; 2]) -> i64 {
    let row = |v: [i64; 2]| {
        let (dx, dy) = (v[0] - p[0], v[1] - p[1]);
        (dx, dy, dx * dx + dy * dy)
    };
    let (ax, ay, al) = row(a);
    let (bx, by, bl) = row(b);
    let (cx, cy, cl) = row(c);
    ax * (by * cl - bl * cy) - ay * (bx * cl - bl * cx) + al * (bx * cy - by * cx)
}

/// How wide the angle is under which `q` sees the segment `e f`, as the
/// pair `(dot, cross)` of `e − q` and `f − q`: for `q` strictly left of
/// `e → f` (`cross > 0`), the angle's cotangent is `dot / cross`, smaller
/// for a wider angle. Inscribed angles on one side of a chord grow inside
/// the circle, so `incircle(e, f, c, p) > 0` exactly when `p`'s cotangent
/// is below `c`'s ([`wider`]): two products where the determinant takes a
/// dozen. Under the point cap every coordinate is below 2^12 in magnitude,
/// so both values are below 2^25 and their products below 2^50.
#[inline]
fn angle_of(e: [i64; 2], f: [i64; 2], q: [i64; 2]) -> [i64; 2] {
    let (u, v) = ([e[0] - q[0], e[1] - q[1]], [f[0] - q[0], f[1] - q[1]]);
    [u[0] * v[0] + u[1] * v[1], u[0] * v[1] - u[1] * v[0]]
}

/// `Less` when angle `p` (of [`angle_of`]) is wider than angle `c`,
/// `Equal` when they are the same (the four points on one circle).
#[inline]
fn wider(p: [i64; 2], c: [i64; 2]) -> Ordering {
    (p[0] * c[1]).cmp(&(c[0] * p[1]))
}

/// The greatest common divisor (`gcd(0, 0) = 0`): the lattice points on
/// a segment, less one end. Most fan edges are a few steps long: a table
/// answers those (a division per step of Euclid's algorithm cost more than
/// the rest of a fan's count), Stein's binary algorithm the others.
fn gcd(a: u64, b: u64) -> u64 {
    if a < SMALL_GCD as u64 && b < SMALL_GCD as u64 {
        return SMALL_GCDS[a as usize][b as usize] as u64;
    }
    if a == 0 || b == 0 {
        return a | b;
    }
    let shift = (a | b).trailing_zeros();
    let (mut a, mut b) = (a >> a.trailing_zeros(), b);
    while b != 0 {
        b >>= b.trailing_zeros();
        if a > b {
            (a, b) = (b, a);
        }
        b -= a;
    }
    a << shift
}

/// [`gcd`]'s table: `SMALL_GCDS[a][b]` for `a, b < SMALL_GCD`.
const SMALL_GCD: usize = 16;
const SMALL_GCDS: [[u8; SMALL_GCD]; SMALL_GCD] = {
    let mut table = [[0u8; SMALL_GCD]; SMALL_GCD];
    let mut a = 0;
    while a < SMALL_GCD {
        let mut b = 0;
        while b < SMALL_GCD {
            let (mut x, mut y) = (a, b);
            while y != 0 {
                (x, y) = (y, x % y);
            }
            table[a][b] = x as u8;
            b += 1;
        }
        a += 1;
    }
    table
};

/// Words of the free-point map: [`POINT_CAP`] bits and a spare word.
const INSIDE_WORDS: usize = POINT_CAP as usize / 64 + 1;

/// Rows of at most this many points take one fixed-length pass.
const SHORT_ROW: usize = 4;

/// Whether each of the first `len` (1..=64) points of a row is inside a
/// triangle, as bits: `f` holds the three orientations at the row's first
/// point, `steps` what they gain per point. Inside when none is negative:
/// no sign bit in their OR (branch-free: the test is not predictable).
/// Inlined, so that a constant `len` gives a fixed-length pass.
#[inline(always)]
fn row_bits(f: [i64; 3], steps: [i64; 3], len: usize) -> u64 {
    let mut bits = 0u64;
    let mut f = f;
    for i in 0..len {
        bits |= u64::from((f[0] | f[1] | f[2]) >= 0) << i;
        for (f, step) in f.iter_mut().zip(steps) {
            *f += step;
        }
    }
    bits
}

/// The bounding box's points in the closed triangle `(0, a, b)`
/// (`inside` of SPEC §7.4; `ccw`: its orientation, it has an area), row
/// by row: `emit(index, bits)` for each row, `bits` the row's points from
/// map index `index` on (the box's low corner `corner`, its `width`), at
/// most 64 at a time. Each of the three orientations is linear in the
/// point, so a row steps them by a constant; with their signs turned so
/// that the triangle is counter-clockwise, a point is inside when none is
/// negative (the three sum to twice the area, so they cannot all be
/// negative or zero as for a clockwise triangle).
#[inline(always)]
fn triangle_rows(
    a: [i64; 2],
    b: [i64; 2],
    ccw: bool,
    corner: [i64; 2],
    width: i64,
    mut emit: impl FnMut(usize, u64),
) {
    let sign = if ccw { 1 } else { -1 };
    // orient(u, v, p) = step_x · p_x + step_y · p_y + at_origin.
    let edge = |u: [i64; 2], v: [i64; 2]| {
        let (dx, dy) = (v[0] - u[0], v[1] - u[1]);
        (-dy * sign, dx * sign, (dy * u[0] - dx * u[1]) * sign)
    };
    let edges = [edge([0, 0], a), edge(a, b), edge(b, [0, 0])];
    let (lx, hx) = (a[0].min(b[0]).min(0), a[0].max(b[0]).max(0));
    let (ly, hy) = (a[1].min(b[1]).min(0), a[1].max(b[1]).max(0));
    let len = (hx - lx + 1) as usize;
    let steps = edges.map(|e| e.0);
    let mut f = edges.map(|(sx, sy, c)| sx * lx + sy * ly + c);
    let mut start = ((ly - corner[1]) * width + (lx - corner[0])) as usize;
    for _ in ly..hy + 1 {
        // A loop as long as the row mispredicted its exit on most rows;
        // the short rows, most of them, take a fixed number of tests
        // (points past the row are outside the triangle).
        let bits = if len <= SHORT_ROW {
            row_bits(f, steps, SHORT_ROW)
        } else if len <= 8 {
            row_bits(f, steps, 8)
        } else {
            row_bits(f, steps, len.min(64))
        };
        emit(start, bits);
        let mut done = 64;
        while done < len {
            // Rows this long are rare: the box holds at most
            // [`POINT_CAP`] points.
            let at: [i64; 3] = core::array::from_fn(|e| f[e] + done as i64 * steps[e]);
            emit(start + done, row_bits(at, steps, (len - done).min(64)));
            done += 64;
        }
        for (f, e) in f.iter_mut().zip(&edges) {
            *f += e.1;
        }
        start += width as usize;
    }
}

/// ORs `bits` into the map `inside` from bit `index` on (the bits set lie
/// inside the bounding box's points).
#[inline(always)]
fn mark_bits(inside: &mut [u64; INSIDE_WORDS], index: usize, bits: u64) {
    let (word, shift) = (index / 64, index % 64);
    // The bits past the word go to the next one, branch-free (the branch
    // was mispredicted): `(bits >> 1) >> (63 − shift)` is `bits >> (64 −
    // shift)`, and 0 for shift 0, where no bit passes. The map has a spare
    // word for a row that ends in the last one.
    inside[word] |= bits << shift;
    inside[word + 1] |= (bits >> 1) >> (63 - shift);
}

/// `i mod k` for `i < 2k`, without a branch (a ring position past the
/// ring's end, as data: a branch on it mispredicted).
#[inline]
fn wrap_once(i: usize, k: usize) -> usize {
    i - (k & 0usize.wrapping_sub(usize::from(i >= k)))
}

/// Whether direction `v` (not 0, coordinates below 2^31 in magnitude)
/// lies in the lower half-turn, at an angle in [π, 2π) counter-clockwise
/// from +x: `(y, x) < (0, 0)` in lexicographic order, one comparison.
#[inline]
fn lower_half(v: [i64; 2]) -> bool {
    (v[1] << 32) + v[0] < 0
}

/// The squared distance to the centroid (times n²) of a packed key.
#[inline]
fn distance_of(key: u64) -> i64 {
    (key >> 20) as i64
}

/// A split's fan in xy, its free lattice points and its wing pairs: the
/// scratch a record read positions first needs, kept between records so
/// that nothing is cleared per split but what it uses.
#[derive(Clone)]
pub struct PositionsFirst {
    /// Ring length.
    k: usize,
    /// Entries relative to R in xy; `real[i]` is false for the ghost.
    q: [[i32; 2]; MAX_SPLIT_VALENCE],
    real: [bool; MAX_SPLIT_VALENCE],
    /// The bounding box's low corner and width.
    x0: i64,
    y0: i64,
    width: i64,
    /// The box's height, and the real entries' count and coordinate sums
    /// (the centroid is `(sx, sy) / n`).
    height: i64,
    n: i64,
    sx: i64,
    sy: i64,
    /// Free points as packed keys (`key`), unordered, `keys[..free]`,
    /// once `listed`: a simple fan is only counted ([`Self::count_simple`])
    /// and listed when a rank needs more than the points near its centroid.
    keys: [u64; LIST_CAP],
    free: usize,
    listed: bool,
    /// In a simple fan, the entry first counter-clockwise from the ray
    /// from R along +x, and how many entries lie in the upper half-turn
    /// (angles in [0, π)): from `turn` on, in ring order, those come first,
    /// then the others, all in increasing angle ([`Self::is_free`]).
    turn: usize,
    upper: usize,
    /// The points of the bounding box inside a wedge, by `(y − y0) width +
    /// (x − x0)`.
    inside: [u64; INSIDE_WORDS],
    /// The wing choices being named (`xs` or `ys` of SPEC §7.4), the edge
    /// `(a, b)` their order goes by, and whether they are in that order.
    choices: [u8; MAX_SPLIT_VALENCE],
    list_edge: [[i64; 2]; 2],
    sorted: bool,
    /// Per ring entry, for the current new edge ([`Self::prepare`]):
    /// whether it may be wing x, wing y; whether its wedge keeps its
    /// orientation under a, under b; how many wedges from it on do under b.
    x_ok: [bool; MAX_SPLIT_VALENCE],
    y_ok: [bool; MAX_SPLIT_VALENCE],
    a_ok: [bool; MAX_SPLIT_VALENCE],
    b_ok: [bool; MAX_SPLIT_VALENCE],
    run_b: [u8; MAX_SPLIT_VALENCE],
    /// Whether every wedge keeps its orientation under both a and b (the
    /// common case: both inside the ring's kernel): then any x and y on
    /// their sides of the edge pair.
    all_ok: bool,
    /// The level's tie-break between choices of equal angle.
    ties: Ties,
}

impl Default for PositionsFirst {
    fn default() -> Self {
        PositionsFirst {
            k: 0,
            q: [[0; 2]; MAX_SPLIT_VALENCE],
            real: [false; MAX_SPLIT_VALENCE],
            x0: 0,
            y0: 0,
            width: 1,
            height: 1,
            n: 1,
            sx: 0,
            sy: 0,
            keys: [0; LIST_CAP],
            free: 0,
            listed: true,
            turn: 0,
            upper: 0,
            inside: [0; INSIDE_WORDS],
            choices: [0; MAX_SPLIT_VALENCE],
            list_edge: [[0; 2]; 2],
            sorted: false,
            x_ok: [false; MAX_SPLIT_VALENCE],
            y_ok: [false; MAX_SPLIT_VALENCE],
            a_ok: [false; MAX_SPLIT_VALENCE],
            b_ok: [false; MAX_SPLIT_VALENCE],
            run_b: [0; MAX_SPLIT_VALENCE],
            all_ok: false,
            ties: Ties::Ring,
        }
    }
}

/// The new edge of a record read positions first, relative to R in xy:
/// `a` owns the ring's arc from wing x to wing y, `b` the rest.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct NewEdge {
    pub a: [i64; 2],
    pub b: [i64; 2],
    /// Kind 1 (R sat on the floor midpoint): then x < y.
    pub midpoint: bool,
}

impl PositionsFirst {
    /// `free_points` of SPEC §7.4 for the split of the vertex at `parent`
    /// whose ring is `ring` (entries index `positions`): the number of free
    /// lattice points, or `None` for an escape (the bounding box holds more
    /// than [`POINT_CAP`] points, no wedge has an area, or no point or more
    /// than [`LIST_CAP`] points are free).
    pub fn free_points(
        &mut self,
        positions: &[[u32; 3]],
        parent: [u32; 3],
        ring: &Ring,
    ) -> Option<usize> {
        if !self.set_ring(positions, parent, ring) {
            return None;
        }
        if let Some(free) = self.count_simple() {
            // Listed lazily, by `point_at` and `rank_of`.
            self.listed = false;
            self.free = if (1..=LIST_CAP).contains(&free) {
                free
            } else {
                0
            };
            return (self.free > 0).then_some(free);
        }
        self.list()
    }

    /// The first step of [`Self::free_points`]: the ring's entries
    /// relative to R, their bounding box and centroid; false when the box
    /// holds more than [`POINT_CAP`] points (an escape). The wing choice
    /// ([`Self::order_xs`]) reads only these (benches call it alone).
    #[inline]
    pub fn set_ring(&mut self, positions: &[[u32; 3]], parent: [u32; 3], ring: &Ring) -> bool {
        let vertices = ring.vertices();
        let k = vertices.len();
        self.k = k;
        let (rx, ry) = (parent[0] as i64, parent[1] as i64);
        let (mut x0, mut x1, mut y0, mut y1) = (0i64, 0i64, 0i64, 0i64);
        let (mut n, mut sx, mut sy) = (0i64, 0i64, 0i64);
        for (i, &v) in vertices.iter().enumerate() {
            let p = if v == NONE {
                None
            } else {
                positions.get(v as usize)
            };
            match p {
                Some(p) => {
                    let q = [p[0] as i64 - rx, p[1] as i64 - ry];
                    x0 = x0.min(q[0]);
                    x1 = x1.max(q[0]);
                    y0 = y0.min(q[1]);
                    y1 = y1.max(q[1]);
                    n += 1;
                    sx += q[0];
                    sy += q[1];
                    // |q| < 2^31: positions are below 2^31.
                    self.q[i] = [q[0] as i32, q[1] as i32];
                    self.real[i] = true;
                }
                None => {
                    self.q[i] = [0, 0];
                    self.real[i] = false;
                }
            }
        }
        let (width, height) = (x1 - x0 + 1, y1 - y0 + 1);
        if width * height > POINT_CAP {
            return false;
        }
        (self.x0, self.y0, self.width, self.height) = (x0, y0, width, height);
        (self.n, self.sx, self.sy) = (n, sx, sy);
        true
    }

    /// The free points of the last fan, listed in `keys` (the part of
    /// [`Self::free_points`] after the bounding box).
    fn list(&mut self) -> Option<usize> {
        self.listed = true;
        self.free = 0;
        let (k, x0, y0, width, height) = (self.k, self.x0, self.y0, self.width, self.height);
        let (n, sx, sy) = (self.n, self.sx, self.sy);
        let words = ((width * height) as usize).div_ceil(64);
        self.inside[..words].fill(0);
        let mut any_wedge = false;
        // Most boxes fit one word: it stays in a register while the wedges
        // mark it (rows ORed into memory waited for each other's stores).
        let mut word = 0u64;
        for i in 0..k {
            let j = if i + 1 == k { 0 } else { i + 1 };
            if !(self.real[i] && self.real[j]) {
                continue;
            }
            let (a, b) = (self.q(i), self.q(j));
            let area = orient([0, 0], a, b);
            if area == 0 {
                continue;
            }
            any_wedge = true;
            let corner = [x0, y0];
            if words == 1 {
                triangle_rows(a, b, area > 0, corner, width, |start, bits| {
                    word |= bits << start
                });
            } else {
                let inside = &mut self.inside;
                triangle_rows(a, b, area > 0, corner, width, |start, bits| {
                    mark_bits(inside, start, bits)
                });
            }
        }
        if !any_wedge {
            return None;
        }
        if words == 1 {
            self.inside[0] = word;
        }
        // R and the ring entries are not free.
        self.unmark([0, 0]);
        for i in 0..k {
            if self.real[i] {
                self.unmark(self.q(i));
            }
        }
        let mut free = 0;
        // A point's row is its index divided by the width, by a
        // multiplication: with `m = ceil(2^32 / width)`, `index · m / 2^32`
        // exceeds `index / width` by less than `index / 2^32 < 2^-22`, less
        // than the distance from a fraction `j / width` to the next
        // integer, so the floor is exact (following the rows with a loop
        // mispredicted its exit at every new row).
        let per_row = (1u64 << 32).div_ceil(width as u64);
        for w in 0..words {
            let mut word = self.inside[w];
            while word != 0 {
                let index = 64 * w as u64 + word.trailing_zeros() as u64;
                word &= word - 1;
                if free == LIST_CAP {
                    return None;
                }
                let dy = ((index * per_row) >> 32) as i64;
                let dx = index as i64 - dy * width;
                let (x, y) = (x0 + dx, y0 + dy);
                let (ex, ey) = (n * x - sx, n * y - sy);
                let distance = (ex * ex + ey * ey) as u64;
                self.keys[free] = distance << 20 | (dy as u64) << 10 | dx as u64;
                free += 1;
            }
        }
        self.free = free;
        (free > 0).then_some(free)
    }

    /// Ring entry `i` relative to R in xy.
    #[inline]
    fn q(&self, i: usize) -> [i64; 2] {
        [self.q[i][0] as i64, self.q[i][1] as i64]
    }

    fn unmark(&mut self, p: [i64; 2]) {
        let index = ((p[1] - self.y0) * self.width + (p[0] - self.x0)) as usize;
        self.inside[index / 64] &= !(1 << (index % 64));
    }

    /// The point of a packed key, relative to R.
    fn point_of(&self, key: u64) -> [i64; 2] {
        [
            self.x0 + (key & 1023) as i64,
            self.y0 + (key >> 10 & 1023) as i64,
        ]
    }

    /// `F[j]` of the last [`Self::free_points`], relative to R; `None` when
    /// `j` is not below the number of free points.
    pub fn point_at(&mut self, j: usize) -> Option<[i64; 2]> {
        if j >= self.free {
            return None;
        }
        if !self.listed {
            if let Some(p) = self.near_point(j) {
                return Some(p);
            }
            // The list holds as many points as the count said (Pick's
            // theorem); should it ever hold fewer, `j` is out of range
            // rather than a selection in too short a list.
            self.list();
            if j >= self.free {
                return None;
            }
        }
        let keys = &mut self.keys[..self.free];
        // The nearest point is the most common rank by far.
        let key = if j == 0 {
            keys.iter().copied().min()?
        } else {
            select_nth(keys, j)
        };
        Some(self.point_of(key))
    }

    /// The rank of point `p` (relative to R) among the last free points
    /// (encoder): `None` when `p` is not free.
    pub fn rank_of(&mut self, p: [i64; 2]) -> Option<usize> {
        if self.free == 0 {
            return None;
        }
        if !self.listed {
            if let Some(rank) = self.near_rank(p) {
                return rank;
            }
            self.list();
        }
        let keys = &self.keys[..self.free];
        let key = keys.iter().copied().find(|&key| self.point_of(key) == p)?;
        Some(keys.iter().filter(|&&other| other < key).count())
    }

    /// The number of free points of a *simple* fan, without listing them:
    /// no ghost, every wedge counter-clockwise with an area, and the ring
    /// around R once (one wedge crosses the ray from R along +x; a wedge
    /// `(a, b)` spans less than half a turn, so `a_y < 0 ≤ b_y` means it
    /// crosses that ray). Then the wedges tile the ring's polygon, a simple
    /// polygon around R with the ring entries as vertices, and Pick's
    /// theorem counts its lattice points, boundary included: `A + B/2 + 1`
    /// for area A and B lattice points on the boundary. R and the k
    /// entries are among them, not free. `None` for any other fan (most
    /// terrain fans are simple; the others are listed).
    fn count_simple(&mut self) -> Option<usize> {
        let k = self.k;
        let (mut twice_area, mut boundary, mut crossings) = (0i64, 0i64, 0);
        let (mut turn, mut upper) = (0, 0);
        // The wedges from the last entry's on, each entry loaded once and
        // carried to the next wedge (loading both ends of every wedge, and
        // wrapping the second, cost about 8 instructions a wedge more).
        let last = k.checked_sub(1)?;
        let (mut a, mut a_real) = (self.q(last), self.real[last]);
        for i in 0..k {
            let (b, b_real) = (self.q(i), self.real[i]);
            if !(a_real && b_real) {
                return None;
            }
            let area = orient([0, 0], a, b);
            if area <= 0 {
                return None;
            }
            twice_area += area;
            boundary += gcd((b[0] - a[0]).unsigned_abs(), (b[1] - a[1]).unsigned_abs()) as i64;
            let crossing = a[1] < 0 && b[1] >= 0;
            crossings += i32::from(crossing);
            turn = if crossing { i } else { turn };
            upper += usize::from(!lower_half(b));
            (a, a_real) = (b, b_real);
        }
        if crossings != 1 {
            return None;
        }
        (self.turn, self.upper) = (turn, upper);
        // 2A + B is even (Pick); R and the entries are inside, so the
        // difference is not negative.
        let points = (twice_area + boundary) / 2 + 1;
        Some((points - 1 - k as i64) as usize)
    }

    /// `F[j]` of a simple fan not listed, from the points near the
    /// centroid `c`: those of the 3 × 3 points around `round(c)` whose
    /// distance to `c` is below 1.5 (`4 |n p − S|² < 9 n²`), every point
    /// that near (a point outside the window is at least 1.5 away from `c`
    /// on an axis), taken in key order. `None` when fewer than `j + 1` of
    /// them are free: then the fan is listed.
    fn near_point(&self, j: usize) -> Option<[i64; 2]> {
        // Past rank 1 the corners hold the point in about half the fans
        // (measured on terrain: rank 2 in 59 %, rank 3 in 8 %, rank 4 in
        // none), and the window then tests them again.
        if let Some(p) = (j < 2).then(|| self.corner_point(j)).flatten() {
            return Some(p);
        }
        let mut window = self.window();
        let mut found = 0;
        loop {
            let mut slot = 0;
            for (i, &key) in window.iter().enumerate() {
                if key < window[slot] {
                    slot = i;
                }
            }
            let key = window[slot];
            if key == u64::MAX {
                return None;
            }
            window[slot] = u64::MAX;
            let p = self.point_of(key);
            if self.is_free(p) {
                if found == j {
                    return Some(p);
                }
                found += 1;
            }
        }
    }

    /// `F[j]` when it is one of the four corners around the centroid
    /// ([`Self::centroid_cell`]) and provably so; `None` leaves it to the
    /// window. On terrain the nearest point is often R itself (not free)
    /// and rank 0 then the next corner.
    #[inline]
    fn corner_point(&self, j: usize) -> Option<[i64; 2]> {
        let (low, bound) = self.centroid_cell();
        let mut corners = self.corner_keys(low);
        // A sorting network: five compare-exchanges.
        for (a, b) in [(0, 1), (2, 3), (0, 2), (1, 3), (1, 2)] {
            let (lo, hi) = (corners[a].min(corners[b]), corners[a].max(corners[b]));
            (corners[a], corners[b]) = (lo, hi);
        }
        let mut found = 0;
        for key in corners {
            if key == u64::MAX {
                return None;
            }
            let p = self.point_of(key);
            if self.is_free(p) {
                if found == j {
                    return (distance_of(key) < bound).then_some(p);
                }
                found += 1;
            }
        }
        None
    }

    /// The unit square that holds the centroid `c`, by its low corner,
    /// and `b²` in the keys' units: every lattice point but the square's
    /// four corners lies at least `b` from `c` on one axis, `b` the least
    /// distance from `c` to the columns and rows just outside the square.
    /// So a key whose distance is below `b²` is a corner's, and only
    /// corners come before it in key order (none ties with it).
    #[inline(always)]
    fn centroid_cell(&self) -> ([i64; 2], i64) {
        let n = self.n;
        let (fx, fy) = (self.sx.div_euclid(n), self.sy.div_euclid(n));
        // In units of 1/n, as the keys' distances: the centroid sits `rx`
        // past column fx, so the columns fx − 1 and fx + 2 lie n + rx and
        // 2n − rx from it; rows likewise.
        let (rx, ry) = (self.sx - fx * n, self.sy - fy * n);
        let b = (n + rx).min(2 * n - rx).min(n + ry).min(2 * n - ry);
        ([fx, fy], b * b)
    }

    /// The keys of the four corners of the square at `low`
    /// ([`Self::centroid_cell`]); `u64::MAX` for those outside the
    /// bounding box or the window.
    #[inline(always)]
    fn corner_keys(&self, low: [i64; 2]) -> [u64; 4] {
        core::array::from_fn(|i| {
            let p = [low[0] + (i & 1) as i64, low[1] + (i >> 1) as i64];
            self.key_near(p).unwrap_or(u64::MAX)
        })
    }

    /// [`Self::rank_of`] for a simple fan not listed: `Some(rank)` when
    /// `p` is near the centroid (see [`Self::near_point`]), `None` when
    /// the fan must be listed.
    fn near_rank(&self, p: [i64; 2]) -> Option<Option<usize>> {
        let key = self.key_near(p)?;
        if !self.is_free(p) {
            return Some(None);
        }
        let nearer_free = |keys: &[u64]| {
            keys.iter()
                .filter(|&&other| other < key && self.is_free(self.point_of(other)))
                .count()
        };
        let (low, bound) = self.centroid_cell();
        let nearer = if distance_of(key) < bound {
            nearer_free(&self.corner_keys(low))
        } else {
            nearer_free(&self.window())
        };
        Some(Some(nearer))
    }

    /// The keys of the 3 × 3 points around the centroid's nearest lattice
    /// point that lie in the bounding box within 1.5 of the centroid;
    /// `u64::MAX` for the others.
    fn window(&self) -> [u64; 9] {
        // round(S / n) per axis: floor((2S + n) / 2n).
        let round = |s: i64| (2 * s + self.n).div_euclid(2 * self.n);
        let (cx, cy) = (round(self.sx), round(self.sy));
        core::array::from_fn(|i| {
            let p = [cx - 1 + (i % 3) as i64, cy - 1 + (i / 3) as i64];
            self.key_near(p).unwrap_or(u64::MAX)
        })
    }

    /// The key of `p` (relative to R) when it lies in the bounding box
    /// within 1.5 of the centroid.
    fn key_near(&self, p: [i64; 2]) -> Option<u64> {
        let (dx, dy) = (p[0] - self.x0, p[1] - self.y0);
        if !(0..self.width).contains(&dx) || !(0..self.height).contains(&dy) {
            return None;
        }
        let (ex, ey) = (self.n * p[0] - self.sx, self.n * p[1] - self.sy);
        let distance = ex * ex + ey * ey;
        (4 * distance < 9 * self.n * self.n)
            .then_some((distance as u64) << 20 | (dy as u64) << 10 | dx as u64)
    }

    /// Whether lattice point `p` (relative to R, in the bounding box) is
    /// free in a *simple* fan ([`Self::count_simple`]): in a wedge, and
    /// neither R nor an entry (SPEC §7.4 `free_points`).
    fn is_free(&self, p: [i64; 2]) -> bool {
        if p == [0, 0] {
            return false;
        }
        // The wedges of a simple fan are counter-clockwise, each spans less
        // than half a turn, and together they turn once around R: every
        // direction lies in the cone of some wedge (a, b), `orient(0, a, p)
        // ≥ 0 ≥ orient(0, b, p)`, and p is in the fan exactly when it is in
        // that wedge, `orient(a, b, p) ≥ 0`. Two cones share only a ray
        // (through an entry), whose points both wedges hold alike (up to
        // the entry), so any cone that holds p will do.
        let start = self.cone(p);
        // An entry's angle is p's only when the entry is p, and then that
        // entry starts p's cone; no other entry can be p.
        let a = self.turned(start);
        (a != p) & (orient(a, self.turned(start + 1), p) >= 0)
    }

    /// A wedge of the last fan, *simple*, whose cone holds the direction
    /// of `p` (relative to R, coordinates below 2^31): its first entry, as
    /// counted from `turn` ([`Self::turned`]).
    ///
    /// From `turn` on, the entries' angles (counter-clockwise from +x, in
    /// [0, 2π)) strictly increase: the wedge that crosses the ray ends at
    /// `turn`, and the others turn less than once around R in all. So a
    /// cone that holds p starts at the last entry whose angle is not past
    /// p's; when there is none, at the last entry (p then lies in the
    /// wedge that crosses +x). Only the entries of p's half-turn need be
    /// searched (when none of them comes first, the last entry of the
    /// half-turn before does), and there angles differ by less than half a
    /// turn, so `orient(0, q, p) ≥ 0` says whether q's is not past p's: a
    /// binary search, branch-free (which cone is data). A walk of all k
    /// entries, one orientation each, cost about 21 instructions an entry
    /// under callgrind; this costs about 10 a halving.
    fn cone(&self, p: [i64; 2]) -> usize {
        let k = self.k;
        let (from, len) = if lower_half(p) {
            (self.upper, k.saturating_sub(self.upper))
        } else {
            (0, self.upper)
        };
        let not_past = |t: usize| {
            let q = self.turned(t);
            q[0] * p[1] - q[1] * p[0] >= 0
        };
        // The first entry of the range past p: the cone starts before it.
        let (mut base, mut len) = (from, len);
        while len > 1 {
            let half = len / 2;
            base = if not_past(base + half) {
                base + half
            } else {
                base
            };
            len -= half;
        }
        let past = base + usize::from(len == 1 && not_past(base));
        if past == 0 { k - 1 } else { past - 1 }
    }

    /// Entry `t` from `turn` on in ring order (`t` ≤ k), relative to R, in
    /// a simple fan.
    #[inline]
    fn turned(&self, t: usize) -> [i64; 2] {
        self.q(wrap_once(self.turn + t, self.k))
    }

    /// Prepares the tests of SPEC §7.4 `pair` for the new edge `e`: which
    /// entries may be wing x and wing y, which wedges keep their
    /// orientation under `a`, and how many wedges from each one on keep it
    /// under `b`. `O(k)` orientation tests, so that a pair then costs a few
    /// comparisons.
    fn prepare(&mut self, eligible: &WingCandidates, e: &NewEdge) {
        let k = self.k;
        let mut all_ok = true;
        // Non-short-circuit `&` and `|` throughout: the flags are data
        // (a branch on each mispredicted often).
        for i in 0..k {
            let (real, q) = (self.real[i], self.q(i));
            let j = if i + 1 == k { 0 } else { i + 1 };
            // orient(b, a, q) is −orient(a, b, q): one side test.
            let side = orient(e.a, e.b, q);
            let eligible = eligible.contains(i);
            self.x_ok[i] = eligible & (!real | (side > 0));
            self.y_ok[i] = eligible & (!real | (side < 0));
            // A wedge touching the ghost is virtual: it always keeps it.
            let virtual_wedge = !(real & self.real[j]);
            let next = self.q(j);
            let a_ok = virtual_wedge | (orient(e.a, q, next) > 0);
            let b_ok = virtual_wedge | (orient(e.b, q, next) > 0);
            (self.a_ok[i], self.b_ok[i]) = (a_ok, b_ok);
            all_ok &= a_ok & b_ok;
        }
        self.all_ok = all_ok;
        if all_ok {
            // `ys_of` reads no runs then.
            return;
        }
        // run_b[t]: how many wedges from t on keep their orientation under
        // b, capped at k: backwards twice around the ring (the first pass
        // carries the run across the ring's end). Branch-free and without a
        // `%`: a division per entry and a mispredicted branch per wedge had
        // cost more than the orientations above.
        let mut run = 0usize;
        for _ in 0..2 {
            for t in (0..k).rev() {
                run = (run + 1).min(k) * usize::from(self.b_ok[t]);
                self.run_b[t] = run as u8;
            }
        }
    }

    /// The wings y that pair with `x` (SPEC §7.4 `pair`) after
    /// [`Self::prepare`], in ring order from x, into `self.choices`
    /// (none when `any` asks only whether there is one); returns their
    /// number, or 1 for `any` when there is one.
    fn ys_of(&mut self, midpoint: bool, x: usize, any: bool) -> usize {
        let k = self.k;
        if !self.x_ok[x] {
            return 0;
        }
        let mut count = 0;
        if self.all_ok {
            // Every arc keeps its wedges: any y on its side pairs (after x
            // under kind 1). The list's order is `before`'s, not this one.
            let from = if midpoint { x + 1 } else { 0 };
            for y in from..k {
                if y != x && self.y_ok[y] {
                    if any {
                        return 1;
                    }
                    self.choices[count] = y as u8;
                    count += 1;
                }
            }
            return count;
        }
        // A's arc, wedges x .. y − 1, grows wedge by wedge; once a wedge
        // fails under a, every longer arc fails too.
        let mut y = x;
        for _ in 1..k {
            if !self.a_ok[y] {
                break;
            }
            y = if y + 1 == k { 0 } else { y + 1 };
            if midpoint && y < x {
                break;
            }
            // B's arc: wedges y .. x − 1, (x − y) mod k of them.
            let b_arc = if x > y { x - y } else { x + k - y };
            if self.y_ok[y] && self.run_b[y] as usize >= b_arc {
                if any {
                    return 1;
                }
                self.choices[count] = y as u8;
                count += 1;
            }
        }
        count
    }

    /// Whether choice `u` comes before choice `w` (`before(a, b)` of SPEC
    /// §7.4, with the current list's edge): the ghost last, real entries
    /// widest angle on the segment `a b` first, then by ring position.
    #[inline]
    fn before(&self, u: usize, w: usize) -> bool {
        let [a, b] = self.list_edge;
        self.before_seen(u, angle_of(a, b, self.q(u)), w, angle_of(a, b, self.q(w)))
    }

    /// [`Self::before`] with the angles of `u` and `w` given.
    #[inline]
    fn before_seen(&self, u: usize, angle_u: [i64; 2], w: usize, angle_w: [i64; 2]) -> bool {
        match self.seen_order(u, angle_u, w, angle_w) {
            Ordering::Equal => self.tie_before(self.ties, u, w),
            order => order.is_lt(),
        }
    }

    /// `before` of SPEC §7.4 up to the tie rule: the ghost last, real
    /// entries widest angle first, two ghosts by ring position; `Equal`
    /// for real entries seen under the same angle, which
    /// [`Self::tie_before`] orders.
    #[inline]
    fn seen_order(&self, u: usize, angle_u: [i64; 2], w: usize, angle_w: [i64; 2]) -> Ordering {
        match (self.real[u], self.real[w]) {
            (true, false) => Ordering::Less,
            (false, true) => Ordering::Greater,
            (false, false) => u.cmp(&w),
            (true, true) => wider(angle_u, angle_w),
        }
    }

    /// Whether real entry `u` comes before real entry `w` seen under the
    /// same angle, under the tie rule `ties`: fewer new edges along the
    /// disfavoured diagonal first, then by ring position.
    #[inline]
    fn tie_before(&self, ties: Ties, u: usize, w: usize) -> bool {
        (self.off_diagonal_edges(ties, u), u) < (self.off_diagonal_edges(ties, w), w)
    }

    /// How many of the new edges from the list's edge ends to real entry
    /// `i` run along the diagonal the tie rule `ties` disfavours (SPEC
    /// §7.4 `off(i)`; always 0 under `ring`).
    #[inline]
    fn off_diagonal_edges(&self, ties: Ties, i: usize) -> u8 {
        let q = self.q(i);
        self.list_edge
            .iter()
            .map(|e| u8::from(ties.off_diagonal([q[0] - e[0], q[1] - e[1]])))
            .sum()
    }

    /// Sets the tie-break of the wing choices (the level's record order,
    /// SPEC §5.1): [`Self::choice`] and [`Self::rank_of_choice`] follow it.
    #[inline]
    pub fn set_ties(&mut self, ties: Ties) {
        self.ties = ties;
    }

    /// Collects the choices of wing x for the new edge `e` (SPEC §7.4
    /// `xs`, in ring order) and returns their number; [`Self::choice`]
    /// then names them in their order.
    pub fn order_xs(&mut self, eligible: &WingCandidates, e: &NewEdge) -> usize {
        self.prepare(eligible, e);
        let k = self.k;
        let mut n = 0;
        if self.all_ok {
            // x pairs when some y ≠ x is on the other side (after x under
            // kind 1): the y's are counted once, not searched per x.
            let ys = self.y_ok[..k].iter().filter(|&&ok| ok).count();
            let last_y = self.y_ok[..k].iter().rposition(|&ok| ok);
            for x in 0..k {
                let paired = if e.midpoint {
                    last_y.is_some_and(|y| y > x)
                } else {
                    ys > usize::from(self.y_ok[x])
                };
                if self.x_ok[x] && paired {
                    self.choices[n] = x as u8;
                    n += 1;
                }
            }
        } else {
            for x in 0..k {
                if self.ys_of(e.midpoint, x, true) > 0 {
                    self.choices[n] = x as u8;
                    n += 1;
                }
            }
        }
        self.list_edge = [e.a, e.b];
        self.sorted = false;
        n
    }

    /// Collects the choices of wing y that pair with `x` (SPEC §7.4 `ys`),
    /// after [`Self::order_xs`] for the same edge, and returns their
    /// number.
    pub fn order_ys(&mut self, e: &NewEdge, x: usize) -> usize {
        let n = if x < self.k {
            self.ys_of(e.midpoint, x, false)
        } else {
            0
        };
        self.list_edge = [e.b, e.a];
        self.sorted = false;
        n
    }

    /// The ring position of choice `i` (in the order of SPEC §7.4) of the
    /// last `n` collected.
    pub fn choice(&mut self, n: usize, i: usize) -> Option<usize> {
        if i >= n {
            return None;
        }
        if i == 0 {
            // The first choice, by far the most common: one pass, each
            // choice's angle taken once.
            let [a, b] = self.list_edge;
            let mut best = self.choices[0] as usize;
            let mut best_angle = angle_of(a, b, self.q(best));
            for &c in &self.choices[1..n] {
                let c = c as usize;
                let angle = angle_of(a, b, self.q(c));
                if self.before_seen(c, angle, best, best_angle) {
                    (best, best_angle) = (c, angle);
                }
            }
            return Some(best);
        }
        if !self.sorted {
            // Insertion sort: a handful of choices, and little code (core's
            // sorts would double the decoder's size on a microcontroller).
            for end in 1..n {
                let mut at = end;
                while at > 0
                    && self.before(self.choices[at] as usize, self.choices[at - 1] as usize)
                {
                    self.choices.swap(at, at - 1);
                    at -= 1;
                }
            }
            self.sorted = true;
        }
        Some(self.choices[i] as usize)
    }

    /// The rank of ring position `entry` among the last `n` choices
    /// collected (encoder): how many come before it under the tie rule
    /// set ([`Self::set_ties`]).
    pub fn rank_of_choice(&self, n: usize, entry: usize) -> Option<usize> {
        self.ranks_of_choice(n, entry)
            .map(|ranks| ranks[self.ties as usize])
    }

    /// [`Self::rank_of_choice`] under every tie rule at once, by
    /// [`Ties::ALL`] index (encoder): the rules differ only between choices
    /// of equal angle, so each choice's angle is compared once for all
    /// three (an encoder writes a small level's wings under each rule).
    pub fn ranks_of_choice(&self, n: usize, entry: usize) -> Option<[usize; 3]> {
        let list = &self.choices[..n];
        if !list.iter().any(|&c| c as usize == entry) {
            return None;
        }
        // Entry's angle once, not once per comparison.
        let [a, b] = self.list_edge;
        let seen = angle_of(a, b, self.q(entry));
        let mut ranks = [0usize; 3];
        for c in list.iter().map(|&c| c as usize).filter(|&c| c != entry) {
            match self.seen_order(c, angle_of(a, b, self.q(c)), entry, seen) {
                Ordering::Less => ranks.iter_mut().for_each(|r| *r += 1),
                Ordering::Greater => {}
                // Seen under the same angle: the rules differ here only.
                Ordering::Equal => {
                    for (t, rank) in Ties::ALL.into_iter().zip(&mut ranks) {
                        *rank += usize::from(self.tie_before(t, c, entry));
                    }
                }
            }
        }
        Some(ranks)
    }
}

/// The `j`-th smallest of `keys` (distinct, `j < keys.len()`), by
/// quickselect on the middle element: `O(n)` on average, and at most
/// [`LIST_CAP`]² steps, with little code (core's selection would add
/// kilobytes to a microcontroller's decoder).
fn select_nth(keys: &mut [u64], j: usize) -> u64 {
    let (mut lo, mut hi) = (0, keys.len());
    while hi - lo > 1 {
        let mid = lo + (hi - lo) / 2;
        keys.swap(mid, hi - 1);
        let pivot = keys[hi - 1];
        let mut store = lo;
        for i in lo..hi - 1 {
            if keys[i] < pivot {
                keys.swap(i, store);
                store += 1;
            }
        }
        keys.swap(store, hi - 1);
        match j.cmp(&store) {
            Ordering::Equal => return keys[store],
            Ordering::Less => hi = store,
            Ordering::Greater => lo = store + 1,
        }
    }
    keys[lo]
}

/// The wings' ring positions `(o, d)` and the placement code of a record
/// read positions first whose new vertex owns the arc from `x` to `y`
/// (SPEC §7.4): `a` owns arc 1 when `x < y`.
#[inline]
pub fn wings_and_code(x: usize, y: usize, midpoint: bool) -> (usize, usize, u8) {
    let code = if midpoint {
        2
    } else if x < y {
        1
    } else {
        0
    };
    if x < y {
        (x, y - x, code)
    } else {
        (y, x - y, code)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A hexagon-like ring of lattice points around R at (5, 5).
    fn hexagon() -> ([[u32; 3]; 7], Ring) {
        let positions = [
            [5, 5, 0],
            [8, 5, 0],
            [7, 8, 0],
            [3, 8, 0],
            [2, 5, 0],
            [3, 2, 0],
            [7, 2, 0],
        ];
        let ring = Ring::of_vertices(&[1, 2, 3, 4, 5, 6]);
        (positions, ring)
    }

    #[test]
    fn free_points_are_the_fans_lattice_points_nearest_the_centroid_first() {
        let (positions, ring) = hexagon();
        let mut pf = PositionsFirst::default();
        let f = pf.free_points(&positions, positions[0], &ring).unwrap();
        let mut points = [[0i64; 2]; LIST_CAP];
        for (j, p) in points[..f].iter_mut().enumerate() {
            *p = pf.point_at(j).unwrap();
        }
        // Every point inside the hexagon, but R and the entries.
        let inside = |p: [i64; 2]| {
            let q: [[i64; 2]; 6] = core::array::from_fn(|i| {
                [
                    positions[i + 1][0] as i64 - 5,
                    positions[i + 1][1] as i64 - 5,
                ]
            });
            (0..6).any(|i| {
                let (a, b) = (q[i], q[(i + 1) % 6]);
                let s = [orient([0, 0], a, p), orient(a, b, p), orient(b, [0, 0], p)];
                s.iter().all(|&s| s >= 0)
            })
        };
        let mut expected = 0;
        for y in -3..=3 {
            for x in -3..=3 {
                let is_entry = (1..7)
                    .any(|i| [positions[i][0] as i64 - 5, positions[i][1] as i64 - 5] == [x, y]);
                if [x, y] != [0, 0] && !is_entry && inside([x, y]) {
                    expected += 1;
                    assert!(points[..f].contains(&[x, y]), "{x} {y}");
                }
            }
        }
        assert_eq!(f, expected);
        // The centroid is (0, 0) relative to R: distances never fall.
        let d = |p: [i64; 2]| p[0] * p[0] + p[1] * p[1];
        for pair in points[..f].windows(2) {
            assert!(d(pair[0]) <= d(pair[1]));
        }
        for (j, p) in points[..f].iter().enumerate() {
            assert_eq!(pf.rank_of(*p), Some(j));
        }
    }

    #[test]
    fn a_fan_past_the_cap_escapes() {
        let positions = [[0, 0, 0], [100, 0, 0], [0, 100, 0], [0, 0, 0]];
        let ring = Ring::of_vertices(&[1, 2, NONE]);
        let mut pf = PositionsFirst::default();
        assert_eq!(pf.free_points(&positions, [50, 50, 0], &ring), None);
    }

    #[test]
    fn wings_are_the_pairs_that_keep_the_triangles_up() {
        let (positions, ring) = hexagon();
        let mut pf = PositionsFirst::default();
        pf.free_points(&positions, positions[0], &ring).unwrap();
        let all = WingCandidates::all(6);
        // The new vertex one step right of R: it owns the arc around entry
        // 0 (8, 5), from entry 5 (7, 2) to entry 1 (7, 8).
        let e = NewEdge {
            a: [1, 0],
            b: [0, 0],
            midpoint: false,
        };
        let n = pf.order_xs(&all, &e);
        let rank = pf.rank_of_choice(n, 5).expect("x = 5 is a choice");
        assert_eq!(pf.choice(n, rank), Some(5));
        let n = pf.order_ys(&e, 5);
        let rank = pf.rank_of_choice(n, 1).expect("(5, 1) is a pair");
        assert_eq!(pf.choice(n, rank), Some(1));
        assert_eq!(wings_and_code(5, 1, false), (1, 4, 0));
        // A pair that would fold a triangle is not one.
        assert_eq!(pf.rank_of_choice(n, 3), None);
    }

    #[test]
    fn a_midpoint_split_whose_p_lands_on_r_still_pairs() {
        // SPEC §7.4: under kind 1 nothing excludes A (P) on R's x and y;
        // the record reads as any other when a pair holds. Ring of the
        // 3-step square around R, N = (1, 0), offset t = 1: A = (0, 0).
        let q: [[i64; 2]; 8] = [
            [3, 0],
            [3, 3],
            [0, 3],
            [-3, 3],
            [-3, 0],
            [-3, -3],
            [0, -3],
            [3, -3],
        ];
        let mut positions = [[10u32, 10, 0]; 9];
        for (i, p) in q.iter().enumerate() {
            positions[i + 1] = [(10 + p[0]) as u32, (10 + p[1]) as u32, 0];
        }
        let ring = Ring::of_vertices(&[1, 2, 3, 4, 5, 6, 7, 8]);
        let mut pf = PositionsFirst::default();
        pf.free_points(&positions, positions[0], &ring).unwrap();
        let e = NewEdge {
            a: [0, 0],
            b: [1, 0],
            midpoint: true,
        };
        let n = pf.order_xs(&WingCandidates::all(8), &e);
        let xs: [Option<usize>; 3] = core::array::from_fn(|i| pf.choice(n, i));
        assert_eq!((n, xs), (3, [Some(2), Some(1), Some(3)]));
        let n = pf.order_ys(&e, 2);
        let ys: [Option<usize>; 3] = core::array::from_fn(|i| pf.choice(n, i));
        assert_eq!((n, ys), (3, [Some(6), Some(7), Some(5)]));
    }

    #[test]
    fn record_order_byte_holds_the_order_and_the_ties() {
        // SPEC §5.1 byte 11: 0 wings-first, 1 to 3 positions first under
        // the tie rules ring, rising, falling (3.8); 4 and above reserved.
        for b in 0..=255u8 {
            let order = RecordOrder::from_byte(b);
            assert_eq!(order.is_some(), b <= 3, "{b}");
            if let Some(order) = order {
                let ties = Ties::from_record_byte(b).unwrap_or_default();
                assert_eq!(order.to_byte(ties), b);
                assert_eq!(order == RecordOrder::PositionsFirst, b >= 1);
            }
        }
        assert_eq!(RecordOrder::WingsFirst.to_byte(Ties::Falling), 0);
        assert_eq!(
            RecordOrder::PositionsFirst.name_with(Ties::Rising),
            "positions-first-rising"
        );
        // The disfavoured diagonals.
        assert!(Ties::Rising.off_diagonal([2, -2]) && !Ties::Rising.off_diagonal([2, 2]));
        assert!(Ties::Falling.off_diagonal([-1, -1]) && !Ties::Falling.off_diagonal([1, -1]));
        assert!(!Ties::Rising.off_diagonal([0, 0]) && !Ties::Ring.off_diagonal([1, -1]));
    }

    #[test]
    fn gcd_agrees_with_euclid() {
        let euclid = |mut a: u64, mut b: u64| {
            while b != 0 {
                (a, b) = (b, a % b);
            }
            a
        };
        let values = (0..40).chain([63, 64, 96, 1000, 1023, 1024, 4096, 12_345, u32::MAX as u64]);
        for a in values.clone() {
            for b in values.clone() {
                assert_eq!(gcd(a, b), euclid(a, b), "gcd({a}, {b})");
            }
        }
    }

    #[test]
    fn select_nth_agrees_with_a_sort() {
        let mut state = 12345u64;
        for n in 1..40 {
            let mut keys = [0u64; 40];
            for k in keys[..n].iter_mut() {
                state = state
                    .wrapping_mul(6364136223846793005)
                    .wrapping_add(1442695040888963407);
                *k = state >> 40;
            }
            let mut sorted = keys;
            sorted[..n].sort_unstable();
            for (j, &want) in sorted[..n].iter().enumerate() {
                let mut work = keys;
                assert_eq!(select_nth(&mut work[..n], j), want, "{n} {j}");
            }
        }
    }

    #[test]
    fn incircle_orders_by_the_angle_seen() {
        let (a, b) = ([0, 0], [4, 0]);
        // (2, 1) sees a b under a wider angle than (2, 3).
        assert!(incircle(a, b, [2, 3], [2, 1]) > 0);
        assert!(incircle(a, b, [2, 1], [2, 3]) < 0);
        // Cocircular: (0, 4) and (4, 4) both see the segment at 45°.
        assert_eq!(incircle(a, b, [0, 4], [4, 4]), 0);
    }

    /// A ring worked by hand and by the clean-room Python decoder
    /// (conformance/python): the free points in order, and the wing
    /// choices of three new edges.
    #[test]
    fn a_small_hexagon_gives_the_python_decoders_lists() {
        let positions = [
            [5, 5, 0],
            [7, 5, 0],
            [6, 7, 0],
            [4, 7, 0],
            [3, 5, 0],
            [4, 3, 0],
            [6, 3, 0],
        ];
        let ring = Ring::of_vertices(&[1, 2, 3, 4, 5, 6]);
        let mut pf = PositionsFirst::default();
        let f = pf.free_points(&positions, positions[0], &ring).unwrap();
        let expected = [
            [0, -1],
            [-1, 0],
            [1, 0],
            [0, 1],
            [-1, -1],
            [1, -1],
            [-1, 1],
            [1, 1],
            [0, -2],
            [0, 2],
        ];
        assert_eq!(f, expected.len());
        for (j, p) in expected.iter().enumerate() {
            assert_eq!(pf.point_at(j), Some(*p), "F[{j}]");
        }
        assert_eq!(rank_context(f), 7);
        let all = WingCandidates::all(6);
        let lists = |pf: &mut PositionsFirst, e: NewEdge, x: usize| {
            let n = pf.order_xs(&all, &e);
            let xs: [Option<usize>; 4] = core::array::from_fn(|i| pf.choice(n, i));
            let n = pf.order_ys(&e, x);
            let ys: [Option<usize>; 4] = core::array::from_fn(|i| pf.choice(n, i));
            (xs, ys)
        };
        let kind0 = |n: [i64; 2]| NewEdge {
            a: n,
            b: [0, 0],
            midpoint: false,
        };
        let (xs, ys) = lists(&mut pf, kind0([0, -1]), 3);
        assert_eq!(xs, [Some(3), Some(4), Some(2), None]);
        assert_eq!(ys, [Some(0), Some(5), Some(1), None]);
        let (xs, ys) = lists(&mut pf, kind0([-1, 0]), 2);
        assert_eq!(xs, [Some(2), Some(1), None, None]);
        assert_eq!(ys, [Some(4), Some(5), None, None]);
        let mid = NewEdge {
            a: [0, 1],
            b: [0, -1],
            midpoint: true,
        };
        let (xs, ys) = lists(&mut pf, mid, 0);
        assert_eq!(xs, [Some(0), Some(1), None, None]);
        assert_eq!(ys, [Some(3), Some(2), Some(4), None]);
        // With the ghost: ring [⊥, (7, 5), (6, 7), (4, 7), (3, 5)].
        let ring = Ring::of_vertices(&[NONE, 1, 2, 3, 4]);
        let f = pf.free_points(&positions, positions[0], &ring).unwrap();
        let expected = [[0, 1], [-1, 1], [1, 1], [0, 2], [-1, 0], [1, 0]];
        assert_eq!(f, expected.len());
        for (j, p) in expected.iter().enumerate() {
            assert_eq!(pf.point_at(j), Some(*p), "F[{j}] with the ghost");
        }
        let all = WingCandidates::all(5);
        let n = pf.order_xs(&all, &kind0([0, 1]));
        let xs: [Option<usize>; 4] = core::array::from_fn(|i| pf.choice(n, i));
        assert_eq!(xs, [Some(1), Some(2), Some(0), None]);
    }
}
