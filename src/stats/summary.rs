//! Descriptive statistics and exceedance probabilities of one QoI column.
//!
//! Percentiles use the linear-interpolation ("type 7") definition of
//! Hyndman & Fan (1996), the default of numpy and R and identical to DuckDB's
//! `quantile_cont`, so numbers in `statistics.parquet` can be reproduced from
//! the raw per-instance table with any of those tools. Exceedance
//! probabilities carry the exact Clopper & Pearson (1934) binomial interval,
//! which stays valid (conservative) for the tiny probabilities a dispersion
//! campaign is usually about, where normal-approximation intervals fail.

use super::beta::beta_quantile;

/// One tidy row of `statistics.parquet`.
///
/// `threshold`, `ci_low` and `ci_high` are NaN where not applicable (e.g. a
/// mean has no threshold and no interval). `n` is the number of finite values
/// the statistic was computed from, after diverged instances and missing
/// (NaN) entries were excluded.
#[derive(Clone, Debug, PartialEq)]
pub struct StatRow {
    /// Name of the quantity of interest, e.g. `peak_pressure_pa`.
    pub quantity: String,
    /// Name of the statistic, e.g. `mean`, `std`, `p99`, `p_above`.
    pub statistic: String,
    /// Threshold the statistic refers to (exceedance rows); NaN otherwise.
    pub threshold: f64,
    /// Value of the statistic; NaN when it is undefined (e.g. no data).
    pub value: f64,
    /// Lower bound of the confidence interval; NaN when there is none.
    pub ci_low: f64,
    /// Upper bound of the confidence interval; NaN when there is none.
    pub ci_high: f64,
    /// Number of values the statistic was computed from.
    pub n: u64,
}

/// Percentiles reported by [`describe`], as `(statistic name, probability)`:
/// the 1 %, 5 %, 50 %, 95 % and 99 % points, i.e. the median plus the two
/// tails customarily quoted for dispersion results (3σ ≈ p01/p99 bands).
pub const PERCENTILES: [(&str, f64); 5] = [
    ("p01", 0.01),
    ("p05", 0.05),
    ("p50", 0.50),
    ("p95", 0.95),
    ("p99", 0.99),
];

/// Percentile of sorted data with linear interpolation between order
/// statistics.
///
/// This is Hyndman & Fan's "type 7" estimator, numpy's default
/// (`method="linear"`) and identical to DuckDB's `quantile_cont`: with
/// `h = (n − 1) p`, the result is
/// `x[⌊h⌋] + (h − ⌊h⌋) (x[⌊h⌋ + 1] − x[⌊h⌋])` (0-based indices).
///
/// `sorted` must be sorted ascending and contain no NaN; this is not checked
/// (the result is then meaningless but no panic occurs). `p` is a probability
/// in `[0, 1]`, not a percentage. Returns NaN for an empty slice or a `p`
/// outside `[0, 1]` (including NaN).
pub fn percentile(sorted: &[f64], p: f64) -> f64 {
    let n = sorted.len();
    if n == 0 || !(0.0..=1.0).contains(&p) {
        return f64::NAN;
    }
    let h = (n - 1) as f64 * p;
    let lo_f = h.floor();
    // `h` lies in [0, n − 1], so the cast is exact and in range; `min` guards
    // against any rounding surprise.
    let lo = (lo_f as usize).min(n - 1);
    let frac = h - lo_f;
    match sorted.get(lo + 1) {
        Some(&hi) if frac > 0.0 => sorted[lo] + frac * (hi - sorted[lo]),
        _ => sorted[lo],
    }
}

/// Mean, sample standard deviation, min, max and [`PERCENTILES`] of a column.
///
/// Only finite values are used: NaN (missing) and ±∞ entries are skipped,
/// since a single infinity would make the mean and standard deviation
/// meaningless; a diverged or overflowing instance should be flagged by the
/// caller rather than folded into the moments. Every returned row has
/// `n` = number of finite values used, and NaN `threshold`, `ci_low` and
/// `ci_high`.
///
/// Rows, in order, have statistic names `mean`, `std`, `min`, `max`, `p01`,
/// `p05`, `p50`, `p95`, `p99`. The standard deviation uses the `n − 1`
/// (sample) denominator and is NaN for `n < 2`; everything is NaN for
/// `n = 0`. The mean is computed in two passes (with a correction term) for
/// accuracy. The input is not modified; a finite copy is sorted.
pub fn describe(quantity: &str, values: &[f64]) -> Vec<StatRow> {
    let mut data: Vec<f64> = values.iter().copied().filter(|v| v.is_finite()).collect();
    data.sort_by(f64::total_cmp);
    let n = data.len();

    let (mean, std) = mean_std(&data);
    let (min, max) = match (data.first(), data.last()) {
        (Some(&lo), Some(&hi)) => (lo, hi),
        _ => (f64::NAN, f64::NAN),
    };

    let row = |statistic: &str, value: f64| StatRow {
        quantity: quantity.to_string(),
        statistic: statistic.to_string(),
        threshold: f64::NAN,
        value,
        ci_low: f64::NAN,
        ci_high: f64::NAN,
        n: n as u64,
    };

    let mut rows = Vec::with_capacity(4 + PERCENTILES.len());
    rows.push(row("mean", mean));
    rows.push(row("std", std));
    rows.push(row("min", min));
    rows.push(row("max", max));
    for (name, p) in PERCENTILES {
        rows.push(row(name, percentile(&data, p)));
    }
    rows
}

/// Mean and sample (n − 1) standard deviation of finite data.
fn mean_std(data: &[f64]) -> (f64, f64) {
    let n = data.len();
    if n == 0 {
        return (f64::NAN, f64::NAN);
    }
    let nf = n as f64;
    let naive = data.iter().sum::<f64>() / nf;
    // Second pass: correct the mean for rounding in the first sum.
    let mean = naive + data.iter().map(|v| v - naive).sum::<f64>() / nf;
    if n < 2 {
        return (mean, f64::NAN);
    }
    let ss: f64 = data.iter().map(|v| (v - mean) * (v - mean)).sum();
    (mean, (ss / (nf - 1.0)).sqrt())
}

/// Side of a threshold an exceedance probability refers to.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Direction {
    /// Count values strictly greater than the threshold (e.g. overpressure).
    Above,
    /// Count values strictly less than the threshold (e.g. cavitation margin).
    Below,
}

/// Estimated probability of exceeding a threshold, with its confidence
/// interval; result of [`exceedance`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Exceedance {
    /// Number of values beyond the threshold.
    pub k: u64,
    /// Number of finite values considered.
    pub n: u64,
    /// Point estimate `k / n`; NaN when `n = 0`.
    pub p: f64,
    /// Lower Clopper–Pearson bound; NaN when `n = 0` or the level is invalid.
    pub ci_low: f64,
    /// Upper Clopper–Pearson bound; NaN when `n = 0` or the level is invalid.
    pub ci_high: f64,
}

/// Probability that a value lies strictly above (or strictly below)
/// `threshold`, with the exact two-sided Clopper–Pearson interval.
///
/// With `α = 1 − level`, `k` hits out of `n` finite values (NaN and ±∞ are
/// skipped, consistently with [`describe`]):
/// `low = Beta⁻¹(α/2; k, n − k + 1)` (0 when `k = 0`) and
/// `high = Beta⁻¹(1 − α/2; k + 1, n − k)` (1 when `k = n`), evaluated by bisection on the
/// regularized incomplete beta. Clopper & Pearson (1934); the interval is
/// exact in the sense that its coverage is never below `level`, which makes
/// it the appropriate choice for rare-event probabilities where a Wald
/// interval collapses to zero width.
///
/// `level` is a confidence level such as `0.95` and must lie strictly
/// between 0 and 1; otherwise `ci_low`/`ci_high` are NaN (the point estimate
/// is still returned). With no finite values (`n = 0`), or a NaN threshold,
/// `p` and the interval are NaN.
pub fn exceedance(values: &[f64], threshold: f64, direction: Direction, level: f64) -> Exceedance {
    let finite = values.iter().copied().filter(|v| v.is_finite());
    let (k, n) = finite.fold((0u64, 0u64), |(k, n), v| {
        let hit = match direction {
            Direction::Above => v > threshold,
            Direction::Below => v < threshold,
        };
        (k + u64::from(hit), n + 1)
    });
    if n == 0 || threshold.is_nan() {
        return Exceedance {
            k,
            n,
            p: f64::NAN,
            ci_low: f64::NAN,
            ci_high: f64::NAN,
        };
    }
    let (ci_low, ci_high) = clopper_pearson(k, n, level);
    Exceedance {
        k,
        n,
        p: k as f64 / n as f64,
        ci_low,
        ci_high,
    }
}

/// Exact two-sided Clopper–Pearson interval for `k` successes in `n > 0`
/// trials; NaN bounds for an invalid `level` or `k > n`.
pub fn clopper_pearson(k: u64, n: u64, level: f64) -> (f64, f64) {
    if !(level > 0.0 && level < 1.0) || k > n || n == 0 {
        return (f64::NAN, f64::NAN);
    }
    let alpha = 1.0 - level;
    let (kf, nf) = (k as f64, n as f64);
    let low = if k == 0 {
        0.0
    } else {
        beta_quantile(kf, nf - kf + 1.0, alpha / 2.0)
    };
    let high = if k == n {
        1.0
    } else {
        beta_quantile(kf + 1.0, nf - kf, 1.0 - alpha / 2.0)
    };
    (low, high)
}
