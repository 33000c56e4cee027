//! The candidate errors a step admits by (§2: the threshold S is raised to
//! a quantile of the current requests' errors), computed exactly and in
//! parallel. Gathering every live vertex's error and selecting in one
//! thread took about a third of a second's serial work on the 1M terrain,
//! while the other core idled. Here each part of the vertex list counts
//! its errors in a histogram of their leading bits, the counts give the
//! one bucket that holds the quantile, and only that bucket's errors are
//! gathered and selected from. The value is the one a selection over all
//! errors gives, in `f64::total_cmp` order.

use rayon::prelude::*;

/// Leading bits of an error's order key that pick its histogram bucket:
/// the sign, the exponent and four bits of the mantissa (sixteenths of an
/// octave), 256 KiB of counts per part.
const BUCKET_BITS: u32 = 16;

/// What a step needs from its candidates' errors.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Admission {
    /// The error of rank `floor((n - 1) * fraction)` among the `n` errors,
    /// from 0, in `f64::total_cmp` order.
    pub quantile: f64,
    /// The largest error (0 if none is larger).
    pub largest: f64,
    /// The smallest error above 0 (infinite if there is none).
    pub smallest_positive: f64,
}

/// The [`Admission`] of the errors `error(v)` gives for the items of
/// `items` (`None`: the item has no candidate), or `None` when none has
/// one. `fraction` is clamped to `0..=1`.
pub fn admission(
    items: &[u32],
    error: impl Fn(u32) -> Option<f64> + Sync,
    fraction: f64,
) -> Option<Admission> {
    if items.len() < GATHER_BELOW {
        gathered(items, &error, fraction)
    } else {
        by_histogram(items, &error, fraction)
    }
}

/// Below this many items a step gathers every error and selects from them
/// in one thread: zeroing and scanning the histograms' 256 KiB of counts
/// cost more than that (every step of a small mesh, and the last steps of a
/// large one: 5 of armadillo's 76 ms of simplification).
const GATHER_BELOW: usize = 1 << 14;

/// [`admission`] by one selection over all the errors.
fn gathered(
    items: &[u32],
    error: &impl Fn(u32) -> Option<f64>,
    fraction: f64,
) -> Option<Admission> {
    let mut all: Vec<f64> = items.iter().filter_map(|&v| error(v)).collect();
    if all.is_empty() {
        return None;
    }
    let rank = ((all.len() - 1) as f64 * fraction.clamp(0.0, 1.0)) as usize;
    let largest = all.iter().copied().fold(0.0, f64::max);
    let smallest_positive = all
        .iter()
        .copied()
        .filter(|&e| e > 0.0)
        .fold(f64::INFINITY, f64::min);
    let (_, quantile, _) = all.select_nth_unstable_by(rank, f64::total_cmp);
    Some(Admission {
        quantile: *quantile,
        largest,
        smallest_positive,
    })
}

/// [`admission`] in parallel parts, through histograms of the errors.
fn by_histogram(
    items: &[u32],
    error: &(impl Fn(u32) -> Option<f64> + Sync),
    fraction: f64,
) -> Option<Admission> {
    let part = items
        .len()
        .div_ceil(rayon::current_num_threads().max(1))
        .max(1 << 14);
    let counted: Vec<Counted> = items
        .par_chunks(part)
        .map(|chunk| Counted::of(chunk, error))
        .collect();
    let total: u64 = counted.iter().map(|c| c.count).sum();
    if total == 0 {
        return None;
    }
    let rank = ((total - 1) as f64 * fraction.clamp(0.0, 1.0)) as u64;
    // The bucket holding the error of rank `rank`, and the errors below it.
    let (mut bucket, mut below) = (0, 0u64);
    for b in 0..1usize << BUCKET_BITS {
        let here: u64 = counted.iter().map(|c| u64::from(c.histogram[b])).sum();
        if below + here > rank {
            bucket = b;
            break;
        }
        below += here;
    }
    let mut inside: Vec<f64> = items
        .par_chunks(part)
        .flat_map_iter(|chunk| {
            chunk
                .iter()
                .filter_map(|&v| error(v))
                .filter(|&e| bucket_of(e) == bucket)
        })
        .collect();
    let (_, quantile, _) = inside.select_nth_unstable_by((rank - below) as usize, f64::total_cmp);
    Some(Admission {
        quantile: *quantile,
        largest: counted.iter().map(|c| c.largest).fold(0.0, f64::max),
        smallest_positive: counted
            .iter()
            .map(|c| c.smallest_positive)
            .fold(f64::INFINITY, f64::min),
    })
}

/// One part's errors: how many, their histogram, their extremes.
struct Counted {
    count: u64,
    histogram: Vec<u32>,
    largest: f64,
    smallest_positive: f64,
}

impl Counted {
    fn of(items: &[u32], error: &impl Fn(u32) -> Option<f64>) -> Counted {
        let mut counted = Counted {
            count: 0,
            histogram: vec![0; 1 << BUCKET_BITS],
            largest: 0.0,
            smallest_positive: f64::INFINITY,
        };
        for e in items.iter().filter_map(|&v| error(v)) {
            counted.count += 1;
            counted.histogram[bucket_of(e)] += 1;
            counted.largest = counted.largest.max(e);
            if e > 0.0 {
                counted.smallest_positive = counted.smallest_positive.min(e);
            }
        }
        counted
    }
}

/// The histogram bucket of `x`: the leading bits of a key whose unsigned
/// order is `f64::total_cmp`'s (negative values' bits inverted, the sign
/// bit of the others set).
fn bucket_of(x: f64) -> usize {
    let bits = x.to_bits();
    let key = if bits >> 63 == 1 {
        !bits
    } else {
        bits | 1 << 63
    };
    (key >> (64 - BUCKET_BITS)) as usize
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Both paths give what one selection over every error gives (the
    /// gathering path is that selection), and so does `admission`.
    fn check(errors: &[Option<f64>], fraction: f64) {
        let items: Vec<u32> = (0..errors.len() as u32).collect();
        let error = |v: u32| errors[v as usize];
        let want = gathered(&items, &error, fraction);
        assert_eq!(admission(&items, error, fraction), want);
        let got = by_histogram(&items, &error, fraction);
        match (got, want) {
            (Some(g), Some(w)) => {
                assert_eq!(g.quantile.to_bits(), w.quantile.to_bits(), "{fraction}");
                // (The sign of a zero maximum is the fold's own business.)
                assert_eq!(g.largest, w.largest);
                assert_eq!(g.smallest_positive.to_bits(), w.smallest_positive.to_bits());
            }
            (g, w) => assert_eq!(g, w),
        }
    }

    fn pseudo_random(seed: u64) -> impl FnMut() -> u64 {
        let mut x = seed | 1;
        move || {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            x
        }
    }

    #[test]
    fn the_quantile_is_the_serial_selections() {
        let mut next = pseudo_random(7);
        for n in [1usize, 2, 3, 100, 40_000, 100_000] {
            // Spread over many octaves, with repeats, zeros and items
            // without a candidate.
            let errors: Vec<Option<f64>> = (0..n)
                .map(|_| match next() % 10 {
                    0 => None,
                    1 => Some(0.0),
                    2 => Some(1.5),
                    _ => Some(f64::from_bits(next() % (1023 << 52)) * 1e-3),
                })
                .collect();
            for fraction in [0.0, 0.25, 0.5, 0.75, 1.0, 1.5, -1.0] {
                check(&errors, fraction);
            }
        }
    }

    #[test]
    fn one_crowded_bucket_and_signed_values() {
        let mut next = pseudo_random(11);
        // Most errors within one sixteenth of an octave: the selection
        // inside the bucket decides.
        let errors: Vec<Option<f64>> = (0..50_000)
            .map(|i| match i % 50 {
                0 => Some(-((next() % 1000) as f64)),
                1 => Some(-0.0),
                _ => Some(1.0 + (next() % 1000) as f64 * 1e-6),
            })
            .collect();
        for fraction in [0.0, 0.01, 0.02, 0.03, 0.5, 0.99, 1.0] {
            check(&errors, fraction);
        }
    }

    #[test]
    fn no_candidate_gives_none() {
        check(&[None, None], 0.5);
        check(&[], 0.5);
    }
}
