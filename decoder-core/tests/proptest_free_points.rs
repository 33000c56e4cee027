//! `PositionsFirst::free_points` and `point_at` against SPEC §7.4
//! "Positions first" written out point by point: every lattice point of
//! the fan's bounding box tested against every real wedge, the free ones
//! sorted by their key. decoder-core marks rows of points at a time, keeps
//! boxes of one word in a register and finds rows by a multiplication;
//! a simple fan (no ghost, no fold) is counted by Pick's theorem and its
//! nearest points found without a list. These fans (simple, folded, flat,
//! with a ghost, up to the 1,024-point cap and past it) check that none of
//! that changes a list, a count or a rank.
//!
//! The wing choices of the same fans (`order_xs`, `order_ys`, `choice`,
//! `rank_of_choice`) are checked against `pair` and `before` written out
//! the same way: every pair tested wedge by wedge, the lists sorted by
//! the SPEC's `incircle`. decoder-core skips the wedge tests when every
//! wedge keeps its orientation under both ends of the new edge, and orders
//! by the angles' cotangents instead of the determinant.

use proptest::prelude::*;
use splitstream_decoder_core::limits::NONE;
use splitstream_decoder_core::positions_first::{LIST_CAP, NewEdge, POINT_CAP, PositionsFirst};
use splitstream_decoder_core::{Ring, Ties, WingCandidates};

/// R's position: far enough from 0 that no entry leaves the grid.
const R: [u32; 3] = [4096, 4096, 7];

fn orient(a: [i64; 2], b: [i64; 2], c: [i64; 2]) -> i64 {
    (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])
}

/// `free_points` of SPEC §7.4 for entries `q` relative to R (`None`: the
/// ghost): the free points in list order, or `None` for an escape.
fn spec_free_points(q: &[Option<[i64; 2]>]) -> Option<Vec<[i64; 2]>> {
    let real: Vec<[i64; 2]> = q.iter().flatten().copied().collect();
    let xs = real.iter().map(|p| p[0]).chain([0]);
    let ys = real.iter().map(|p| p[1]).chain([0]);
    let (x0, x1) = (xs.clone().min()?, xs.max()?);
    let (y0, y1) = (ys.clone().min()?, ys.max()?);
    if (x1 - x0 + 1) * (y1 - y0 + 1) > POINT_CAP {
        return None;
    }
    let k = q.len();
    let wedges: Vec<([i64; 2], [i64; 2])> = (0..k)
        .filter_map(|i| Some((q[i]?, q[(i + 1) % k]?)))
        .filter(|&(a, b)| orient([0, 0], a, b) != 0)
        .collect();
    if wedges.is_empty() {
        return None;
    }
    let inside = |p: [i64; 2]| {
        wedges.iter().any(|&(a, b)| {
            let s = [orient([0, 0], a, p), orient(a, b, p), orient(b, [0, 0], p)];
            s.iter().all(|&s| s >= 0) || s.iter().all(|&s| s <= 0)
        })
    };
    let n = real.len() as i64;
    let (sx, sy) = (
        real.iter().map(|p| p[0]).sum::<i64>(),
        real.iter().map(|p| p[1]).sum::<i64>(),
    );
    let mut free = Vec::new();
    for y in y0..=y1 {
        for x in x0..=x1 {
            let p = [x, y];
            if p != [0, 0] && !real.contains(&p) && inside(p) {
                let (ex, ey) = (n * x - sx, n * y - sy);
                free.push(((ex * ex + ey * ey), y, x));
            }
        }
    }
    if free.is_empty() || free.len() > LIST_CAP {
        return None;
    }
    free.sort();
    Some(free.into_iter().map(|(_, y, x)| [x, y]).collect())
}

/// `incircle(a, b, c, p)` of SPEC §7.4.
fn incircle(a: [i64; 2], b: [i64; 2], c: [i64; 2], p: [i64; 2]) -> i64 {
    let row = |v: [i64; 2]| {
        let (dx, dy) = (v[0] - p[0], v[1] - p[1]);
        [dx, dy, dx * dx + dy * dy]
    };
    let ([ax, ay, al], [bx, by, bl], [cx, cy, cl]) = (row(a), row(b), row(c));
    ax * (by * cl - bl * cy) - ay * (bx * cl - bl * cx) + al * (bx * cy - by * cx)
}

/// `pair(x, y)` of SPEC §7.4 (every entry eligible, as under the schedule
/// `every-vertex`) for the new edge `a b`.
fn spec_pair(
    q: &[Option<[i64; 2]>],
    a: [i64; 2],
    b: [i64; 2],
    kind: u8,
    x: usize,
    y: usize,
) -> bool {
    let k = q.len();
    let keeps = |end: [i64; 2], from: usize, to: usize| {
        let mut i = from;
        while i != to {
            let j = (i + 1) % k;
            if let (Some(p), Some(n)) = (q[i], q[j])
                && orient(end, p, n) <= 0
            {
                return false;
            }
            i = j;
        }
        true
    };
    x != y
        && (kind == 0 || x < y)
        && q[x].is_none_or(|p| orient(a, b, p) > 0)
        && q[y].is_none_or(|p| orient(b, a, p) > 0)
        && keeps(a, x, y)
        && keeps(b, y, x)
}

/// `off(i)` of SPEC §7.4: how many of the edges from `e` and `f` to `p`
/// run along the diagonal that `ties` disfavours.
fn spec_off(ties: Ties, e: [i64; 2], f: [i64; 2], p: [i64; 2]) -> i64 {
    [e, f]
        .iter()
        .filter(|end| {
            let (dx, dy) = (p[0] - end[0], p[1] - end[1]);
            match ties {
                Ties::Ring => false,
                Ties::Rising => dx != 0 && dx == -dy,
                Ties::Falling => dx != 0 && dx == dy,
            }
        })
        .count() as i64
}

/// A list of wing choices sorted by `before(e, f)` of SPEC §7.4 under the
/// tie rule `ties`.
fn spec_sorted(
    q: &[Option<[i64; 2]>],
    e: [i64; 2],
    f: [i64; 2],
    ties: Ties,
    mut list: Vec<usize>,
) -> Vec<usize> {
    let before = |i: usize, j: usize| match (q[i], q[j]) {
        (Some(_), None) => true,
        (None, Some(_)) => false,
        (None, None) => i < j,
        (Some(qi), Some(qj)) => {
            let c = incircle(e, f, qj, qi);
            let (oi, oj) = (spec_off(ties, e, f, qi), spec_off(ties, e, f, qj));
            c > 0 || (c == 0 && (oi < oj || (oi == oj && i < j)))
        }
    };
    list.sort_by(|&i, &j| {
        if i == j {
            std::cmp::Ordering::Equal
        } else if before(i, j) {
            std::cmp::Ordering::Less
        } else {
            std::cmp::Ordering::Greater
        }
    });
    list
}

/// A fan: 3 to 12 entries within `reach` of R (per axis), at most one the
/// ghost. The thin reach (100 in x, 3 in y) gives wedges more than 64
/// lattice points wide under the point cap: rows that take more than one
/// 64-bit word when listed.
fn fans() -> impl Strategy<Value = Vec<Option<[i64; 2]>>> {
    (
        prop_oneof![
            Just((3i64, 3i64)),
            Just((8, 8)),
            Just((20, 20)),
            Just((40, 40)),
            Just((100, 3)),
        ],
        3usize..=12,
    )
        .prop_flat_map(|((rx, ry), k)| {
            (
                prop::collection::vec([-rx..=rx, -ry..=ry], k),
                prop::option::of(0..k),
            )
        })
        .prop_map(|(points, ghost)| {
            points
                .into_iter()
                .enumerate()
                .map(|(i, p)| (Some(i) != ghost).then_some(p))
                .collect()
        })
}

/// A fan around R: 3 to 12 entries sorted by angle, most of them simple
/// (every wedge counter-clockwise, the ring once around R), sometimes
/// with a ghost.
fn star_fans() -> impl Strategy<Value = Vec<Option<[i64; 2]>>> {
    (fans(), prop::bool::weighted(0.2)).prop_map(|(q, ghost)| {
        let mut points: Vec<[i64; 2]> = q.into_iter().flatten().filter(|p| *p != [0, 0]).collect();
        let angle = |p: &[i64; 2]| (p[1] as f64).atan2(p[0] as f64);
        points.sort_by(|a, b| angle(a).total_cmp(&angle(b)));
        points.dedup_by(|a, b| angle(a) == angle(b));
        let mut fan: Vec<Option<[i64; 2]>> = points.into_iter().map(Some).collect();
        if ghost && fan.len() > 2 {
            fan[0] = None;
        }
        fan
    })
}

/// The positions (R first) and the ring of fan `q`.
fn fan_of(q: &[Option<[i64; 2]>]) -> (Vec<[u32; 3]>, Ring) {
    let mut positions = vec![R];
    let mut entries = Vec::new();
    for p in q {
        match p {
            Some(p) => {
                entries.push(positions.len() as u32);
                positions.push([(R[0] as i64 + p[0]) as u32, (R[1] as i64 + p[1]) as u32, 0]);
            }
            None => entries.push(NONE),
        }
    }
    let mut ring = Ring::default();
    assert!(ring.set_vertices(&entries));
    (positions, ring)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(4000))]

    /// The wing lists of every new edge from R to a free point (kind 0)
    /// and of a midpoint split around it (kind 1, offset `t`), under each
    /// tie rule (3.8).
    #[test]
    fn wing_choices_are_the_spec_lists(
        q in prop_oneof![fans(), star_fans()],
        pick in 0usize..1000,
        t in 0i64..4,
    ) {
        prop_assume!(q.len() >= 3);
        let Some(free) = spec_free_points(&q) else {
            return Ok(());
        };
        let (positions, ring) = fan_of(&q);
        let mut pf = PositionsFirst::default();
        prop_assert!(pf.free_points(&positions, R, &ring).is_some());
        let n = free[pick % free.len()];
        let k = q.len();
        let eligible = WingCandidates::all(k);
        for (kind, ties) in [0u8, 1].into_iter().flat_map(|kind| Ties::ALL.map(|t| (kind, t))) {
            pf.set_ties(ties);
            let (a, b) = if kind == 0 {
                (n, [0, 0])
            } else {
                ([(t & 1) - n[0], (t >> 1) - n[1]], n)
            };
            let edge = NewEdge { a, b, midpoint: kind == 1 };
            let xs: Vec<usize> = (0..k)
                .filter(|&x| (0..k).any(|y| spec_pair(&q, a, b, kind, x, y)))
                .collect();
            let xs = spec_sorted(&q, a, b, ties, xs);
            // Each choice asked of a list just collected, and then all of
            // them of one list (the first choice after the others).
            for (u, &x) in xs.iter().enumerate() {
                prop_assert_eq!(pf.order_xs(&eligible, &edge), xs.len());
                prop_assert_eq!(pf.choice(xs.len(), u), Some(x), "{:?} x {}", edge, u);
            }
            prop_assert_eq!(pf.order_xs(&eligible, &edge), xs.len());
            for u in (0..=xs.len()).rev() {
                prop_assert_eq!(pf.choice(xs.len(), u), xs.get(u).copied());
            }
            for (u, &x) in xs.iter().enumerate() {
                pf.order_xs(&eligible, &edge);
                prop_assert_eq!(pf.rank_of_choice(xs.len(), x), Some(u));
                let ys: Vec<usize> = (0..k).filter(|&y| spec_pair(&q, a, b, kind, x, y)).collect();
                let ys = spec_sorted(&q, b, a, ties, ys);
                prop_assert!(!ys.is_empty());
                for (v, &y) in ys.iter().enumerate() {
                    prop_assert_eq!(pf.order_ys(&edge, x), ys.len());
                    prop_assert_eq!(pf.choice(ys.len(), v), Some(y), "{:?} x {} y {}", edge, x, v);
                    prop_assert_eq!(pf.rank_of_choice(ys.len(), y), Some(v));
                }
            }
            // An entry that is not a choice has no rank.
            if let Some(other) = (0..k).find(|x| !xs.contains(x)) {
                pf.order_xs(&eligible, &edge);
                prop_assert_eq!(pf.rank_of_choice(xs.len(), other), None);
            }
        }
    }

    #[test]
    fn free_points_are_the_spec_list(q in prop_oneof![fans(), star_fans()]) {
        prop_assume!(q.len() >= 3);
        let mut positions = vec![R];
        let mut entries = Vec::new();
        for p in &q {
            match p {
                Some(p) => {
                    entries.push(positions.len() as u32);
                    positions.push([
                        (R[0] as i64 + p[0]) as u32,
                        (R[1] as i64 + p[1]) as u32,
                        0,
                    ]);
                }
                None => entries.push(NONE),
            }
        }
        let mut ring = Ring::default();
        prop_assert!(ring.set_vertices(&entries));
        let mut pf = PositionsFirst::default();
        let got = pf.free_points(&positions, R, &ring);
        let expected = spec_free_points(&q);
        prop_assert_eq!(got, expected.as_ref().map(Vec::len));
        if let Some(expected) = expected {
            for (j, p) in expected.iter().enumerate() {
                prop_assert_eq!(pf.point_at(j), Some(*p), "rank {}", j);
            }
            prop_assert_eq!(pf.point_at(expected.len()), None);
            // Ranks, each asked of a fan just counted (a simple fan is
            // listed only when a rank is far from its centroid).
            for (j, p) in expected.iter().enumerate() {
                pf.free_points(&positions, R, &ring);
                prop_assert_eq!(pf.rank_of(*p), Some(j), "point {:?}", p);
            }
            pf.free_points(&positions, R, &ring);
            prop_assert_eq!(pf.rank_of([0, 0]), None);
            // Each rank asked first of a fan just counted (the low ranks
            // are then often taken among the corners around the centroid).
            for (j, p) in expected.iter().enumerate() {
                pf.free_points(&positions, R, &ring);
                prop_assert_eq!(pf.point_at(j), Some(*p), "rank {} first", j);
            }
            // Ranks in decreasing order, the fan counted once.
            pf.free_points(&positions, R, &ring);
            for j in (0..expected.len()).rev() {
                prop_assert_eq!(pf.point_at(j), Some(expected[j]), "rank {}", j);
            }
        }
    }
}
