//! Distribution-free confidence intervals for quantiles from order statistics, and the test
//! for a column too constant to carry any sensitivity information.
//!
//! For a continuous distribution the number of sample values at or below the true p-quantile
//! `ξ_p` is `Binom(n, p)`, whatever the distribution; an interval between two order
//! statistics therefore has an exact coverage that depends only on `n`, `p` and the chosen
//! ranks (Thompson 1936; Conover, "Practical Nonparametric Statistics", 3rd ed., §3.2;
//! Hahn & Meeker, "Statistical Intervals", 1991, §5.2). This is what a Monte Carlo campaign
//! needs for its percentiles: no normality assumption, valid in the tails.

use super::beta::binom_cdf;

/// Distribution-free two-sided confidence interval for the `p`-quantile `ξ_p` of the
/// distribution `sorted` was drawn from.
///
/// With `α = 1 − level` and `F(k) = P(Binom(n, p) ≤ k)`, the lower bound is the order
/// statistic `X_(l)` (1-based) with the largest `l` such that `P(X_(l) > ξ_p) = F(l − 1) ≤ α/2`,
/// the upper bound `X_(u)` with the smallest `u` such that
/// `P(X_(u) < ξ_p) = 1 − F(u − 1) ≤ α/2`. Each tail thus misses with probability at most
/// `α/2` (equal-tailed as far as the discrete ranks allow) and
/// `P(X_(l) ≤ ξ_p ≤ X_(u)) = F(u − 1) − F(l − 1) ≥ level`, always with `l < u`.
/// Hahn & Meeker (1991) §5.2; Conover (1999) §3.2. `F` is evaluated through the regularized
/// incomplete beta, `F(k) = I_{1−p}(n − k, k + 1)`, and `l`, `u` are found by bisection on
/// `k`, so `n` = 10⁷ takes milliseconds.
///
/// `sorted` must be sorted ascending and finite (not checked; no panic either way); `p` is a
/// probability in `(0, 1)` (not a percentage), `level` a confidence level in `(0, 1)` such as
/// 0.95. The bounds are in the units of the data.
///
/// Returns `(low, high)`. A bound is NaN when no order statistic of this `n` qualifies:
/// the lower one when `(1 − p)ⁿ > α/2`, the upper one when `pⁿ > α/2` (for instance the upper
/// bound of the 99 % point needs `n ≥ 368` at 95 %); the other bound may still exist, and the
/// missing one then means an unbounded side. See [`quantile_interval_min_n`]. Both are NaN for
/// an empty slice or `p` or `level` outside `(0, 1)`.
pub fn quantile_interval(sorted: &[f64], p: f64, level: f64) -> (f64, f64) {
    let n = sorted.len() as u64;
    let (l, u) = quantile_interval_ranks(n, p, level);
    let at = |rank: u64| match rank {
        0 => f64::NAN,
        r => sorted.get((r - 1) as usize).copied().unwrap_or(f64::NAN),
    };
    (at(l), at(u))
}

/// The 1-based ranks `(l, u)` of [`quantile_interval`]; 0 where the bound does not exist.
fn quantile_interval_ranks(n: u64, p: f64, level: f64) -> (u64, u64) {
    if n == 0 || !(p > 0.0 && p < 1.0) || !(level > 0.0 && level < 1.0) {
        return (0, 0);
    }
    let half = (1.0 - level) / 2.0;
    let cdf = |k: u64| binom_cdf(k, n, p);
    // Lower: the largest k in [0, n − 1] with F(k) ≤ α/2, then l = k + 1.
    let l = if cdf(0) <= half {
        // F is non-decreasing and F(lo) ≤ α/2 throughout: the last such k lies in [lo, hi].
        let (mut lo, mut hi) = (0u64, n - 1);
        while lo < hi {
            let mid = lo + (hi - lo).div_ceil(2);
            if cdf(mid) <= half {
                lo = mid;
            } else {
                hi = mid - 1;
            }
        }
        lo + 1
    } else {
        0
    };
    // Upper: the smallest k in [0, n − 1] with F(k) ≥ 1 − α/2, then u = k + 1.
    let u = if cdf(n - 1) >= 1.0 - half {
        let (mut lo, mut hi) = (0u64, n - 1);
        while lo < hi {
            let mid = lo + (hi - lo) / 2;
            if cdf(mid) >= 1.0 - half {
                hi = mid;
            } else {
                lo = mid + 1;
            }
        }
        lo + 1
    } else {
        0
    };
    (l, u)
}

/// Smallest sample size for which both bounds of [`quantile_interval`] exist.
///
/// The lower bound needs `(1 − p)ⁿ ≤ α/2` and the upper `pⁿ ≤ α/2` with `α = 1 − level`, so
/// this is the smallest `n ≥ ln(α/2) / ln(max(p, 1 − p))` (checked against the same binomial
/// terms [`quantile_interval`] uses, so the two agree at the boundary). For example 6 for the
/// median, 36 for the 90 % point, 72 for the 95 % point and 368 for the 99 % point, all at 95 %.
///
/// Returns 0 (never a valid answer) for `p` or `level` outside `(0, 1)`; saturates at
/// `u64::MAX` for `p` so close to 0 or 1 that no representable `n` suffices.
pub fn quantile_interval_min_n(p: f64, level: f64) -> u64 {
    if !(p > 0.0 && p < 1.0 && level > 0.0 && level < 1.0) {
        return 0;
    }
    let half = (1.0 - level) / 2.0;
    let both = |n: u64| binom_cdf(0, n, p) <= half && binom_cdf(n - 1, n, p) >= 1.0 - half;
    // ln max(p, 1 − p), without forming 1 − p.
    let ln_worst = p.ln().max((-p).ln_1p());
    let guess = (half.ln() / ln_worst).ceil();
    if guess >= 1.8e19 {
        return u64::MAX;
    }
    let mut n = (guess as u64).max(1);
    while n > 1 && both(n - 1) {
        n -= 1;
    }
    while !both(n) {
        match n.checked_add(1) {
            Some(next) => n = next,
            None => return u64::MAX,
        }
    }
    n
}

/// Whether a column is constant to rounding, so that ranks, variances and sensitivity indices
/// computed from it would only describe floating-point noise.
///
/// True when `max − min ≤ 1e-9 · max(|max|, |min|)` or `max − min ≤ f64::MIN_POSITIVE`, with
/// `min = sorted[0]` and `max = sorted[n − 1]` (O(1): only the ends of the sorted column are
/// read). A peak pressure of 3e5 Pa with a spread of 3.4e-10 Pa, a relief valve capping every
/// instance at its crack pressure, is constant; 1e-9 is about 10⁷ ulps, well above the
/// rounding a long integration accumulates and far below any physical spread.
///
/// `sorted` must be sorted ascending and finite. An empty or one-element column is constant
/// (true); a column whose ends are not finite is not (false).
pub fn is_constant(sorted: &[f64]) -> bool {
    let (Some(&min), Some(&max)) = (sorted.first(), sorted.last()) else {
        return true;
    };
    let spread = max - min;
    if !spread.is_finite() {
        return false;
    }
    spread <= 1e-9 * max.abs().max(min.abs()) || spread <= f64::MIN_POSITIVE
}
