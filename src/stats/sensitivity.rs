//! Global sensitivity measures: Spearman rank correlation between a sampled
//! input and a QoI, and variance-based Sobol indices from a Saltelli design.
//!
//! Spearman's ρ is cheap, needs no special design and captures any monotone
//! dependence, which makes it the default screening measure for a plain Monte
//! Carlo campaign. Sobol indices need the A/B/AB_i design of Saltelli (2002,
//! 2010) but apportion the output variance exactly, including interaction
//! effects (total-effect index).

/// Spearman rank correlation coefficient of paired values.
///
/// Pairs in which either member is non-finite (NaN or ±∞) are dropped; the
/// remaining values are replaced by their ranks (1-based, ties receiving the
/// average of the ranks they span) and the Pearson correlation of the ranks is
/// returned, which is the tie-corrected definition of Spearman (1904) used by
/// `scipy.stats.spearmanr`.
///
/// Returns NaN when `x` and `y` differ in length, when fewer than 3 valid
/// pairs remain, or when either column is constant (zero rank variance).
pub fn spearman(x: &[f64], y: &[f64]) -> f64 {
    if x.len() != y.len() {
        return f64::NAN;
    }
    let (xs, ys): (Vec<f64>, Vec<f64>) = x
        .iter()
        .zip(y)
        .filter(|(a, b)| a.is_finite() && b.is_finite())
        .map(|(&a, &b)| (a, b))
        .unzip();
    if xs.len() < 3 {
        return f64::NAN;
    }
    pearson(&average_ranks(&xs), &average_ranks(&ys))
}

/// 1-based ranks of finite values, ties receiving their average rank.
fn average_ranks(values: &[f64]) -> Vec<f64> {
    let mut order: Vec<usize> = (0..values.len()).collect();
    order.sort_by(|&i, &j| values[i].total_cmp(&values[j]));
    let mut ranks = vec![0.0; values.len()];
    let mut start = 0;
    while start < order.len() {
        let value = values[order[start]];
        let mut end = start + 1;
        while end < order.len() && values[order[end]] == value {
            end += 1;
        }
        // Positions start..end (0-based) hold ranks start+1 ..= end.
        let rank = (start + 1 + end) as f64 / 2.0;
        for &idx in &order[start..end] {
            ranks[idx] = rank;
        }
        start = end;
    }
    ranks
}

/// Pearson correlation of two equally long slices; NaN if either is constant.
fn pearson(x: &[f64], y: &[f64]) -> f64 {
    let n = x.len() as f64;
    let mx = x.iter().sum::<f64>() / n;
    let my = y.iter().sum::<f64>() / n;
    let (mut sxy, mut sxx, mut syy) = (0.0, 0.0, 0.0);
    for (a, b) in x.iter().zip(y) {
        let (dx, dy) = (a - mx, b - my);
        sxy += dx * dy;
        sxx += dx * dx;
        syy += dy * dy;
    }
    if sxx <= 0.0 || syy <= 0.0 {
        return f64::NAN;
    }
    (sxy / (sxx.sqrt() * syy.sqrt())).clamp(-1.0, 1.0)
}

/// First-order and total-effect Sobol indices of one input; result of
/// [`sobol_indices`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SobolIndices {
    /// First-order (main-effect) index `S_i = V[E(Y|X_i)] / V(Y)`.
    pub first: f64,
    /// Total-effect index `ST_i = E[V(Y|X_~i)] / V(Y)`, including all
    /// interactions involving input `i`.
    pub total: f64,
}

/// First-order and total-effect Sobol indices of one input from a Saltelli
/// design.
///
/// `f_a[b]` and `f_b[b]` are the model outputs at rows `b` of the independent
/// sample matrices A and B, and `f_ab[b]` the output at row `b` of `AB_i`
/// (A with column `i` taken from B). Estimators, following Saltelli et al.
/// (2010), "Variance based sensitivity analysis of model output", Table 2
/// (also SALib's `sobol.analyze`):
///
/// * first order (Saltelli 2010): `S_i = mean(f_b (f_ab − f_a)) / V`
/// * total effect (Jansen 1999): `ST_i = mean((f_a − f_ab)²) / (2 V)`
///
/// where `V` is the population variance (denominator `2N`) of the pooled A
/// and B outputs. A base sample `b` with any non-finite output (a diverged or
/// missing instance) is dropped from all three sums, so `N` counts the
/// remaining complete bases.
///
/// Both indices are NaN when the three slices differ in length, fewer than 2
/// complete bases remain, or the output variance is zero. Sampling error can
/// make estimates fall slightly outside `[0, 1]`; they are not clipped.
pub fn sobol_indices(f_a: &[f64], f_b: &[f64], f_ab: &[f64]) -> SobolIndices {
    let nan = SobolIndices {
        first: f64::NAN,
        total: f64::NAN,
    };
    if f_a.len() != f_b.len() || f_a.len() != f_ab.len() {
        return nan;
    }
    let bases: Vec<(f64, f64, f64)> = f_a
        .iter()
        .zip(f_b)
        .zip(f_ab)
        .map(|((&a, &b), &ab)| (a, b, ab))
        .filter(|(a, b, ab)| a.is_finite() && b.is_finite() && ab.is_finite())
        .collect();
    if bases.len() < 2 {
        return nan;
    }
    let n = bases.len() as f64;

    // Pooled variance of the A and B outputs (two-pass for accuracy).
    let mean = bases.iter().map(|(a, b, _)| a + b).sum::<f64>() / (2.0 * n);
    let var = bases
        .iter()
        .map(|(a, b, _)| (a - mean) * (a - mean) + (b - mean) * (b - mean))
        .sum::<f64>()
        / (2.0 * n);
    if !(var > 0.0 && var.is_finite()) {
        return nan;
    }

    let first = bases.iter().map(|(a, b, ab)| b * (ab - a)).sum::<f64>() / n / var;
    let total = bases
        .iter()
        .map(|(a, _, ab)| (a - ab) * (a - ab))
        .sum::<f64>()
        / n
        / (2.0 * var);
    SobolIndices { first, total }
}
