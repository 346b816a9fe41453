//! Paired comparisons of two designs integrated on the same random inputs (common random
//! numbers): differences of means and quantiles with bootstrap intervals that resample the
//! pairs, and differences of exceedance probabilities with Newcombe's paired score interval.
//! Each comes with the interval an unpaired comparison of the same two samples would give, so
//! the gain of the pairing can be read off.

use super::bootstrap::{percentile_interval, SplitMix64};
use super::summary::percentile;
use statrs::distribution::{ContinuousCDF, Normal};

/// Two-sided standard-normal quantile z_{(1+level)/2}; NaN for a level outside (0, 1).
fn z_of(level: f64) -> f64 {
    if !(level > 0.0 && level < 1.0) {
        return f64::NAN;
    }
    Normal::standard().inverse_cdf(0.5 + level / 2.0)
}

/// Wilson (1927) score interval of a proportion k/n without continuity correction
/// (Newcombe 1998, Stat. Med. 17:857, method 3); (NaN, NaN) for n = 0.
pub fn wilson(k: u64, n: u64, level: f64) -> (f64, f64) {
    if n == 0 {
        return (f64::NAN, f64::NAN);
    }
    let (z, n_f) = (z_of(level), n as f64);
    let p = k as f64 / n_f;
    let z2 = z * z;
    let centre = p + z2 / (2.0 * n_f);
    let half = z * (p * (1.0 - p) / n_f + z2 / (4.0 * n_f * n_f)).sqrt();
    let denom = 1.0 + z2 / n_f;
    (
        ((centre - half) / denom).max(0.0),
        ((centre + half) / denom).min(1.0),
    )
}

/// A paired 2×2 table of an event under two designs on the same n units: `both` (event under
/// both), `only_first`, `only_second`, `neither`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct PairedTable {
    pub both: u64,
    pub only_first: u64,
    pub only_second: u64,
    pub neither: u64,
}

impl PairedTable {
    /// Units counted.
    pub fn n(&self) -> u64 {
        self.both + self.only_first + self.only_second + self.neither
    }

    /// p₁ − p₂ = (only_first − only_second)/n; NaN for n = 0.
    pub fn difference(&self) -> f64 {
        let n = self.n();
        if n == 0 {
            return f64::NAN;
        }
        (self.only_first as f64 - self.only_second as f64) / n as f64
    }

    /// Newcombe's correlation estimate ψ of method 10: with A = ad − bc, (A − n/2)/√(product
    /// of the margins) for A > n/2, 0 for 0 ≤ A ≤ n/2, A/√(…) for A < 0, and 0 where a margin
    /// is empty (Newcombe 1998, Stat. Med. 17:2635, method 10; Fagerland, Lydersen & Laake,
    /// "Statistical Analysis of Contingency Tables", 2017, §8.5).
    fn phi(&self) -> f64 {
        let (a, b, c, d) = (
            self.both as f64,
            self.only_first as f64,
            self.only_second as f64,
            self.neither as f64,
        );
        let denom = (a + b) * (c + d) * (a + c) * (b + d);
        let cross = a * d - b * c;
        let half_n = self.n() as f64 / 2.0;
        if denom <= 0.0 {
            0.0
        } else if cross > half_n {
            (cross - half_n) / denom.sqrt()
        } else if cross >= 0.0 {
            0.0
        } else {
            cross / denom.sqrt()
        }
    }
}

/// Interval of p₁ − p₂ by the hybrid score ("square-and-add") method combining the two Wilson
/// intervals, with the correlation estimate `phi` of the pair (0: independent samples).
fn hybrid_score(p1: f64, p2: f64, w1: (f64, f64), w2: (f64, f64), phi: f64) -> (f64, f64) {
    let d = p1 - p2;
    let (l1, u1) = w1;
    let (l2, u2) = w2;
    let lower = ((p1 - l1).powi(2) - 2.0 * phi * (p1 - l1) * (u2 - p2) + (u2 - p2).powi(2))
        .max(0.0)
        .sqrt();
    let upper = ((u1 - p1).powi(2) - 2.0 * phi * (u1 - p1) * (p2 - l2) + (p2 - l2).powi(2))
        .max(0.0)
        .sqrt();
    ((d - lower).max(-1.0), (d + upper).min(1.0))
}

/// Confidence interval of the difference p₁ − p₂ of two proportions measured on the **same**
/// units: Newcombe's method 10, the hybrid score interval of the two Wilson intervals with the
/// table's φ correlation, no continuity correction (R. G. Newcombe, "Improved confidence
/// intervals for the difference between binomial proportions based on paired data",
/// Statistics in Medicine 17 (1998) 2635–2650, method 10; its coverage is close to nominal and
/// it needs no iteration, unlike Tango's score interval, Stat. Med. 17 (1998) 891–908).
/// Returns (NaN, NaN) for an empty table or a level outside (0, 1).
pub fn newcombe_paired(t: &PairedTable, level: f64) -> (f64, f64) {
    let n = t.n();
    if n == 0 || z_of(level).is_nan() {
        return (f64::NAN, f64::NAN);
    }
    let (k1, k2) = (t.both + t.only_first, t.both + t.only_second);
    let (p1, p2) = (k1 as f64 / n as f64, k2 as f64 / n as f64);
    hybrid_score(p1, p2, wilson(k1, n, level), wilson(k2, n, level), t.phi())
}

/// The interval of the same difference if the two samples were independent: Newcombe's
/// hybrid score interval for unpaired proportions (R. G. Newcombe, "Interval estimation for
/// the difference between independent proportions: comparison of eleven methods", Statistics in
/// Medicine 17 (1998) 873–890, method 10) — [`newcombe_paired`] with φ = 0.
pub fn newcombe_unpaired(k1: u64, n1: u64, k2: u64, n2: u64, level: f64) -> (f64, f64) {
    if n1 == 0 || n2 == 0 || z_of(level).is_nan() {
        return (f64::NAN, f64::NAN);
    }
    let (p1, p2) = (k1 as f64 / n1 as f64, k2 as f64 / n2 as f64);
    hybrid_score(p1, p2, wilson(k1, n1, level), wilson(k2, n2, level), 0.0)
}

/// Paired differences of the mean and of quantiles of `second − first`, each with a paired
/// and an unpaired percentile-bootstrap interval.
#[derive(Clone, Debug, PartialEq)]
pub struct PairedDifferences {
    /// Pairs used (both values finite).
    pub n: u64,
    /// mean(second) − mean(first).
    pub mean: Estimate,
    /// quantile_p(second) − quantile_p(first) (type 7), one per requested p.
    pub quantiles: Vec<Estimate>,
}

/// A difference with its paired and unpaired intervals (NaN: none).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Estimate {
    pub value: f64,
    pub paired: (f64, f64),
    pub unpaired: (f64, f64),
}

/// Order of `values` ascending (ties by position: deterministic).
fn order(values: &[f64]) -> Vec<usize> {
    let mut idx: Vec<usize> = (0..values.len()).collect();
    idx.sort_by(|&i, &j| values[i].total_cmp(&values[j]).then(i.cmp(&j)));
    idx
}

/// Type-7 quantiles of the resample that holds `counts[i]` copies of `values[i]` (`m` values in
/// all), walking `values` in ascending `order`: O(n) per resample instead of a sort.
fn weighted_quantiles(
    values: &[f64],
    order: &[usize],
    counts: &[u32],
    m: usize,
    ps: &[f64],
) -> Vec<f64> {
    // The 0-based ranks each quantile needs, and where they are found.
    let ranks: Vec<(usize, f64)> = ps
        .iter()
        .map(|&p| {
            let h = (m - 1) as f64 * p;
            (h.floor() as usize, h - h.floor())
        })
        .collect();
    let mut wanted: Vec<usize> = ranks
        .iter()
        .flat_map(|&(r, _)| [r, (r + 1).min(m - 1)])
        .collect();
    wanted.sort_unstable();
    wanted.dedup();
    let mut at = vec![0.0; wanted.len()];
    let (mut seen, mut w) = (0usize, 0usize);
    for &i in order {
        seen += counts[i] as usize;
        while w < wanted.len() && wanted[w] < seen {
            at[w] = values[i];
            w += 1;
        }
        if w == wanted.len() {
            break;
        }
    }
    let value_at = |r: usize| at[wanted.binary_search(&r).unwrap_or(0)];
    ranks
        .iter()
        .map(|&(r, frac)| {
            let lo = value_at(r);
            if frac > 0.0 {
                lo + frac * (value_at((r + 1).min(m - 1)) - lo)
            } else {
                lo
            }
        })
        .collect()
}

/// Multinomial resample counts of `n` units.
fn draw_counts(rng: &mut SplitMix64, n: usize, counts: &mut [u32]) {
    counts.fill(0);
    for _ in 0..n {
        counts[rng.below(n)] += 1;
    }
}

/// Differences `second − first` of the mean and of the `ps` quantiles over the pairs where both
/// are finite, with percentile-bootstrap intervals at `level` (Efron & Tibshirani 1993, §13.3)
/// from `resamples` resamples seeded by `seed`: paired (the same units drawn for both: the
/// design's effect on one set of random inputs) and unpaired (each sample drawn on its own: what
/// two independent campaigns would give). Deterministic: the same inputs and seed give the same
/// bits. With no pair every value is NaN; a `second` equal to `first` gives exact zeros.
pub fn paired_differences(
    first: &[f64],
    second: &[f64],
    ps: &[f64],
    level: f64,
    resamples: usize,
    seed: u64,
) -> PairedDifferences {
    let (a, b): (Vec<f64>, Vec<f64>) = first
        .iter()
        .zip(second)
        .filter(|(x, y)| x.is_finite() && y.is_finite())
        .map(|(&x, &y)| (x, y))
        .unzip();
    let n = a.len();
    let none = Estimate {
        value: f64::NAN,
        paired: (f64::NAN, f64::NAN),
        unpaired: (f64::NAN, f64::NAN),
    };
    if n == 0 {
        return PairedDifferences {
            n: 0,
            mean: none,
            quantiles: vec![none; ps.len()],
        };
    }
    let diff: Vec<f64> = a.iter().zip(&b).map(|(x, y)| y - x).collect();
    let mean_of = |v: &[f64], c: Option<&[u32]>| -> f64 {
        match c {
            None => v.iter().sum::<f64>() / n as f64,
            Some(c) => v.iter().zip(c).map(|(x, &k)| x * f64::from(k)).sum::<f64>() / n as f64,
        }
    };
    let (oa, ob) = (order(&a), order(&b));
    let ones = vec![1u32; n];
    let qa = weighted_quantiles(&a, &oa, &ones, n, ps);
    let qb = weighted_quantiles(&b, &ob, &ones, n, ps);
    let k = ps.len();
    // Replicates: [mean, quantiles…] for the paired and the unpaired bootstrap.
    let mut paired: Vec<Vec<f64>> = vec![Vec::with_capacity(resamples); k + 1];
    let mut unpaired: Vec<Vec<f64>> = vec![Vec::with_capacity(resamples); k + 1];
    let mut rng = SplitMix64::new(seed);
    let (mut c1, mut c2) = (vec![0u32; n], vec![0u32; n]);
    for _ in 0..resamples {
        draw_counts(&mut rng, n, &mut c1);
        paired[0].push(mean_of(&diff, Some(&c1)));
        let (ra, rb) = (
            weighted_quantiles(&a, &oa, &c1, n, ps),
            weighted_quantiles(&b, &ob, &c1, n, ps),
        );
        for j in 0..k {
            paired[j + 1].push(rb[j] - ra[j]);
        }
        draw_counts(&mut rng, n, &mut c2);
        unpaired[0].push(mean_of(&b, Some(&c2)) - mean_of(&a, Some(&c1)));
        let rb2 = weighted_quantiles(&b, &ob, &c2, n, ps);
        for j in 0..k {
            unpaired[j + 1].push(rb2[j] - ra[j]);
        }
    }
    let mut estimate = |j: usize, value: f64| Estimate {
        value,
        paired: percentile_interval(&mut paired[j], level),
        unpaired: percentile_interval(&mut unpaired[j], level),
    };
    let mean = estimate(0, mean_of(&diff, None));
    let quantiles = (0..k).map(|j| estimate(j + 1, qb[j] - qa[j])).collect();
    PairedDifferences {
        n: n as u64,
        mean,
        quantiles,
    }
}

/// Type-7 quantile of the finite values of `v` (NaN when there are none).
pub fn finite_quantile(v: &[f64], p: f64) -> f64 {
    let mut s: Vec<f64> = v.iter().copied().filter(|x| x.is_finite()).collect();
    s.sort_by(f64::total_cmp);
    percentile(&s, p)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn weighted_quantiles_equal_the_sorted_resample() {
        let v = [3.0, -1.0, 7.5, 2.0, 2.0, 10.0, 0.5];
        let c = [2u32, 0, 1, 3, 0, 1, 0];
        let mut expanded: Vec<f64> = v
            .iter()
            .zip(c)
            .flat_map(|(&x, k)| std::iter::repeat_n(x, k as usize))
            .collect();
        expanded.sort_by(f64::total_cmp);
        let ps = [0.0, 0.1, 0.5, 0.9, 0.99, 1.0];
        let got = weighted_quantiles(&v, &order(&v), &c, expanded.len(), &ps);
        for (p, g) in ps.iter().zip(got) {
            assert_eq!(g, percentile(&expanded, *p), "p = {p}");
        }
    }

    #[test]
    fn newcombe_worked_example() {
        // Complete response before and after consolidation therapy (Cavo et al. 2012) as worked
        // in Fagerland, Lydersen & Laake (2017), ch. 8: the table (59, 6; 16, 80) gives the
        // Newcombe square-and-add interval −0.1186 to −0.0046 for the difference −0.0621.
        let t = PairedTable {
            both: 59,
            only_first: 6,
            only_second: 16,
            neither: 80,
        };
        let (lo, hi) = newcombe_paired(&t, 0.95);
        assert!((t.difference() + 0.0621).abs() < 5e-5);
        assert!(
            (lo + 0.1186).abs() < 5e-5 && (hi + 0.0046).abs() < 5e-5,
            "{lo} {hi}"
        );
    }

    #[test]
    fn identical_samples_give_exact_zeros() {
        let v: Vec<f64> = (0..200).map(|i| f64::from(i).sin() * 3.0 + 1.0).collect();
        let d = paired_differences(&v, &v, &[0.5, 0.99], 0.95, 200, 7);
        assert_eq!(d.n, 200);
        assert_eq!(d.mean.value, 0.0);
        assert_eq!(d.mean.paired, (0.0, 0.0));
        for q in &d.quantiles {
            assert_eq!((q.value, q.paired.0, q.paired.1), (0.0, 0.0, 0.0));
            assert!(q.unpaired.1 > q.unpaired.0);
        }
        let none = paired_differences(&[f64::NAN], &[1.0], &[0.5], 0.95, 10, 1);
        assert_eq!(none.n, 0);
    }
}
