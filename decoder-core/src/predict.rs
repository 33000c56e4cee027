//! Position prediction for a split (SPEC §7.4).
//!
//! Once the wings are known, so are the ring entries P and C will have as
//! neighbours: P's arc (arc 1) and C's arc (arc 2), which share the wings.
//! Each vector the stream codes (C − R, P − R or the edge C − P in
//! constrained mode; P − R and C − R in optimal mode) is predicted by a fixed
//! linear combination of three means relative to R: of the real wings, of
//! the real interior entries of arc 1 and of those of arc 2. The residual
//! left is then predicted once more, on one axis, from the plane the split
//! spans (the wing edge crossed with the direction from arc 1 to arc 2), as
//! the level's plane policy says. Everything is exact integer arithmetic;
//! the encoder calls the same functions, so both sides agree by construction.

use crate::header::PositionMode;
use crate::limits::plane;
use crate::ring::Ring;

/// A level's plane policy (SPEC §5.1, §7.4): which axis of each residual
/// vector is predicted from the other two and the split's plane.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum PlanePolicy {
    /// No plane prediction: axes read x, y, z in contexts 0, 1, 2.
    #[default]
    Off,
    /// The axis along which the normal is largest; tangent axes in context
    /// 0, the predicted axis in context 1.
    Dominant,
    /// Always this axis (0 x, 1 y, 2 z); contexts by axis.
    Axis(u8),
    /// Format 3.1: no plane; z predicted from the surface of R's fan at the
    /// vector's x and y, read before it (terrain). Contexts by axis.
    Height,
}

impl PlanePolicy {
    /// Every policy, in the order of their bytes.
    pub const ALL: [PlanePolicy; plane::COUNT as usize] = [
        PlanePolicy::Off,
        PlanePolicy::Dominant,
        PlanePolicy::Axis(0),
        PlanePolicy::Axis(1),
        PlanePolicy::Axis(2),
        PlanePolicy::Height,
    ];

    /// The policy of a level header's byte (SPEC §5.1); `None` for the
    /// reserved values 5..=255.
    pub fn from_byte(b: u8) -> Option<PlanePolicy> {
        match b {
            plane::OFF => Some(PlanePolicy::Off),
            plane::DOMINANT => Some(PlanePolicy::Dominant),
            plane::X..=plane::Z => Some(PlanePolicy::Axis(b - plane::X)),
            plane::HEIGHT => Some(PlanePolicy::Height),
            _ => None,
        }
    }

    /// The level header byte of this policy.
    pub fn to_byte(self) -> u8 {
        match self {
            PlanePolicy::Off => plane::OFF,
            PlanePolicy::Dominant => plane::DOMINANT,
            PlanePolicy::Axis(a) => plane::X + a.min(2),
            PlanePolicy::Height => plane::HEIGHT,
        }
    }

    /// Its name on the command line and in reports.
    pub fn name(self) -> &'static str {
        match self {
            PlanePolicy::Off => "off",
            PlanePolicy::Dominant => "dominant",
            PlanePolicy::Axis(0) => "x",
            PlanePolicy::Axis(1) => "y",
            PlanePolicy::Axis(_) => "z",
            PlanePolicy::Height => "height",
        }
    }
}

/// The ring statistics a split's predictions use (SPEC §7.4), per axis,
/// relative to R: floor means of the real wings (`W`), of the real interior
/// entries of arc 1 (`I1`) and of arc 2 (`I2`), 0 for an empty set; the sum
/// `G` of every real ring entry and their number `nG`; and the wing edge
/// `pos[b] − pos[a]` when neither wing is the ghost.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ArcMeans {
    pub wings: [i64; 3],
    pub arc_1: [i64; 3],
    pub arc_2: [i64; 3],
    pub sum: [i64; 3],
    pub count: i64,
    pub wing_edge: Option<[i64; 3]>,
}

/// `ceil(2^48 / n)` for `n` in 1..=255 (0 unused): floor division by a
/// set size as a multiplication, see [`floor_div`].
const RECIPROCALS: [u64; 256] = {
    let mut t = [0u64; 256];
    let mut n = 1;
    while n < 256 {
        t[n] = (1u128 << 48).div_ceil(n as u128) as u64;
        n += 1;
    }
    t
};

/// `floor(s / n)` for `1 <= n <= 255` and `|s| < 2^40`. With
/// `m = ceil(2^48 / n)`, `floor(x m / 2^48) = floor(x / n)` for every
/// `0 <= x < 2^40` (Granlund and Montgomery 1994, Theorem 4.2: `n <= 2^8`),
/// so the division is one multiplication; negative sums are rounded
/// towards minus infinity through `-floor((-s + n - 1) / n)`.
#[inline]
pub fn floor_div(s: i64, n: i64) -> i64 {
    match RECIPROCALS.get(n as usize) {
        Some(&m) if n > 0 && s.unsigned_abs() < 1 << 40 => {
            let q = |x: u64| ((x as u128 * m as u128) >> 48) as i64;
            if s >= 0 {
                q(s as u64)
            } else {
                -q(s.unsigned_abs() + n as u64 - 1)
            }
        }
        _ if n > 0 => s.div_euclid(n),
        _ => 0,
    }
}

/// The statistics of SPEC §7.4 for the split of a vertex at `parent` whose
/// ring is `ring`, with wings at ring positions `offset` and
/// `offset + distance` (`1 <= distance`, `offset + distance < ring.len()`).
#[inline]
pub fn arc_means(
    positions: &[[u32; 3]],
    parent: [u32; 3],
    ring: &Ring,
    offset: usize,
    distance: usize,
) -> ArcMeans {
    let vertices = ring.vertices();
    let b_at = offset + distance;
    if distance == 0 || b_at >= vertices.len() {
        return ArcMeans::default();
    }
    let origin = parent.map(|x| x as i64);
    // Sums relative to R and counts of the real entries of a run of the
    // ring (the ghost, NONE, has no position). Coordinates are below 2^31
    // and a ring has at most 255 entries: every sum stays below 2^39.
    let sum = |entries: &[u32]| -> ([i64; 3], i64) {
        let (mut s, mut n) = ([0i64; 3], 0);
        for &v in entries {
            if let Some(p) = positions.get(v as usize) {
                s[0] += p[0] as i64 - origin[0];
                s[1] += p[1] as i64 - origin[1];
                s[2] += p[2] as i64 - origin[2];
                n += 1;
            }
        }
        (s, n)
    };
    let (arc_1, n_1) = sum(&vertices[offset + 1..b_at]);
    let (after, n_after) = sum(&vertices[b_at + 1..]);
    let (before, n_before) = sum(&vertices[..offset]);
    let arc_2: [i64; 3] = core::array::from_fn(|k| after[k] + before[k]);
    let n_2 = n_after + n_before;
    let (a, n_a) = sum(&vertices[offset..offset + 1]);
    let (b, n_b) = sum(&vertices[b_at..b_at + 1]);
    let wings: [i64; 3] = core::array::from_fn(|k| a[k] + b[k]);
    let n_wings = n_a + n_b;
    let mean = |sum: &[i64; 3], n: i64| -> [i64; 3] {
        match n {
            0 => [0; 3],
            1 => *sum,
            2 => sum.map(|s| s >> 1),
            _ => sum.map(|s| floor_div(s, n)),
        }
    };
    ArcMeans {
        wings: mean(&wings, n_wings),
        arc_1: mean(&arc_1, n_1),
        arc_2: mean(&arc_2, n_2),
        sum: core::array::from_fn(|k| wings[k] + arc_1[k] + arc_2[k]),
        count: n_wings + n_1 + n_2,
        // Both wings real: pos[b] − pos[a] (relative to R on both sides).
        wing_edge: (n_a == 1 && n_b == 1).then(|| core::array::from_fn(|k| b[k] - a[k])),
    }
}

/// Which vector of a split the stream codes (SPEC §7.4).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Target {
    /// P − R: constrained code 1 (R sits on C), optimal mode's first vector.
    P,
    /// C − R: constrained code 0 (R sits on P), optimal mode's second vector.
    C,
    /// The edge C − P: constrained code 2 (R is the floor midpoint).
    Edge,
}

impl Target {
    /// The vector coded after the constrained-mode placement code `code`.
    pub fn of_code(code: u8) -> Option<Target> {
        match code {
            0 => Some(Target::C),
            1 => Some(Target::P),
            2 => Some(Target::Edge),
            _ => None,
        }
    }
}

/// Weights (wings, own arc, other arc) of SPEC §7.4's linear predictor, in
/// sixteenths: constrained mode's P or C, its edge, optimal mode's P or C.
pub const CONSTRAINED_VERTEX_WEIGHTS: [i64; 3] = [1, 7, -2];
pub const CONSTRAINED_EDGE_WEIGHTS: [i64; 3] = [0, 5, -5];
pub const OPTIMAL_WEIGHTS: [i64; 3] = [1, 4, -1];

/// The prediction of `target` (relative to R for P and C, SPEC §7.4):
/// `(w_W m_W + w_own m_own + w_other m_other) >> 4` per axis, where the own
/// arc is arc 1 for P and arc 2 for C and for the edge.
#[inline]
pub fn predict(means: &ArcMeans, mode: PositionMode, target: Target) -> [i64; 3] {
    let weights = match (mode, target) {
        (PositionMode::Constrained, Target::Edge) => CONSTRAINED_EDGE_WEIGHTS,
        (PositionMode::Constrained, _) => CONSTRAINED_VERTEX_WEIGHTS,
        (PositionMode::Optimal, _) => OPTIMAL_WEIGHTS,
    };
    let (own, other) = match target {
        Target::P => (&means.arc_1, &means.arc_2),
        Target::C | Target::Edge => (&means.arc_2, &means.arc_1),
    };
    // Means are below 2^31 in magnitude: the sum is below 2^35.
    core::array::from_fn(|k| {
        (weights[0] * means.wings[k] + weights[1] * own[k] + weights[2] * other[k]) >> 4
    })
}

/// Constrained mode's positions of P and C (SPEC §7.4) from R and the
/// decoded vector `x` of the placement code's target.
#[inline]
pub fn constrained_positions(parent: [u32; 3], code: u8, x: [i64; 3]) -> ([i64; 3], [i64; 3]) {
    let r = parent.map(|v| v as i64);
    match code {
        // R sits on P: x = C - R.
        0 => (r, core::array::from_fn(|k| r[k] + x[k])),
        // R sits on C: x = P - R.
        1 => (core::array::from_fn(|k| r[k] + x[k]), r),
        // R is the floor midpoint P + (e >> 1): x = e = C - P.
        _ => {
            let p: [i64; 3] = core::array::from_fn(|k| r[k] - (x[k] >> 1));
            (p, core::array::from_fn(|k| p[k] + x[k]))
        }
    }
}

/// What a split's vectors are predicted from besides the arc means: the
/// positions, R's position (`parent`) and R's ring (SPEC §7.4).
#[derive(Clone, Copy)]
pub struct SplitFan<'a> {
    pub positions: &'a [[u32; 3]],
    pub parent: [u32; 3],
    pub ring: &'a Ring,
}

impl SplitFan<'_> {
    /// The vector a residual decodes to (SPEC §7.4 `vector`): `prediction +
    /// r` modulo 2^32, with, under the plane policy `height`, the z of the
    /// surface prediction plus `r`'s z where a wedge of R's fan holds the
    /// point. `r` is the residual after the plane's offset ([`Plane::decode`]).
    #[inline]
    pub fn vector(
        &self,
        policy: PlanePolicy,
        target: Target,
        prediction: [i64; 3],
        r: [i64; 3],
    ) -> [i64; 3] {
        let mut x = add_residual(prediction, r);
        if let Some(h) = self.height_under(policy, target, x) {
            x[2] = wrap(h + r[2]);
        }
        x
    }

    /// The residual an encoder codes for the vector `x` (every component
    /// below 2^31 in magnitude), before the plane's offset
    /// ([`Plane::encode`]): the inverse of [`SplitFan::vector`].
    #[inline]
    pub fn residual(
        &self,
        policy: PlanePolicy,
        target: Target,
        prediction: [i64; 3],
        x: [i64; 3],
    ) -> [i64; 3] {
        let mut r = residual(x, prediction);
        if let Some(h) = self.height_under(policy, target, x) {
            r[2] = wrap(x[2] - h);
        }
        r
    }

    /// The height prediction of `x`'s z under `policy`: only under
    /// `height`, and only where a wedge holds the point.
    #[inline]
    fn height_under(&self, policy: PlanePolicy, target: Target, x: [i64; 3]) -> Option<i64> {
        if policy != PlanePolicy::Height {
            return None;
        }
        height_prediction(self.positions, self.parent, self.ring, target, x)
    }
}

/// The height policy's prediction of a vector's z (SPEC §7.4, format 3.1):
/// the z of the surface of R's fan, relative to R, at the vector's end
/// (`Target::P`, `Target::C`: vectors from R), or the difference of the
/// surface's z at C and at P (`Target::Edge`, R the floor midpoint of P
/// and C). `x` holds the decoded x and y of the vector (its z is ignored).
/// `None` when a point lies in no real wedge of the ring: the caller keeps
/// the linear prediction.
#[inline]
pub fn height_prediction(
    positions: &[[u32; 3]],
    parent: [u32; 3],
    ring: &Ring,
    target: Target,
    x: [i64; 3],
) -> Option<i64> {
    match target {
        Target::P | Target::C => surface_height(positions, parent, ring, [x[0], x[1]]),
        Target::Edge => {
            // P = R − (x >> 1), C = P + x (`constrained_positions`).
            let p = [-(x[0] >> 1), -(x[1] >> 1)];
            let c = [p[0] + x[0], p[1] + x[1]];
            let at_c = surface_height(positions, parent, ring, c)?;
            let at_p = surface_height(positions, parent, ring, p)?;
            Some(wrap(at_c - at_p))
        }
    }
}

/// `surface(y)` of SPEC §7.4: the first real wedge `(R, r_i, r_{i+1})` of
/// the ring, in ring order, whose projection on the xy plane holds the
/// point `y` (relative to R) in its cone, and the z of that wedge's plane
/// at `y`, relative to R, rounded (`round`). With `a`, `b` the wedge's
/// entries relative to R and `det = a × b` (xy cross product, not 0), `y`
/// is in the cone when `y × b` and `a × y` are 0 or of the sign of `det`;
/// then `y = s a + t b` with `s = (y × b) / det`, `t = (a × y) / det`.
///
/// Exact in 128 bits: `|a_i|, |b_i| < 2^31`, `|y_i| < 2^32`, so the cross
/// products are below `2^64`, `|det| < 2^63` and the numerator below
/// `2^96`. The z is returned modulo 2^32 (as [`wrap`] gives it): the
/// vector's z wraps modulo 2^32 anyway.
pub fn surface_height(
    positions: &[[u32; 3]],
    parent: [u32; 3],
    ring: &Ring,
    y: [i64; 2],
) -> Option<i64> {
    // With |y_i| <= 2^31 every cross product with an entry (|e_i| < 2^31)
    // is below 2^63: 64-bit arithmetic, the common case; 128 bits beyond.
    if y.iter().all(|c| c.unsigned_abs() <= 1 << 31) {
        surface_search(positions, parent, ring, |e| e[0] * y[1] - e[1] * y[0])
    } else {
        let (y0, y1) = (y[0] as i128, y[1] as i128);
        surface_search(positions, parent, ring, |e| {
            e[0] as i128 * y1 - e[1] as i128 * y0
        })
    }
}

/// The wedge search of [`surface_height`], with `cross(e)` = `e × y` (xy)
/// in a type wide enough for it: wedge i's `t` is `r_i × y` and its `s`,
/// `y × r_{i+1}`, is minus the next entry's, so one product per entry.
#[inline(always)]
fn surface_search<T>(
    positions: &[[u32; 3]],
    parent: [u32; 3],
    ring: &Ring,
    cross: impl Fn([i64; 3]) -> T,
) -> Option<i64>
where
    T: Copy + Default + PartialOrd + core::ops::Neg<Output = T> + Into<i128>,
{
    let vertices = ring.vertices();
    let k = vertices.len();
    let origin = parent.map(|x| x as i64);
    // Entries relative to R (|x| < 2^31); the ghost has no position.
    let with_cross = |v: u32| -> Option<([i64; 3], T)> {
        let p = positions.get(v as usize)?;
        let e = [
            p[0] as i64 - origin[0],
            p[1] as i64 - origin[1],
            p[2] as i64 - origin[2],
        ];
        Some((e, cross(e)))
    };
    let zero = T::default();
    let mut a = with_cross(*vertices.first()?);
    for i in 0..k {
        let b = with_cross(vertices[if i + 1 == k { 0 } else { i + 1 }]);
        if let (Some((a, t)), Some((b, minus_s))) = (a, b) {
            // Products of two values below 2^31: exact in 64 bits.
            let det = a[0] * b[1] - a[1] * b[0];
            let s = -minus_s;
            let inside = if det > 0 {
                s >= zero && t >= zero
            } else {
                det < 0 && s <= zero && t <= zero
            };
            if inside {
                let z = s.into() * a[2] as i128 + t.into() * b[2] as i128;
                // Only its value modulo 2^32 matters (the z adds wrap).
                return Some(round_div_wide(z, det as i128) as i32 as i64);
            }
        }
        a = b;
    }
    None
}

/// `round(p / q)` of SPEC §7.4 in 128 bits, for `q != 0` and `|p| < 2^126`.
#[inline]
fn round_div_wide(p: i128, q: i128) -> i128 {
    let (p, q) = if q < 0 { (-p, -q) } else { (p, q) };
    let (x, d) = (2 * p + q, 2 * q);
    // A 64-bit division where it fits (small grids, always on terrain):
    // the 128-bit one is a library call.
    match (i64::try_from(x), i64::try_from(d)) {
        (Ok(x), Ok(d)) => x.div_euclid(d) as i128,
        #[cfg(not(target_arch = "arm"))]
        _ => x.div_euclid(d),
        // 32-bit Arm has no 128-bit division routine: LLVM expands
        // `div_euclid` inline (about 1 KB of thumbv7em `.text`); the
        // shift-and-subtract loop is the same floor division in 720 bytes
        // less. The host keeps the library call (`__divti3`).
        #[cfg(target_arch = "arm")]
        _ => floor_div_positive(x, d),
    }
}

/// `floor(x / d)` for `d > 0` (so `x.div_euclid(d)`), by shift and
/// subtract: the 128-bit division of [`round_div_wide`] on 32-bit Arm.
/// For `x < 0`, `floor(x / d) = !((!x) / d)` (`!y = -y - 1`).
#[cfg(any(target_arch = "arm", test))]
fn floor_div_positive(x: i128, d: i128) -> i128 {
    let negative = x < 0;
    let n = if negative { !x } else { x } as u128;
    let d = d as u128;
    let (mut q, mut r) = (0u128, 0u128);
    for i in (0..u128::BITS - n.leading_zeros()).rev() {
        // `r < d`, so a bit shifted out of `r` means `r > d`.
        let carry = r >> 127 != 0;
        r = (r << 1) | ((n >> i) & 1);
        q <<= 1;
        if carry || r >= d {
            r = r.wrapping_sub(d);
            q |= 1;
        }
    }
    if negative { !(q as i128) } else { q as i128 }
}

/// The plane prediction of one split (SPEC §7.4): the shifted normal and
/// the predicted axis, or nothing under the policy `off`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Plane {
    pub policy: PlanePolicy,
    /// `n`, at most [`plane::NORMAL_BITS`] significant bits per component.
    pub normal: [i64; 3],
    /// The predicted axis j; `None` under the policy `off`.
    pub axis: Option<usize>,
    order: [usize; 3],
    contexts: [u8; 3],
}

impl Plane {
    /// The plane of a split with statistics `means` under `policy`.
    #[inline]
    pub fn new(policy: PlanePolicy, means: &ArcMeans) -> Plane {
        match policy {
            PlanePolicy::Off | PlanePolicy::Height => Plane::with_normal(policy, [0; 3]),
            _ => Plane::with_normal(policy, normal(means)),
        }
    }

    /// The plane of a split whose shifted normal `n` (SPEC §7.4
    /// `plane_of`) is known, under `policy` (`n` is ignored under `off`).
    /// An encoder trying every policy computes `n` once.
    #[inline]
    pub fn with_normal(policy: PlanePolicy, n: [i64; 3]) -> Plane {
        let (normal, axis) = match policy {
            PlanePolicy::Off | PlanePolicy::Height => {
                return Plane {
                    policy,
                    normal: [0; 3],
                    axis: None,
                    order: [0, 1, 2],
                    contexts: [0, 1, 2],
                };
            }
            PlanePolicy::Dominant => {
                let m = n.map(|x| x.unsigned_abs());
                // The largest component, the lowest axis on ties.
                let j = if m[1] > m[0] {
                    if m[2] > m[1] { 2 } else { 1 }
                } else if m[2] > m[0] {
                    2
                } else {
                    0
                };
                (n, j)
            }
            PlanePolicy::Axis(a) => (n, (a as usize).min(2)),
        };
        let order = [(axis + 1) % 3, (axis + 2) % 3, axis];
        let contexts = match policy {
            PlanePolicy::Dominant => core::array::from_fn(|k| (k == axis) as u8),
            _ => [0, 1, 2],
        };
        Plane {
            policy,
            normal,
            axis: Some(axis),
            order,
            contexts,
        }
    }

    /// The axes in the order the stream holds them: x, y, z, or under a
    /// plane policy j + 1, j + 2 (mod 3), then the predicted axis j.
    #[inline]
    pub fn order(&self) -> [usize; 3] {
        self.order
    }

    /// The rANS context of `axis` (SPEC §5.5.5).
    #[inline]
    pub fn context(&self, axis: usize) -> u8 {
        self.contexts.get(axis).copied().unwrap_or(0)
    }

    /// The plane's prediction of the residual on the predicted axis j from
    /// the two others: `round(-(n_{j+1} r_{j+1} + n_{j+2} r_{j+2}) / n_j)`,
    /// 0 when `n_j = 0` or without a plane.
    #[inline]
    pub fn offset(&self, r: &[i64; 3]) -> i64 {
        let Some(j) = self.axis else {
            return 0;
        };
        let n = &self.normal;
        let (j1, j2) = (self.order[0], self.order[1]);
        // |n| <= 2^15 and the residuals read are i32: far inside i64.
        round_div(-(n[j1] * r[j1] + n[j2] * r[j2]), n[j])
    }

    /// The residual vector from the values read (decoder): the predicted
    /// axis gets the plane's offset added, modulo 2^32 ([`wrap`]).
    #[inline]
    pub fn decode(&self, coded: [i64; 3]) -> [i64; 3] {
        let mut r = coded;
        if let Some(j) = self.axis {
            r[j] = wrap(coded[j] + self.offset(&coded));
        }
        r
    }

    /// The values to write for the residual vector `r` (encoder; every
    /// component a 32-bit value, as [`residual`] gives them).
    pub fn encode(&self, r: [i64; 3]) -> [i64; 3] {
        let mut coded = r;
        if let Some(j) = self.axis {
            coded[j] = wrap(r[j] - self.offset(&r));
        }
        coded
    }
}

/// `x` modulo 2^32 as a signed 32-bit value (two's complement): the
/// residual additions of SPEC §7.4 wrap, so that any position of the grid
/// can be coded whatever its prediction.
#[inline]
pub fn wrap(x: i64) -> i64 {
    x as i32 as i64
}

/// The decoded vector: the prediction plus the residual, modulo 2^32
/// (SPEC §7.4).
#[inline]
pub fn add_residual(prediction: [i64; 3], r: [i64; 3]) -> [i64; 3] {
    core::array::from_fn(|k| wrap(prediction[k] + r[k]))
}

/// The residual that [`add_residual`] turns back into `x` (encoder), for a
/// vector `x` of magnitude below 2^31.
#[inline]
pub fn residual(x: [i64; 3], prediction: [i64; 3]) -> [i64; 3] {
    core::array::from_fn(|k| wrap(x[k] - prediction[k]))
}

/// `round(p / q)`, halves rounded up: with the signs flipped so that
/// `q > 0`, `floor((2p + q) / (2q))`; 0 when `q = 0`.
#[inline]
pub fn round_div(p: i64, q: i64) -> i64 {
    if q == 0 || p == 0 {
        return 0;
    }
    let (p, q) = if q < 0 { (-p, -q) } else { (p, q) };
    // floor(x / d) with d = 2q > 0, through unsigned magnitudes (cheaper
    // than a signed division when both fit in 32 bits, as they usually do).
    let (x, d) = (2 * p + q, (2 * q) as u64);
    if x >= 0 {
        (x as u64 / d) as i64
    } else {
        -(x.unsigned_abs().div_ceil(d) as i64)
    }
}

/// The split's normal (SPEC §7.4): `N = (pos[b] − pos[a]) × (m_I2 − m_I1)`,
/// 0 when a wing is the ghost, shifted right (arithmetic shift) by
/// `max(0, bitlen(max |N_i|) − 15)`.
///
/// Exact in 64 bits: positions lie in `0 .. 2^31`, so `|pos[b] − pos[a]|`
/// and `|m_I2 − m_I1|` (two floor means of positions relative to the same R)
/// are at most `2^31 − 1`; each product is below `2^62` and each component
/// below `2^63`.
#[inline]
pub fn normal(means: &ArcMeans) -> [i64; 3] {
    let Some(a) = means.wing_edge else {
        return [0; 3];
    };
    let b: [i64; 3] = core::array::from_fn(|k| means.arc_2[k] - means.arc_1[k]);
    let n = cross(a, b);
    let largest = n.iter().map(|x| x.unsigned_abs()).max().unwrap_or(0);
    let shift = (u64::BITS - largest.leading_zeros()).saturating_sub(plane::NORMAL_BITS);
    n.map(|x| x >> shift)
}

#[inline]
fn cross(a: [i64; 3], b: [i64; 3]) -> [i64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// Constrained mode's context of the placement code (SPEC §5.5.5): where
/// R lies along the direction `a = m_I2 − m_I1` from arc 1 to arc 2, from
/// `T = −G·a` against `Q = nG |a|²`, in 128-bit arithmetic.
#[inline]
pub fn placement_context(means: &ArcMeans) -> u8 {
    let a: [i64; 3] = core::array::from_fn(|k| means.arc_2[k] - means.arc_1[k]);
    let g = means.sum;
    // With |a| < 2^24 and |G| < 2^32 (any grid of up to 23 bits), 10 |T|
    // and 5 Q stay below 2^62: 64 bits suffice. Otherwise |a| < 2^32,
    // |G| < 2^39, nG <= 255: 10 T and 5 Q stay below 2^78.
    let small = a.iter().all(|x| x.unsigned_abs() < 1 << 24)
        && g.iter().all(|x| x.unsigned_abs() < 1 << 32);
    let (t, q) = if small {
        let t = -(g[0] * a[0] + g[1] * a[1] + g[2] * a[2]);
        let q = means.count * (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
        (t as i128, q as i128)
    } else {
        let t = -(mul_wide(g[0], a[0]) + mul_wide(g[1], a[1]) + mul_wide(g[2], a[2]));
        let q = means.count as i128
            * (mul_wide(a[0], a[0]) + mul_wide(a[1], a[1]) + mul_wide(a[2], a[2]));
        (t, q)
    };
    bucket(t, q)
}

/// `a · b` in 128 bits, for [`placement_context`]'s wide path (SPEC
/// §5.5.5). Inlined on the host; on 32-bit Arm one out-of-line copy: each
/// inlined 128-bit product was a long run of 32-bit multiplies (the six
/// took 232 bytes more of a thumbv7em decoder's `.text`), on a path only
/// grids of over 23 bits take.
#[cfg_attr(not(target_arch = "arm"), inline(always))]
#[cfg_attr(target_arch = "arm", inline(never))]
fn mul_wide(a: i64, b: i64) -> i128 {
    a as i128 * b as i128
}

/// The placement context of `T` against `Q` (SPEC §5.5.5).
#[inline]
fn bucket(t: i128, q: i128) -> u8 {
    let t10 = 10 * t;
    if t10 < -5 * q {
        0
    } else if t10 < -q {
        1
    } else if t10 <= q {
        2
    } else if t10 <= 5 * q {
        3
    } else {
        4
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::limits::NONE;

    /// R at (100, 100, 50) with the 8 lattice neighbours counter-clockwise
    /// from +x, on the plane z = 50 + 3 dx − 2 dy (so every wedge is that
    /// plane), and the ring of vertex 0 (R) over vertices 1..=8.
    fn plane_fan() -> ([[u32; 3]; 9], Ring) {
        let height = |dx: i64, dy: i64| (50 + 3 * dx - 2 * dy) as u32;
        let around = [
            (1, 0),
            (1, 1),
            (0, 1),
            (-1, 1),
            (-1, 0),
            (-1, -1),
            (0, -1),
            (1, -1),
        ];
        let mut positions = [[100, 100, 50]; 9];
        for (i, (dx, dy)) in around.into_iter().enumerate() {
            positions[i + 1] = [(100 + dx) as u32, (100 + dy) as u32, height(dx, dy)];
        }
        (positions, Ring::of_vertices(&[1, 2, 3, 4, 5, 6, 7, 8]))
    }

    #[test]
    fn surface_height_is_exact_on_a_plane() {
        let (positions, ring) = plane_fan();
        let parent = positions[0];
        for (x, y) in [(0, 0), (1, 0), (2, 1), (-3, 2), (-1, -1), (5, -7), (0, -2)] {
            assert_eq!(
                surface_height(&positions, parent, &ring, [x, y]),
                Some(3 * x - 2 * y),
                "({x}, {y})"
            );
        }
        // The edge vector C − P with R their floor midpoint: the difference.
        let x = [3, -2, 0];
        let (p, c) = ([-1i64, 1], [2i64, -1]);
        let expected = (3 * c[0] - 2 * c[1]) - (3 * p[0] - 2 * p[1]);
        assert_eq!(
            height_prediction(&positions, parent, &ring, Target::Edge, x),
            Some(expected)
        );
        assert_eq!(
            height_prediction(&positions, parent, &ring, Target::C, x),
            Some(13)
        );
    }

    #[test]
    fn surface_height_interpolates_the_first_wedge_that_holds_the_point() {
        // Wedge (R, r_0, r_1) with r_0 = (4, 0, 8), r_1 = (0, 4, 0), relative
        // to R: y = s r_0 + t r_1 has z = 8 s.
        let positions = [
            [10, 10, 10],
            [14, 10, 18],
            [10, 14, 10],
            [6, 10, 10],
            [10, 6, 10],
        ];
        let ring = Ring::of_vertices(&[1, 2, 3, 4]);
        let parent = positions[0];
        // (1, 1): s = 1/4; (3, 1): s = 3/4; (1, 3): s = 1/4.
        assert_eq!(surface_height(&positions, parent, &ring, [1, 1]), Some(2));
        assert_eq!(surface_height(&positions, parent, &ring, [3, 1]), Some(6));
        assert_eq!(surface_height(&positions, parent, &ring, [1, 3]), Some(2));
        // Other wedges are flat (z = 0 relative to R).
        assert_eq!(surface_height(&positions, parent, &ring, [-2, 1]), Some(0));
        // Halves round up: with r_0 at z + 1, (2, 0) and (2, 1) have s = 1/2.
        let positions = [
            [10, 10, 10],
            [14, 10, 11],
            [10, 14, 10],
            [6, 10, 10],
            [10, 6, 10],
        ];
        assert_eq!(surface_height(&positions, parent, &ring, [2, 0]), Some(1));
        assert_eq!(surface_height(&positions, parent, &ring, [2, 1]), Some(1));
    }

    #[test]
    fn surface_height_skips_ghost_and_flat_wedges_and_follows_either_orientation() {
        let (positions, _) = plane_fan();
        let parent = positions[0];
        // A boundary ring: the ghost first, then the fan over +y only.
        let ring = Ring::of_vertices(&[NONE, 1, 2, 3, 4, 5]);
        assert_eq!(surface_height(&positions, parent, &ring, [1, 1]), Some(1));
        // Below the x axis no real wedge holds the point: no prediction.
        assert_eq!(surface_height(&positions, parent, &ring, [0, -1]), None);
        // The same fan clockwise (a mesh whose triangles face down).
        let ring = Ring::of_vertices(&[8, 7, 6, 5, 4, 3, 2, 1]);
        assert_eq!(
            surface_height(&positions, parent, &ring, [-3, 2]),
            Some(-13)
        );
        // Collinear neighbours (det = 0) hold nothing.
        let ring = Ring::of_vertices(&[1, 5]);
        assert_eq!(surface_height(&positions, parent, &ring, [0, 1]), None);
    }

    #[test]
    fn surface_height_survives_31_bits() {
        // Extreme positions: a thin wedge far from R, a point at 2^32.
        let top = (1u32 << 31) - 1;
        let positions = [[0, 0, 0], [top, 1, top], [top, 2, 0], [0, top, top]];
        let ring = Ring::of_vertices(&[1, 2, 3]);
        let parent = positions[0];
        for y in [
            [(1i64 << 32) - 1, 3],
            [1, 1],
            [-(1 << 31), -(1 << 31)],
            [top as i64, 0],
        ] {
            if let Some(z) = surface_height(&positions, parent, &ring, y) {
                assert_eq!(z, wrap(z), "{y:?}");
            }
        }
        let parent = [top, top, top];
        let ring = Ring::of_vertices(&[1, 2, 3]);
        let h = height_prediction(
            &positions,
            parent,
            &ring,
            Target::Edge,
            [i32::MIN as i64, i32::MAX as i64, 0],
        );
        assert_eq!(h, h.map(wrap));
    }

    #[test]
    fn surface_search_agrees_in_both_widths() {
        // A pseudo-random fan (xorshift) and points up to 2^31: the 64-bit
        // and the 128-bit searches give the same height.
        let mut x = 0x9E37_79B9_7F4A_7C15u64;
        let mut next = |m: u64| {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            x % m
        };
        for _ in 0..200 {
            let top = 1u64 << (8 + next(24));
            let mut positions = [[0u32; 3]; 7];
            for p in &mut positions {
                *p = [next(top) as u32, next(top) as u32, next(top) as u32];
            }
            let ring = Ring::of_vertices(&[1, 2, 3, 4, 5, 6]);
            let parent = positions[0];
            let span = 1i64 << 31;
            let y = [
                next(2 * span as u64) as i64 - span,
                next(2 * span as u64) as i64 - span,
            ];
            let narrow = surface_search(&positions, parent, &ring, |e| e[0] * y[1] - e[1] * y[0]);
            let (y0, y1) = (y[0] as i128, y[1] as i128);
            let wide = surface_search(&positions, parent, &ring, |e| {
                e[0] as i128 * y1 - e[1] as i128 * y0
            });
            assert_eq!(narrow, wide, "{positions:?} {y:?}");
            assert_eq!(surface_height(&positions, parent, &ring, y), wide);
        }
    }

    #[test]
    fn wide_rounding_division_agrees_in_both_widths() {
        // round(p / q) = floor((2p + q) / 2q), halves up, as `round_div`.
        for (p, q) in [(3, 2), (-3, 2), (-5, 3), (7, -2), (0, 5), (1, 1 << 40)] {
            assert_eq!(
                round_div_wide(p, q),
                round_div(p as i64, q as i64) as i128,
                "{p} {q}"
            );
        }
        // Past 64 bits: 2^95 + 2^40 over 2^41 is 2^54 + 1/2, rounded up.
        let big = (1i128 << 95) + (1 << 40);
        assert_eq!(round_div_wide(big, 1 << 41), (1 << 54) + 1);
        assert_eq!(round_div_wide(-big, 1 << 41), -(1 << 54));
        assert_eq!(round_div_wide(big, -(1 << 41)), -(1 << 54));
        assert_eq!(
            round_div_wide(-(1i128 << 96) + 1, (1i128 << 63) - 1),
            -(1 << 33)
        );
    }

    /// The shift-and-subtract division used on 32-bit Arm is `div_euclid`
    /// for positive divisors, small and wide.
    #[test]
    fn floor_division_by_shifts_is_div_euclid() {
        let values = [
            0i128,
            1,
            2,
            3,
            7,
            (1 << 40) + 5,
            (1 << 63) - 1,
            1 << 64,
            (1 << 95) + (1 << 40),
            (1 << 126) - 3,
            i128::MAX,
        ];
        for &x in &values {
            for &d in &values[1..] {
                for x in [x, -x, !x] {
                    assert_eq!(floor_div_positive(x, d), x.div_euclid(d), "{x} {d}");
                }
            }
        }
        let mut seed = 7u128;
        for _ in 0..2000 {
            seed = seed
                .wrapping_mul(0x2360_ED05_1FC6_5DA4_4385_DF64_9FCC_F645)
                .wrapping_add(1);
            let x = (seed >> (seed as u32 & 63)) as i128 - (1 << 62);
            let d = ((seed >> 64) as u64 >> ((seed >> 58) as u32 & 63)).max(1) as i128;
            assert_eq!(floor_div_positive(x, d), x.div_euclid(d), "{x} {d}");
            let x = (seed as i128) >> 2;
            assert_eq!(floor_div_positive(x, d), x.div_euclid(d), "{x} {d}");
        }
    }

    #[test]
    fn height_residuals_invert() {
        let (positions, ring) = plane_fan();
        let fan = SplitFan {
            positions: &positions,
            parent: positions[0],
            ring: &ring,
        };
        let policy = PlanePolicy::Height;
        for target in [Target::P, Target::C, Target::Edge] {
            for x in [
                [2, 1, 9],
                [-1, 0, -4],
                [0, 0, 0],
                [i32::MAX as i64, -3, i32::MIN as i64],
            ] {
                let prediction = [1, -1, 5];
                let r = fan.residual(policy, target, prediction, x);
                let back = fan.vector(policy, target, prediction, r);
                assert_eq!(back, x.map(wrap), "{target:?} {x:?}");
                // Under any other policy, the plain linear residual.
                let off = fan.residual(PlanePolicy::Off, target, prediction, x);
                assert_eq!(off, residual(x, prediction));
            }
        }
        // On the plane the height residual of an exact vector is 0.
        let r = fan.residual(policy, Target::C, [0; 3], [2, 1, 4]);
        assert_eq!(r, [2, 1, 0]);
    }

    #[test]
    fn reciprocal_division_is_floor_division() {
        let mut x = 0x2545_F491_4F6C_DD1Du64;
        let mut next = || {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            x
        };
        for n in 1..=255i64 {
            for s in [0, 1, -1, n, -n, n - 1, 1 - n, (1 << 40) - 1, 1 - (1 << 40)] {
                assert_eq!(floor_div(s, n), s.div_euclid(n), "{s} / {n}");
            }
            for _ in 0..2000 {
                let r = next();
                let s = (r >> 23) as i64 * if r & 1 == 0 { 1 } else { -1 };
                assert_eq!(floor_div(s, n), s.div_euclid(n), "{s} / {n}");
            }
        }
        assert_eq!(floor_div(1 << 50, 3), (1i64 << 50) / 3);
        assert_eq!(floor_div(-7, 300), -1);
        assert_eq!(floor_div(7, 0), 0);
    }

    #[test]
    fn rounding_division() {
        assert_eq!(round_div(3, 2), 2);
        assert_eq!(round_div(-3, 2), -1);
        assert_eq!(round_div(3, -2), -1);
        assert_eq!(round_div(-3, -2), 2);
        assert_eq!(round_div(5, 3), 2);
        assert_eq!(round_div(4, 3), 1);
        assert_eq!(round_div(-4, 3), -1);
        assert_eq!(round_div(-5, 3), -2);
        assert_eq!(round_div(7, 0), 0);
    }

    #[test]
    fn policies_round_trip_their_bytes() {
        for (i, p) in PlanePolicy::ALL.iter().enumerate() {
            assert_eq!(p.to_byte(), i as u8);
            assert_eq!(PlanePolicy::from_byte(i as u8), Some(*p));
        }
        assert_eq!(PlanePolicy::from_byte(6), None);
        assert_eq!(PlanePolicy::from_byte(255), None);
    }

    #[test]
    fn normal_is_exact_then_shifted() {
        // The largest differences a 31-bit grid allows.
        let big = (1i64 << 31) - 1;
        let means = ArcMeans {
            arc_1: [-big, -big, 0],
            arc_2: [0, 0, big],
            wing_edge: Some([big, -big, big]),
            ..ArcMeans::default()
        };
        let n = normal(&means);
        assert!(n.iter().all(|x| x.abs() <= 1 << 15));
        assert!(n.iter().any(|x| x.abs() >= 1 << 14));
        // Small normals are not shifted.
        let small = ArcMeans {
            arc_2: [0, 10, 0],
            wing_edge: Some([-10, 0, 10]),
            ..ArcMeans::default()
        };
        assert_eq!(normal(&small), [-100, 0, -100]);
    }

    #[test]
    fn wrapped_residuals_code_every_vector() {
        let big = (1i64 << 31) - 1;
        for x in [0, 1, -1, big, -big] {
            for prediction in [0, big, -big, 10 * big, -10 * big, 12345] {
                let r = residual([x; 3], [prediction; 3]);
                assert!(r.iter().all(|v| i32::try_from(*v).is_ok()));
                assert_eq!(add_residual([prediction; 3], r), [x; 3]);
            }
        }
    }

    #[test]
    fn plane_encode_inverts_decode() {
        let means = ArcMeans {
            arc_1: [3, -7, 1],
            arc_2: [-5, 9, 4],
            wing_edge: Some([12, 3, -8]),
            ..ArcMeans::default()
        };
        for policy in PlanePolicy::ALL {
            let plane = Plane::new(policy, &means);
            for r in [
                [0, 0, 0],
                [5, -3, 7],
                [-100, 40, 2],
                [1 << 30, -(1 << 30), 5],
            ] {
                assert_eq!(plane.decode(plane.encode(r)), r, "{policy:?}");
            }
        }
    }

    #[test]
    fn a_known_normal_gives_the_same_plane() {
        for (wing_edge, arc_2) in [
            (Some([3, -9, 2]), [1, 1, 7]),
            (Some([5, 0, 0]), [0, 5, 0]),
            (Some([-4, 4, -4]), [4, 4, -4]),
            (None, [4, 4, 4]),
        ] {
            let means = ArcMeans {
                arc_2,
                wing_edge,
                ..ArcMeans::default()
            };
            let n = Plane::new(PlanePolicy::Dominant, &means).normal;
            for policy in PlanePolicy::ALL {
                assert_eq!(
                    Plane::with_normal(policy, n),
                    Plane::new(policy, &means),
                    "{policy:?}"
                );
            }
        }
    }

    #[test]
    fn plane_orders_and_contexts_follow_the_spec() {
        for (wing_edge, arc_2) in [
            (Some([3, -9, 2]), [1, 1, 7]),
            (Some([5, 0, 0]), [0, 5, 0]),
            (None, [4, 4, 4]),
        ] {
            let means = ArcMeans {
                arc_2,
                wing_edge,
                ..ArcMeans::default()
            };
            for policy in PlanePolicy::ALL {
                let plane = Plane::new(policy, &means);
                let n = normal(&means).map(|x| x.abs());
                let expected_axis = match policy {
                    PlanePolicy::Off | PlanePolicy::Height => None,
                    PlanePolicy::Dominant => {
                        Some((0..3).find(|&i| n[i] == *n.iter().max().unwrap()).unwrap())
                    }
                    PlanePolicy::Axis(a) => Some(a as usize),
                };
                assert_eq!(plane.axis, expected_axis, "{policy:?}");
                for axis in 0..3 {
                    assert_eq!(
                        plane.context(axis),
                        crate::context::residual(policy, axis, plane.axis)
                    );
                }
                let order = plane.order();
                if let Some(j) = plane.axis {
                    assert_eq!(order, [(j + 1) % 3, (j + 2) % 3, j]);
                } else {
                    assert_eq!(order, [0, 1, 2]);
                }
            }
        }
    }

    #[test]
    fn placement_context_survives_31_bits() {
        let big = (1i64 << 31) - 1;
        let means = ArcMeans {
            arc_1: [-big; 3],
            arc_2: [big; 3],
            sum: [-255 * big; 3],
            count: 255,
            ..ArcMeans::default()
        };
        assert_eq!(placement_context(&means), 3);
        let means = ArcMeans {
            sum: [255 * big; 3],
            ..means
        };
        assert_eq!(placement_context(&means), 1);
        let means = ArcMeans { count: 1, ..means };
        assert_eq!(placement_context(&means), 0);
        assert_eq!(placement_context(&ArcMeans::default()), 2);
    }
}
