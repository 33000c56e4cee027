//! What reading a raster split's position before its wings would cost a
//! decoder (encoder/BENCHMARKS.md, "Positions before wings on rasters";
//! `positions_first.py` prices its bits): the work such a record would do,
//! timed beside the work it would replace.
//!
//! ```text
//! cargo run --release -p splitstream-decoder-core --features alloc --example positions_first_cost -- IN.sps [RUNS]
//! ```
//!
//! The stream is decoded `RUNS` times (default 7) under each of four
//! observers (`LevelDecoder::next_round_observed`), alternating, and the
//! medians are compared:
//! - `none`: the decode alone;
//! - `replaced`: each split's near order of the wings and arc means computed
//!   once more (what a positions-first record would no longer compute);
//! - `positions first`: each split's free lattice points of the fan in xy,
//!   enumerated a row at a time over each real wedge, ordered by distance to
//!   the ring's centroid, the new vertex's rank found among them, then the
//!   wing pairs that keep every new triangle counter-clockwise in xy and the
//!   eligible entries ordered by the angle under which they see the new edge;
//! - `outward`: the same, but the new vertex's rank found as a decoder
//!   reading it would: lattice points generated outward from the centroid
//!   in key order and counted until the new vertex comes (the two ranks
//!   must agree; the example fails if their sums differ).
//!
//! Each observer folds its results into a checksum so that none of its work
//! is optimised away. The differences to `none` are the costs per split.

use std::time::Instant;

use splitstream_decoder_core::limits::{MAX_SPLIT_VALENCE, NONE};
use splitstream_decoder_core::owned::OwnedWorkspace;
use splitstream_decoder_core::wing_order::{NearKeys, WingPolicy, near_keys, near_wings};
use splitstream_decoder_core::{Error, MeshState, Ring, SplitObserver, SplitRecord, arc_means};

/// The bounding-box cap of the enumeration (the study's escape).
const CAP: i64 = 1024;

#[derive(Clone, Copy, PartialEq)]
enum Work {
    None,
    Replaced,
    PositionsFirst,
    /// The same, the fan's points generated outward from the centroid and
    /// stopped at the new vertex (what a decoder reading the rank would do).
    Outward,
}

struct Observer {
    work: Work,
    checksum: u64,
    splits: u64,
    /// Splits whose new vertex was among the enumerated points.
    found: u64,
    /// The sum of the ranks found (the two searches must agree).
    rank_sum: u64,
    candidates: Vec<u64>,
    pending: Vec<u64>,
}

/// A split vertex's fan in xy, for the outward search.
struct Fan<'a> {
    origin: Xy,
    entries: &'a [Option<Xy>],
    /// Real ring entries and the sum of their positions.
    n: i64,
    s: Xy,
    /// The bounding box of the fan.
    lo: Xy,
    hi: Xy,
}

impl Fan<'_> {
    /// The order key: `|n p - S|^2`, then y, then x.
    fn key(&self, p: Xy) -> u64 {
        let d = [self.n * p[0] - self.s[0], self.n * p[1] - self.s[1]];
        ((d[0] * d[0] + d[1] * d[1]) as u64) << 24
            | ((p[1] - self.lo[1]) as u64) << 12
            | (p[0] - self.lo[0]) as u64
    }

    fn point(&self, key: u64) -> Xy {
        [
            self.lo[0] + (key & 0xFFF) as i64,
            self.lo[1] + (key >> 12 & 0xFFF) as i64,
        ]
    }

    /// Whether `p` is a free lattice point of the fan: in a real wedge
    /// (closed), neither R nor a ring entry.
    fn holds(&self, p: Xy) -> bool {
        if p == self.origin || self.entries.contains(&Some(p)) {
            return false;
        }
        let k = self.entries.len();
        (0..k).any(|i| {
            let (Some(a), Some(b)) = (self.entries[i], self.entries[(i + 1) % k]) else {
                return false;
            };
            let d = [
                cross(self.origin, a, p),
                cross(a, b, p),
                cross(b, self.origin, p),
            ];
            cross(self.origin, a, b) != 0
                && (d.iter().all(|&x| x >= 0) || d.iter().all(|&x| x <= 0))
        })
    }

    /// The rank of `new` among the free points in key order, generating
    /// Chebyshev shells around the rounded centroid `c` and taking a point
    /// once no later shell can hold a smaller key: a point of shell s + 1 or
    /// beyond is at least s + 1/2 from S / n on one axis (`|c - S/n| <= 1/2`),
    /// so its `4 |n p - S|^2 >= n^2 (2 s + 1)^2`.
    fn outward_rank(&self, new: Xy, pending: &mut Vec<u64>) -> u64 {
        pending.clear();
        let n = self.n;
        let c = [
            (2 * self.s[0] + n).div_euclid(2 * n),
            (2 * self.s[1] + n).div_euclid(2 * n),
        ];
        let reach = (c[0] - self.lo[0])
            .max(self.hi[0] - c[0])
            .max(c[1] - self.lo[1])
            .max(self.hi[1] - c[1]);
        let mut count = 0u64;
        for shell in 0..=reach + 1 {
            if shell <= reach {
                for y in (c[1] - shell).max(self.lo[1])..=(c[1] + shell).min(self.hi[1]) {
                    let step = if (y - c[1]).abs() == shell {
                        1
                    } else {
                        2 * shell.max(1)
                    };
                    let mut x = c[0] - shell;
                    while x <= c[0] + shell {
                        if x >= self.lo[0] && x <= self.hi[0] {
                            pending.push(self.key([x, y]));
                        }
                        x += step;
                    }
                }
            }
            let bound = if shell <= reach {
                ((n * n * (2 * shell + 1) * (2 * shell + 1)) as u64) << 24
            } else {
                u64::MAX
            };
            // The smallest pending key each time: a scan, the list being short.
            while let Some((at, key)) = pending.iter().copied().enumerate().min_by_key(|&(_, k)| k)
            {
                if shell <= reach && (key >> 24) * 4 >= bound >> 24 {
                    break;
                }
                pending.swap_remove(at);
                let p = self.point(key);
                if self.holds(p) {
                    if p == new {
                        return count;
                    }
                    count += 1;
                }
            }
        }
        u64::MAX
    }
}

type Xy = [i64; 2];

fn cross(o: Xy, u: Xy, v: Xy) -> i64 {
    (u[0] - o[0]) * (v[1] - o[1]) - (u[1] - o[1]) * (v[0] - o[0])
}

/// `x` bounds of the closed counter-clockwise triangle `t` on row `y`.
fn row_span(t: [Xy; 3], y: i64) -> Option<(i64, i64)> {
    let (mut lo, mut hi) = (i64::MIN, i64::MAX);
    for i in 0..3 {
        let (u, v) = (t[i], t[(i + 1) % 3]);
        // cross(u, v, (x, y)) >= 0  <=>  dy x <= k
        let dy = v[1] - u[1];
        let k = (v[0] - u[0]) * (y - u[1]) + dy * u[0];
        match dy {
            0 if k < 0 => return None,
            0 => {}
            d if d > 0 => hi = hi.min(k.div_euclid(d)),
            // dy < 0: x >= ceil(k / dy) = -floor(k / -dy)
            d => lo = lo.max(-(k.div_euclid(-d))),
        }
    }
    (lo <= hi).then_some((lo, hi))
}

impl Observer {
    fn positions_first(
        &mut self,
        state: &MeshState<'_>,
        r: u32,
        ring: &Ring,
        rec: &SplitRecord,
        outward: bool,
    ) {
        let positions = state.positions();
        let xy = |v: u32| -> Option<Xy> {
            positions
                .get(v as usize)
                .map(|p| [p[0] as i64, p[1] as i64])
        };
        let Some(origin) = xy(r) else { return };
        let vertices = ring.vertices();
        let k = vertices.len();
        let mut entries = [None; MAX_SPLIT_VALENCE];
        for (e, &v) in entries.iter_mut().zip(vertices) {
            *e = if v == NONE { None } else { xy(v) };
        }
        let entries = &entries[..k];
        // The new vertex: C, or P where R sat on C.
        let new = if rec.position_c[..2] == positions[r as usize][..2] {
            [rec.position_p[0] as i64, rec.position_p[1] as i64]
        } else {
            [rec.position_c[0] as i64, rec.position_c[1] as i64]
        };
        // The fan's free lattice points, ordered by |n p - S|^2, then y, x.
        let (mut n, mut s) = (0i64, [0i64; 2]);
        let (mut lo, mut hi) = (origin, origin);
        for e in entries.iter().flatten() {
            n += 1;
            s = [s[0] + e[0], s[1] + e[1]];
            lo = [lo[0].min(e[0]), lo[1].min(e[1])];
            hi = [hi[0].max(e[0]), hi[1].max(e[1])];
        }
        let mut rank = u64::MAX;
        let in_cap = n > 0 && (hi[0] - lo[0] + 1) * (hi[1] - lo[1] + 1) <= CAP;
        if in_cap && outward {
            let fan = Fan {
                origin,
                entries,
                n,
                s,
                lo,
                hi,
            };
            rank = fan.outward_rank(new, &mut self.pending);
        } else if in_cap {
            self.candidates.clear();
            for i in 0..k {
                let (Some(a), Some(b)) = (entries[i], entries[(i + 1) % k]) else {
                    continue;
                };
                let t = match cross(origin, a, b) {
                    0 => continue, // no area: its points are on real wedges' edges
                    c if c > 0 => [origin, a, b],
                    _ => [origin, b, a],
                };
                let (y0, y1) = (t.iter().map(|p| p[1]).min(), t.iter().map(|p| p[1]).max());
                for y in y0.unwrap_or(0)..=y1.unwrap_or(-1) {
                    if let Some((x0, x1)) = row_span(t, y) {
                        for x in x0.max(lo[0])..=x1.min(hi[0]) {
                            let p = [x, y];
                            if p == origin || entries.contains(&Some(p)) {
                                continue;
                            }
                            let d = [n * x - s[0], n * y - s[1]];
                            let key = ((d[0] * d[0] + d[1] * d[1]) as u64) << 24
                                | ((y - lo[1]) as u64) << 12
                                | (x - lo[0]) as u64;
                            self.candidates.push(key);
                        }
                    }
                }
            }
            self.candidates.sort_unstable();
            self.candidates.dedup();
            if new[0] >= lo[0] && new[1] >= lo[1] {
                let d = [n * new[0] - s[0], n * new[1] - s[1]];
                let key = ((d[0] * d[0] + d[1] * d[1]) as u64) << 24
                    | ((new[1] - lo[1]) as u64) << 12
                    | (new[0] - lo[0]) as u64;
                rank = self
                    .candidates
                    .binary_search(&key)
                    .map_or(u64::MAX, |i| i as u64);
            }
        }
        // The wing pairs that keep every new triangle counter-clockwise.
        let ccw = |a: Option<Xy>, b: Option<Xy>, c: Option<Xy>| match (a, b, c) {
            (Some(a), Some(b), Some(c)) => cross(a, b, c) > 0,
            _ => true,
        };
        let mut visible = [false; MAX_SPLIT_VALENCE];
        let mut first_side = [false; MAX_SPLIT_VALENCE];
        let mut second_side = [false; MAX_SPLIT_VALENCE];
        for i in 0..k {
            visible[i] = ccw(Some(new), entries[i], entries[(i + 1) % k]);
            first_side[i] = ccw(Some(new), Some(origin), entries[i]);
            second_side[i] = ccw(Some(origin), Some(new), entries[i]);
        }
        let seen_by = |e: Option<Xy>| -> f64 {
            let Some(p) = e else { return 2.0 };
            let u = [(origin[0] - p[0]) as f64, (origin[1] - p[1]) as f64];
            let v = [(new[0] - p[0]) as f64, (new[1] - p[1]) as f64];
            let norm = (u[0] * u[0] + u[1] * u[1]).sqrt() * (v[0] * v[0] + v[1] * v[1]).sqrt();
            if norm == 0.0 {
                1.0
            } else {
                (u[0] * v[0] + u[1] * v[1]) / norm
            }
        };
        let (mut pairs, mut best) = (0u64, (f64::MAX, 0usize));
        for x in (0..k).filter(|&x| first_side[x]) {
            let mut t = x;
            while visible[t] {
                t = if t + 1 == k { 0 } else { t + 1 };
                if t == x {
                    break;
                }
                if second_side[t] && (entries[x].is_some() || entries[t].is_some()) {
                    pairs += 1;
                }
            }
            let angle = seen_by(entries[x]);
            if angle < best.0 {
                best = (angle, x);
            }
        }
        if rank != u64::MAX {
            self.found += 1;
            self.rank_sum += rank;
        }
        self.checksum = self
            .checksum
            .wrapping_mul(31)
            .wrapping_add(rank ^ pairs ^ best.1 as u64 ^ self.candidates.len() as u64);
    }

    fn replaced(&mut self, state: &MeshState<'_>, r: u32, ring: &Ring, rec: &SplitRecord) {
        let positions = state.positions();
        let eligible = state.wing_candidates(ring);
        let mut keys: NearKeys = [0; MAX_SPLIT_VALENCE];
        let m = near_keys(positions, ring, &eligible, WingPolicy::NearXy, &mut keys);
        let wings = near_wings(&keys[..m], ring.len(), 0, 0).unwrap_or((0, 1));
        let (o, d) = (rec.wing_offset as usize, rec.wing_distance as usize);
        let means = arc_means(positions, positions[r as usize], ring, o, d);
        self.checksum = self
            .checksum
            .wrapping_mul(31)
            .wrapping_add(wings.0 as u64 ^ means.count as u64);
    }
}

impl SplitObserver for Observer {
    fn record(&mut self, state: &MeshState<'_>, r: u32, ring: &Ring, rec: &SplitRecord) {
        self.splits += 1;
        match self.work {
            Work::None => {}
            Work::Replaced => self.replaced(state, r, ring, rec),
            Work::PositionsFirst => self.positions_first(state, r, ring, rec, false),
            Work::Outward => self.positions_first(state, r, ring, rec, true),
        }
    }
}

/// One whole decode under `observer`: seconds.
fn decode(stream: &[u8], observer: &mut Observer) -> Result<f64, Error> {
    let mut workspace = OwnedWorkspace::for_stream(stream)?;
    let started = Instant::now();
    let mut decoder = workspace.decoder(stream)?;
    while let Some(k) = decoder.next_level() {
        let bytes = decoder.level_bytes(k, stream)?;
        let mut level = decoder.begin_level(k, bytes)?;
        while level.next_round_observed(observer)?.is_some() {}
    }
    Ok(started.elapsed().as_secs_f64())
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let (input, runs) = match &args[..] {
        [_, input] => (input, 7),
        [_, input, runs] => (input, runs.parse().unwrap_or(7)),
        _ => {
            eprintln!("usage: positions_first_cost IN.sps [RUNS]");
            std::process::exit(2);
        }
    };
    let stream = std::fs::read(input).unwrap_or_else(|e| {
        eprintln!("positions_first_cost: {input}: {e}");
        std::process::exit(1)
    });
    let works = [
        ("none", Work::None),
        ("replaced", Work::Replaced),
        ("positions first", Work::PositionsFirst),
        ("outward", Work::Outward),
    ];
    let mut times = vec![Vec::new(); works.len()];
    let (mut splits, mut found) = (0, (0, 0));
    for _ in 0..runs {
        for (i, &(_, work)) in works.iter().enumerate() {
            let mut observer = Observer {
                work,
                checksum: 0,
                splits: 0,
                found: 0,
                rank_sum: 0,
                candidates: Vec::with_capacity(CAP as usize),
                pending: Vec::with_capacity(CAP as usize),
            };
            let seconds = decode(&stream, &mut observer).unwrap_or_else(|e| {
                eprintln!("positions_first_cost: {input}: {e}");
                std::process::exit(1)
            });
            times[i].push(seconds);
            splits = observer.splits;
            if work == Work::PositionsFirst {
                found = (observer.found, observer.rank_sum);
            }
            if work == Work::Outward && (observer.found, observer.rank_sum) != found {
                eprintln!(
                    "positions_first_cost: the outward search found {} new vertices (rank sum {}), the enumeration {found:?}",
                    observer.found, observer.rank_sum
                );
                std::process::exit(1);
            }
            std::hint::black_box(observer.checksum);
        }
    }
    let median = |t: &mut Vec<f64>| {
        t.sort_by(f64::total_cmp);
        t[t.len() / 2]
    };
    let base = median(&mut times[0]);
    println!(
        "{input}: {splits} splits ({:.1} % of the new vertices among the enumerated points), medians of {runs} decodes",
        100.0 * found.0 as f64 / splits.max(1) as f64
    );
    for (i, (name, _)) in works.iter().enumerate() {
        let t = median(&mut times[i]);
        println!(
            "  {name:<16} {:>9.1} ms   {:>+7.1} ns a split",
            t * 1e3,
            (t - base) * 1e9 / splits.max(1) as f64
        );
    }
}
