//! SplitMix64 (Steele, Lea & Flood 2014), used counter-style: value `i` of a
//! stream is a pure function of `(seed, i)`, so samples can be drawn in
//! parallel in any order and still come out identical on every run.

const GAMMA: u64 = 0x9E37_79B9_7F4A_7C15;

/// The `i`-th output of the SplitMix64 sequence started at `seed`.
pub fn splitmix64(seed: u64, i: u64) -> u64 {
    let mut z = seed.wrapping_add(i.wrapping_add(1).wrapping_mul(GAMMA));
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// The `i`-th value of the stream as a float uniform in `[0, 1)`.
pub fn unit(seed: u64, i: u64) -> f64 {
    (splitmix64(seed, i) >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn matches_the_reference_sequence() {
        // First outputs of the reference splitmix64 seeded with 1234567.
        assert_eq!(splitmix64(1234567, 0), 6457827717110365317);
        assert_eq!(splitmix64(1234567, 1), 3203168211198807973);
    }

    #[test]
    fn unit_floats_stay_in_range() {
        let mean = (0..10_000)
            .map(|i| unit(7, i))
            .inspect(|u| assert!((0.0..1.0).contains(u)))
            .sum::<f64>()
            / 10_000.0;
        assert!((mean - 0.5).abs() < 0.02);
    }
}
