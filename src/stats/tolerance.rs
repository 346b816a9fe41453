//! Wilks one-sided nonparametric tolerance bounds: which order statistic of a Monte Carlo
//! sample bounds a given fraction of the population with a given confidence.
//!
//! The fraction of a continuous population lying above the m-th largest of `n` values is
//! `Beta(m, n − m + 1)`-distributed whatever the population (Wilks 1941), so the order
//! statistic to quote depends only on `n`, the coverage and the confidence. This is the
//! "95/95" rule of nuclear-safety uncertainty analysis (59 runs: the maximum); see Nutt &
//! Wallis (2004), "Evaluation of nuclear safety from the outputs of computer codes in the
//! presence of uncertainties", Reliab. Eng. Syst. Saf. 83, 57–77.

use super::beta::binom_cdf;

/// Which side of the population a tolerance bound limits.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Side {
    /// An upper bound: at least the coverage fraction of the population lies below it
    /// (e.g. a peak pressure).
    Upper,
    /// A lower bound: at least the coverage fraction of the population lies above it
    /// (e.g. a cavitation margin).
    Lower,
}

/// A one-sided nonparametric tolerance bound; result of [`tolerance_bound`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Tolerance {
    /// The bound, in the units of the data: the `order`-th largest value (upper) or
    /// `order`-th smallest (lower); NaN when no order statistic qualifies.
    pub value: f64,
    /// `m`, 1 for the extreme itself; 0 when no order statistic qualifies.
    pub order: u64,
    /// Number of values the bound was chosen from.
    pub n: u64,
    /// The exact confidence `P(Binom(n, 1 − coverage) ≥ m)` of the chosen order statistic,
    /// at least the requested confidence; NaN when no order statistic qualifies.
    pub achieved_confidence: f64,
}

/// Wilks one-sided nonparametric tolerance bound of a sample: a value that at least a fraction
/// `coverage` (γ) of the population lies below (upper) or above (lower), with confidence
/// `confidence` (β).
///
/// The m-th largest of `n` values qualifies as an upper bound when the number of sample values
/// beyond the population's γ-quantile, `Binom(n, 1 − γ)`, is at least `m` with probability β:
/// `P(Binom(n, 1 − γ) ≥ m) ≥ β` (Wilks 1941; Nutt & Wallis 2004). The largest such
/// `m` is chosen, the least conservative bound this sample supports; the lower bound is the
/// mirror image (m-th smallest). Holds for any continuous distribution.
///
/// `sorted` must be sorted ascending and finite (not checked; no panic either way);
/// `coverage` and `confidence` are probabilities in `(0, 1)`, e.g. 0.95 and 0.95.
///
/// When even the extreme does not qualify (`n` < [`wilks_min_samples`]`(γ, β, 1)`, e.g.
/// `n < 59` at 95/95), or `coverage` or `confidence` is outside `(0, 1)`, the result has
/// `value` NaN, `order` 0 and `achieved_confidence` NaN.
pub fn tolerance_bound(sorted: &[f64], coverage: f64, confidence: f64, side: Side) -> Tolerance {
    let n = sorted.len() as u64;
    let none = Tolerance {
        value: f64::NAN,
        order: 0,
        n,
        achieved_confidence: f64::NAN,
    };
    if n == 0 || !valid(coverage) || !valid(confidence) {
        return none;
    }
    let q = 1.0 - coverage;
    // P(Binom(n, q) ≥ m) = 1 − F(m − 1): m qualifies iff F(m − 1) ≤ 1 − β, and F is
    // non-decreasing, so the qualifying m form a prefix 1..=m_max.
    let miss = 1.0 - confidence;
    let cdf = |k: u64| binom_cdf(k, n, q);
    if cdf(0) > miss {
        return none;
    }
    let (mut lo, mut hi) = (0u64, n - 1);
    while lo < hi {
        let mid = lo + (hi - lo).div_ceil(2);
        if cdf(mid) <= miss {
            lo = mid;
        } else {
            hi = mid - 1;
        }
    }
    let m = lo + 1;
    let index = match side {
        Side::Upper => n - m,
        Side::Lower => m - 1,
    };
    Tolerance {
        value: sorted.get(index as usize).copied().unwrap_or(f64::NAN),
        order: m,
        n,
        achieved_confidence: 1.0 - cdf(lo),
    }
}

/// Smallest sample size `n` for which the `order`-th extreme (largest for an upper bound,
/// smallest for a lower one) is a (`coverage`, `confidence`) tolerance bound, i.e.
/// `P(Binom(n, 1 − coverage) ≥ order) ≥ confidence` (Wilks 1941; Nutt & Wallis 2004).
///
/// Order 1 gives `1 − γⁿ ≥ β`: 59 at 95/95, 230 at 99/90; order 2 at 95/95 gives 93.
/// Returns 0 (never a valid answer) for `order` 0 or `coverage` or `confidence` outside
/// `(0, 1)`; saturates at `u64::MAX` when no representable `n` suffices.
pub fn wilks_min_samples(coverage: f64, confidence: f64, order: u64) -> u64 {
    if order == 0 || !valid(coverage) || !valid(confidence) {
        return 0;
    }
    let (q, miss) = (1.0 - coverage, 1.0 - confidence);
    let ok = |n: u64| n >= order && binom_cdf(order - 1, n, q) <= miss;
    // The confidence grows with n: double to bracket, then bisect.
    let mut hi = order;
    while !ok(hi) {
        match hi.checked_mul(2) {
            Some(next) if next <= (1u64 << 53) => hi = next,
            _ => return u64::MAX,
        }
    }
    let mut lo = order; // ok(lo − 1) is false: fewer than `order` values have no such statistic.
    while lo < hi {
        let mid = lo + (hi - lo) / 2;
        if ok(mid) {
            hi = mid;
        } else {
            lo = mid + 1;
        }
    }
    lo
}

/// A probability strictly between 0 and 1 (false for NaN).
fn valid(p: f64) -> bool {
    p > 0.0 && p < 1.0
}
