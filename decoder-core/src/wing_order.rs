//! The wings named in the ring's geometric order (SPEC §5.1 `wing_policy`,
//! §7.4 "Wings in the near order", format 3.2).
//!
//! A split's wings are the two ring entries next to both P and C. P's and
//! C's rings, merged into R's, make a ring that is long along the edge PC
//! and narrow across it, and the wings sit at its waist: they are the
//! entries nearest to the ring's centre, and nearly opposite each other on
//! the ring. Under the policies `near` and `near-xy` the stream names the
//! first wing by its rank among the eligible entries ordered by distance to
//! the centre, and the second by its rank among the entries after it,
//! ordered by how far they are from the entry opposite the first. The ranks
//! are mostly 0 or 1 where the plain ranks of `ranks` spread over the ring.

use crate::Error;
use crate::limits::MAX_SPLIT_VALENCE;
use crate::predict::floor_div;
use crate::ring::Ring;
use crate::symbols::WingCandidates;

/// How a level codes the wings of its splits (SPEC §5.1, level header
/// byte 9).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum WingPolicy {
    /// Ranks among the eligible entries in ring order (formats 3.0, 3.1).
    #[default]
    Ranks,
    /// Ranks in the near order, distances over x, y and z (3.2).
    Near,
    /// Ranks in the near order, distances over x and y only (3.2): for
    /// terrain, whose z is on another scale.
    NearXy,
}

impl WingPolicy {
    /// Every policy, in byte order.
    pub const ALL: [WingPolicy; 3] = [WingPolicy::Ranks, WingPolicy::Near, WingPolicy::NearXy];

    pub fn from_byte(b: u8) -> Option<WingPolicy> {
        WingPolicy::ALL.get(b as usize).copied()
    }

    pub fn to_byte(self) -> u8 {
        self as u8
    }

    /// The name `splitstream info` and the SPEC use.
    pub fn name(self) -> &'static str {
        match self {
            WingPolicy::Ranks => "ranks",
            WingPolicy::Near => "near",
            WingPolicy::NearXy => "near-xy",
        }
    }

    /// The axes the distances run over.
    fn axes(self) -> usize {
        match self {
            WingPolicy::NearXy => 2,
            _ => 3,
        }
    }
}

/// Largest distance key: larger squared distances, and the ghost, all get
/// it (SPEC §7.4), so that a key, a ring position and a balance pack into
/// one `u64`.
pub const KEY_CAP: u64 = (1 << 47) - 1;

/// Room for the order keys of one ring's eligible entries ([`near_keys`]).
pub type NearKeys = [u64; MAX_SPLIT_VALENCE];

/// Calls `f(i, d)` for every eligible ring entry `i`, in ring order, with
/// `d` its distance to the floor mean of the ring's real entries per axis
/// (SPEC §7.4), or `None` for the ghost.
#[inline(always)]
fn centre_distances(
    positions: &[[u32; 3]],
    ring: &Ring,
    eligible: &WingCandidates,
    mut f: impl FnMut(usize, Option<[u64; 3]>),
) {
    let vertices = ring.vertices();
    let (mut sum, mut n) = ([0u64; 3], 0u64);
    for &v in vertices {
        if let Some(p) = positions.get(v as usize) {
            sum = [
                sum[0] + p[0] as u64,
                sum[1] + p[1] as u64,
                sum[2] + p[2] as u64,
            ];
            n += 1;
        }
    }
    // The floor mean as a multiplication (`floor_div`: sums of at most 255
    // coordinates below 2^31 stay below 2^40), not three u64 divisions a
    // split: those are library calls on 32-bit targets.
    let n = n.max(1) as i64;
    let centre = sum.map(|s| floor_div(s as i64, n) as u64);
    for w in 0..vertices.len().div_ceil(64) {
        let mut bits = eligible.word(w);
        while bits != 0 {
            let i = 64 * w + bits.trailing_zeros() as usize;
            bits &= bits - 1;
            let d = vertices
                .get(i)
                .and_then(|&v| positions.get(v as usize))
                .map(|p| core::array::from_fn(|a| (p[a] as u64).abs_diff(centre[a])));
            f(i, d);
        }
    }
}

/// The order key of entry `i` from its squared distance (SPEC §7.4).
#[inline(always)]
fn order_key(i: usize, squared: Option<u64>) -> u64 {
    (squared.map_or(KEY_CAP, |q| q.min(KEY_CAP)) << 8) | i as u64
}

/// Writes the near order key `K(i) = near_key(i) × 256 + i` of every
/// eligible ring entry `i`, in ring order, into `keys`, and returns how many
/// (SPEC §7.4). `near_key(i)` is the squared distance, over the policy's
/// axes, from `r_i` to the floor mean of the ring's real entries, capped at
/// [`KEY_CAP`]; the ghost's is the cap. Keys are distinct, since `i` is in
/// them. (A coordinate difference is below 2^31, so each square is below
/// 2^62 and three of them fit in 64 bits.)
pub fn near_keys(
    positions: &[[u32; 3]],
    ring: &Ring,
    eligible: &WingCandidates,
    policy: WingPolicy,
    keys: &mut NearKeys,
) -> usize {
    let z_mask = if policy.axes() == 3 { u64::MAX } else { 0 };
    let mut m = 0;
    centre_distances(positions, ring, eligible, |i, d| {
        let squared = d.map(|[dx, dy, dz]| dx * dx + dy * dy + (dz & z_mask) * (dz & z_mask));
        if let Some(slot) = keys.get_mut(m) {
            *slot = order_key(i, squared);
            m += 1;
        }
    });
    m
}

/// [`near_keys`] under `near` and under `near-xy` at once (an encoder
/// weighing both): one pass over the ring.
pub fn near_keys_both(
    positions: &[[u32; 3]],
    ring: &Ring,
    eligible: &WingCandidates,
    near: &mut NearKeys,
    near_xy: &mut NearKeys,
) -> usize {
    let mut m = 0;
    centre_distances(positions, ring, eligible, |i, d| {
        let xy = d.map(|[dx, dy, _]| dx * dx + dy * dy);
        let xyz = d.map(|[dx, dy, dz]| dx * dx + dy * dy + dz * dz);
        if let (Some(a), Some(b)) = (near.get_mut(m), near_xy.get_mut(m)) {
            *a = order_key(i, xyz);
            *b = order_key(i, xy);
            m += 1;
        }
    });
    m
}

/// How far ring position `j` is from the position opposite `first` on a
/// ring of `k` entries: `|2 ((j − first) mod k) − k|` (SPEC §7.4).
#[inline]
fn balance(first: u64, j: u64, k: u64) -> u64 {
    // (j − first) mod k without a division: both are below k.
    let along = if j >= first { j - first } else { j + k - first };
    (2 * along).abs_diff(k)
}

/// Stands for "not a candidate" in [`nth_smallest`]: above every key of
/// either stage (`K < 2^55`, a second-stage key below `2^63 + 2^55`).
const EXCLUDED: u64 = u64::MAX;

/// The `rank`-th smallest (from 0) of the distinct values `f(key)` other
/// than [`EXCLUDED`]. Repeated minimum extraction: `rank + 1` passes, so the
/// usual ranks 0 and 1 cost one or two; each pass is branch-free (the keys
/// are data the branch predictor cannot learn).
#[inline]
fn nth_smallest(keys: &[u64], rank: usize, f: impl Fn(u64) -> u64) -> Option<u64> {
    let mut floor = 0u64;
    let mut best = EXCLUDED;
    for _ in 0..=rank {
        best = EXCLUDED;
        for &key in keys {
            let x = f(key);
            let take = (x >= floor) & (x < best);
            best = if take { x } else { best };
        }
        if best == EXCLUDED {
            return None;
        }
        floor = best + 1;
    }
    Some(best)
}

/// The second stage's key of the entry of key `key`, the first wing's key
/// being `first` (SPEC §7.4): its balance, then its own key; [`EXCLUDED`]
/// for an entry not after the first wing in the near order.
#[inline]
fn second_key(first: u64, key: u64, k: u64) -> u64 {
    let x = (balance(first & 0xFF, key & 0xFF, k) << 55) | key;
    if key > first { x } else { EXCLUDED }
}

/// The wings' ring offset and distance `(o, d)` named by the coded near
/// ranks `u` and `v` (SPEC §7.4, 3.2), from the `keys` of [`near_keys`] of a
/// ring of `k` entries. Fails with `ring-offset-out-of-range` when the near
/// order has no `u`-th entry or no `v`-th entry after it.
pub fn near_wings(keys: &[u64], k: usize, u: u8, v: u8) -> Result<(usize, usize), Error> {
    let k = k as u64;
    let first = nth_smallest(keys, u as usize, |key| key).ok_or(Error::RingOffsetOutOfRange)?;
    let second = nth_smallest(keys, v as usize, |key| second_key(first, key, k))
        .ok_or(Error::RingOffsetOutOfRange)?;
    let (a, b) = (first & 0xFF, second & 0xFF);
    let (a, b) = (a.min(b) as usize, a.max(b) as usize);
    Ok((a, b - a))
}

/// The near ranks `(u, v)` of the wings at ring positions `o` and `o + d`
/// (encoder), from the `keys` of [`near_keys`]: `None` when one of them is
/// not an eligible entry.
pub fn near_ranks(keys: &[u64], k: usize, o: usize, d: usize) -> Option<(u8, u8)> {
    if d == 0 {
        return None;
    }
    let key_at = |i: usize| keys.iter().copied().find(|&key| key & 0xFF == i as u64);
    let (a, b) = (key_at(o)?, key_at(o + d)?);
    let (first, second) = (a.min(b), a.max(b));
    let k = k as u64;
    let u = keys.iter().filter(|&&key| key < first).count();
    let target = second_key(first, second, k);
    let v = keys
        .iter()
        .filter(|&&key| second_key(first, key, k) < target)
        .count();
    Some((u as u8, v as u8))
}

#[cfg(all(test, feature = "alloc"))]
mod tests {
    use super::*;
    use alloc::vec::Vec;

    fn all_eligible(k: usize) -> WingCandidates {
        WingCandidates::from_first_mask((1 << k) - 1)
    }

    /// Keys as [`near_keys`] packs them, from distance keys per entry.
    fn pack(distances: &[u64], eligible: &WingCandidates) -> Vec<u64> {
        (0..distances.len())
            .filter(|&i| eligible.contains(i))
            .map(|i| (distances[i].min(KEY_CAP) << 8) | i as u64)
            .collect()
    }

    #[test]
    fn near_ranks_and_wings_are_inverse() {
        // Keys with ties, a ghost (the cap) and gaps in the eligible set.
        let distances = [5u64, 1, 9, 1, u64::MAX, 0, 7, 3, 3];
        let k = distances.len();
        for eligible in [
            all_eligible(k),
            WingCandidates::from_first_mask(0b1_1011_0111),
        ] {
            let keys = pack(&distances, &eligible);
            for o in 0..k {
                for d in 1..k - o {
                    match near_ranks(&keys, k, o, d) {
                        Some((u, v)) => assert_eq!(near_wings(&keys, k, u, v), Ok((o, d))),
                        None => assert!(!eligible.contains(o) || !eligible.contains(o + d)),
                    }
                }
            }
        }
    }

    #[test]
    fn ranks_past_the_order_fail() {
        let keys = pack(&[0; 4], &all_eligible(4));
        assert_eq!(near_wings(&keys, 4, 3, 0), Err(Error::RingOffsetOutOfRange));
        assert_eq!(near_wings(&keys, 4, 2, 1), Err(Error::RingOffsetOutOfRange));
        assert!(near_wings(&keys, 4, 2, 0).is_ok());
        assert_eq!(
            near_wings(&keys, 4, 255, 255),
            Err(Error::RingOffsetOutOfRange)
        );
        assert_eq!(near_wings(&[], 0, 0, 0), Err(Error::RingOffsetOutOfRange));
    }

    #[test]
    fn both_key_sets_at_once_are_each_policys() {
        let positions = [
            [7, 100, 3],
            [50, 9, 1000],
            [20, 30, 40],
            [0, 0, 0],
            [99, 1, 5],
        ];
        let ring = Ring::of_vertices(&[0, 1, crate::limits::NONE, 2, 4, 3]);
        let eligible = WingCandidates::from_first_mask(0b110111);
        let (mut a, mut b) = ([0; MAX_SPLIT_VALENCE], [0; MAX_SPLIT_VALENCE]);
        let m = near_keys_both(&positions, &ring, &eligible, &mut a, &mut b);
        for (policy, both) in [(WingPolicy::Near, &a), (WingPolicy::NearXy, &b)] {
            let mut one = [0; MAX_SPLIT_VALENCE];
            assert_eq!(near_keys(&positions, &ring, &eligible, policy, &mut one), m);
            assert_eq!(one[..m], both[..m]);
        }
        assert_eq!(m, 5);
        // The ghost (ring position 2) has the capped key.
        assert_eq!(a[2], (KEY_CAP << 8) | 2);
    }

    #[test]
    fn the_waist_comes_first() {
        // A ring long along x: the entries at x = 50 are nearest the centre
        // and opposite each other, so they are ranks (0, 0).
        let positions = [
            [100, 50, 0],
            [60, 60, 0],
            [50, 60, 0],
            [40, 60, 0],
            [0, 50, 0],
            [40, 40, 0],
            [50, 40, 0],
            [60, 40, 0],
        ];
        let ring = Ring::of_vertices(&[0, 1, 2, 3, 4, 5, 6, 7]);
        let eligible = all_eligible(8);
        let mut keys: NearKeys = [0; MAX_SPLIT_VALENCE];
        let m = near_keys(&positions, &ring, &eligible, WingPolicy::Near, &mut keys);
        assert_eq!(m, 8);
        assert_eq!(near_ranks(&keys[..m], 8, 2, 4), Some((0, 0)));
        assert_eq!(near_wings(&keys[..m], 8, 0, 0), Ok((2, 4)));
    }
}
