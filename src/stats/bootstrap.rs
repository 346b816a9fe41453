//! Deterministic resampling for bootstrap confidence intervals.
//!
//! The generator is SplitMix64 (Steele, Lea & Flood 2014, "Fast splittable pseudorandom
//! number generators", OOPSLA): 64 bits of state, passes BigCrush, and, unlike the `rand`
//! crates, its stream is fixed by this file, so a campaign's statistics are reproducible
//! bit for bit from the seed across versions and platforms.

use super::summary::percentile;

/// SplitMix64 pseudorandom generator.
#[derive(Clone, Debug)]
pub(crate) struct SplitMix64(u64);

impl SplitMix64 {
    /// A generator whose stream is fixed by `seed`.
    pub(crate) fn new(seed: u64) -> Self {
        Self(seed)
    }

    /// The next 64 random bits.
    pub(crate) fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform index in `0..n` (0 for `n = 0`) by Lemire's multiply-shift; the bias,
    /// below `n / 2⁶⁴`, is immaterial for any sample that fits in memory.
    pub(crate) fn below(&mut self, n: usize) -> usize {
        ((u128::from(self.next_u64()) * n as u128) >> 64) as usize
    }
}

/// Percentile bootstrap interval (Efron & Tibshirani 1993, "An Introduction to the
/// Bootstrap", §13.3): the `(1 − level)/2` and `(1 + level)/2` type-7 percentiles of the
/// finite replicates. Non-finite replicates (a degenerate resample) are dropped; NaN bounds
/// when none remain or `level` is outside `(0, 1)`. Sorts `replicates` in place.
pub(crate) fn percentile_interval(replicates: &mut Vec<f64>, level: f64) -> (f64, f64) {
    if !(level > 0.0 && level < 1.0) {
        return (f64::NAN, f64::NAN);
    }
    replicates.retain(|v| v.is_finite());
    replicates.sort_by(f64::total_cmp);
    let half = (1.0 - level) / 2.0;
    (
        percentile(replicates, half),
        percentile(replicates, 1.0 - half),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn splitmix64_reference_stream() {
        // Reference output of Vigna's splitmix64.c seeded with 0.
        let mut rng = SplitMix64::new(0);
        assert_eq!(rng.next_u64(), 0xE220_A839_7B1D_CDAF);
        assert_eq!(rng.next_u64(), 0x6E78_9E6A_A1B9_65F4);
        let mut rng = SplitMix64::new(7);
        assert!((0..1000).all(|_| rng.below(3) < 3));
        assert_eq!(rng.below(0), 0);
    }

    #[test]
    fn percentile_interval_drops_non_finite() {
        let mut v: Vec<f64> = (0..=100).rev().map(f64::from).collect();
        v.push(f64::NAN);
        let (lo, hi) = percentile_interval(&mut v, 0.9);
        assert!(
            (lo - 5.0).abs() < 1e-12 && (hi - 95.0).abs() < 1e-12,
            "{lo} {hi}"
        );
        let (lo, hi) = percentile_interval(&mut vec![f64::NAN], 0.9);
        assert!(lo.is_nan() && hi.is_nan());
        let (lo, hi) = percentile_interval(&mut vec![1.0, 2.0], 1.0);
        assert!(lo.is_nan() && hi.is_nan());
    }
}
