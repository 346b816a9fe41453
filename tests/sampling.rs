//! Tests of the sampling module: inverse CDFs against analytic moments, validation, and the
//! stratification / reproducibility properties of every design.

use cryoslosh::sampling::*;
use statrs::function::erf::erfc;

const M: usize = 100_000;

/// Standard normal CDF (reference, independent of the library's internals).
fn phi_cdf(x: f64) -> f64 {
    0.5 * erfc(-x / std::f64::consts::SQRT_2)
}

fn phi_pdf(x: f64) -> f64 {
    (-0.5 * x * x).exp() / (2.0 * std::f64::consts::PI).sqrt()
}

/// Mean and standard deviation of `quantile(u_k)` over the midpoint grid `u_k = (k + ½)/M`.
fn grid_moments(dist: &Distribution) -> (f64, f64) {
    let xs: Vec<f64> = (0..M)
        .map(|k| dist.quantile((k as f64 + 0.5) / M as f64))
        .collect();
    let mean = xs.iter().sum::<f64>() / M as f64;
    let var = xs.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / M as f64;
    (mean, var.sqrt())
}

/// Grid moments match the analytic mean and std to 1e-3 (relative to the std, a scale that is
/// meaningful for zero means too), and `Distribution::mean` matches the analytic mean.
fn check_moments(dist: &Distribution, mean: f64, std: f64) {
    dist.validate().unwrap_or_else(|e| panic!("{dist:?}: {e}"));
    let (m, s) = grid_moments(dist);
    assert!(
        (m - mean).abs() <= 1e-3 * std,
        "{dist:?}: grid mean {m} vs analytic {mean}"
    );
    assert!(
        (s - std).abs() <= 1e-3 * std,
        "{dist:?}: grid std {s} vs analytic {std}"
    );
    assert!(
        (dist.mean() - mean).abs() <= 1e-9 * (mean.abs() + std),
        "{dist:?}: mean() {} vs {mean}",
        dist.mean()
    );
}

/// Analytic mean and std of Normal(mu, sigma) truncated to [lo, hi].
fn truncated_moments(mu: f64, sigma: f64, lo: f64, hi: f64) -> (f64, f64) {
    let (a, b) = ((lo - mu) / sigma, (hi - mu) / sigma);
    let z = phi_cdf(b) - phi_cdf(a);
    let (pa, pb) = (phi_pdf(a), phi_pdf(b));
    let apa = if a.is_finite() { a * pa } else { 0.0 };
    let bpb = if b.is_finite() { b * pb } else { 0.0 };
    let mean = mu + sigma * (pa - pb) / z;
    let var = sigma * sigma * (1.0 + (apa - bpb) / z - ((pa - pb) / z).powi(2));
    (mean, var.sqrt())
}

#[test]
fn normal_moments() {
    check_moments(
        &Distribution::Normal {
            mean: 20.0,
            std: 3.0,
        },
        20.0,
        3.0,
    );
    check_moments(
        &Distribution::Normal {
            mean: 0.0,
            std: 1e-3,
        },
        0.0,
        1e-3,
    );
}

#[test]
fn truncated_normal_moments() {
    for (mu, sigma, lo, hi) in [
        (1.0, 2.0, -1.0, 4.0),
        (0.0, 1.0, 0.0, f64::INFINITY),
        (0.0, 1.0, f64::NEG_INFINITY, 0.5),
        (0.0, 1.0, 2.0, 3.0),
        (10.0, 1.0, 6.0, 7.5),
        (300.0, 5.0, 290.0, 320.0),
    ] {
        let (mean, std) = truncated_moments(mu, sigma, lo, hi);
        check_moments(
            &Distribution::TruncatedNormal {
                mean: mu,
                std: sigma,
                lo,
                hi,
            },
            mean,
            std,
        );
    }
    // Half-normal, in closed form.
    let half = Distribution::TruncatedNormal {
        mean: 0.0,
        std: 1.0,
        lo: 0.0,
        hi: f64::INFINITY,
    };
    let pi = std::f64::consts::PI;
    assert!((half.mean() - (2.0 / pi).sqrt()).abs() < 1e-12);
}

#[test]
fn uniform_lognormal_triangular_moments() {
    check_moments(
        &Distribution::Uniform { lo: 2.0, hi: 5.0 },
        3.5,
        3.0 / 12f64.sqrt(),
    );

    let (median, sigma) = (2.0, 0.3);
    let ln = Distribution::LogNormal { median, sigma };
    let mean = median * (0.5 * sigma * sigma).exp();
    check_moments(&ln, mean, mean * ((sigma * sigma).exp() - 1.0).sqrt());
    assert!((ln.quantile(0.5) - median).abs() < 1e-12 * median);

    for (lo, mode, hi) in [
        (1.0, 2.0, 5.0),
        (0.0, 0.0, 1.0),
        (-3.0, 4.0, 4.0),
        (10.0, 10.5, 11.0),
    ] {
        let var = (lo * lo + mode * mode + hi * hi - lo * mode - lo * hi - mode * hi) / 18.0;
        check_moments(
            &Distribution::Triangular { lo, mode, hi },
            (lo + mode + hi) / 3.0,
            f64::sqrt(var),
        );
    }
}

#[test]
fn choice_frequencies_match_weights() {
    let values = vec![1.0, 2.0, 5.0];
    for (weights, expected) in [
        (vec![1.0, 2.0, 7.0], [0.1, 0.2, 0.7]),
        (vec![], [1.0 / 3.0; 3]),
        (vec![0.5, 0.5, 1.0], [0.25, 0.25, 0.5]),
    ] {
        let dist = Distribution::Choice {
            values: values.clone(),
            weights,
        };
        dist.validate().unwrap();
        let mut counts = [0usize; 3];
        for k in 0..M {
            let x = dist.quantile((k as f64 + 0.5) / M as f64);
            let idx = values.iter().position(|&v| v == x).expect("a listed value");
            counts[idx] += 1;
        }
        for (c, e) in counts.iter().zip(expected) {
            assert!(
                (*c as f64 / M as f64 - e).abs() <= 2.0 / M as f64,
                "{dist:?}: {counts:?}"
            );
        }
        let mean: f64 = values.iter().zip(expected).map(|(v, p)| v * p).sum();
        assert!((dist.mean() - mean).abs() < 1e-12);
    }
    // Extremes stay on the listed values.
    let dist = Distribution::Choice {
        values: values.clone(),
        weights: vec![1.0, 2.0, 7.0],
    };
    assert_eq!(dist.quantile(0.0), 1.0);
    assert_eq!(dist.quantile(1.0), 5.0);
    assert_eq!(dist.support(), (1.0, 5.0));
}

#[test]
fn truncated_normal_far_tail() {
    let dist = Distribution::TruncatedNormal {
        mean: 0.0,
        std: 1.0,
        lo: 6.0,
        hi: 8.0,
    };
    dist.validate().unwrap();
    let mut previous = f64::NEG_INFINITY;
    let us = [0.0, 1e-300, 1e-16]
        .into_iter()
        .chain((0..=10_000).map(|k| k as f64 / 10_000.0))
        .chain([1.0 - 1e-16, 1.0]);
    for u in us {
        let x = dist.quantile(u);
        assert!(x.is_finite() && (6.0..=8.0).contains(&x), "u = {u}: {x}");
        assert!(x >= previous, "not monotone at u = {u}: {x} < {previous}");
        previous = x;
    }
    // Strictly increasing across the bulk, and the median where Q(x) = Q(6)/2.
    assert!(dist.quantile(0.25) < dist.quantile(0.5) && dist.quantile(0.5) < dist.quantile(0.75));
    let median = dist.quantile(0.5);
    let (q6, q8) = (phi_cdf(-6.0), phi_cdf(-8.0));
    assert!(
        ((phi_cdf(-median) - q8) / (q6 - q8) - 0.5).abs() < 1e-9,
        "median {median}"
    );
    // Mean: φ(6)/Q(6) (Q(8) is negligible), and the grid agrees.
    let mean = (phi_pdf(6.0) - phi_pdf(8.0)) / (phi_cdf(-6.0) - phi_cdf(-8.0));
    assert!((dist.mean() - mean).abs() < 1e-9);
    let (grid_mean, _) = grid_moments(&dist);
    assert!((grid_mean - mean).abs() < 1e-3 * 0.16);

    // Mirror image in the lower tail.
    let mirror = Distribution::TruncatedNormal {
        mean: 0.0,
        std: 1.0,
        lo: -8.0,
        hi: -6.0,
    };
    for u in [0.01, 0.3, 0.5, 0.9] {
        assert!((mirror.quantile(u) + dist.quantile(1.0 - u)).abs() < 1e-9);
    }
    assert!((mirror.mean() + mean).abs() < 1e-9);
}

#[test]
fn quantile_is_finite_at_the_ends() {
    let dists = [
        Distribution::Normal {
            mean: 1.0,
            std: 2.0,
        },
        Distribution::LogNormal {
            median: 1.0,
            sigma: 2.0,
        },
        Distribution::TruncatedNormal {
            mean: 0.0,
            std: 1.0,
            lo: -1.0,
            hi: f64::INFINITY,
        },
        Distribution::Uniform { lo: 0.0, hi: 1.0 },
        Distribution::Triangular {
            lo: 0.0,
            mode: 1.0,
            hi: 1.0,
        },
    ];
    for dist in &dists {
        let (lo, hi) = dist.support();
        for u in [0.0, 1e-300, 0.5, 1.0 - 1e-17, 1.0] {
            let x = dist.quantile(u);
            assert!(x.is_finite() && x >= lo && x <= hi, "{dist:?} at {u}: {x}");
        }
        // NaN in, NaN out: a NaN unit sample is a caller bug and must not look like a value.
        assert!(dist.quantile(f64::NAN).is_nan());
        assert!(dist.quantile(0.1) <= dist.quantile(0.9));
    }
    // Normal clamps at 1e-15: about 7.94 σ.
    let z = Distribution::Normal {
        mean: 0.0,
        std: 1.0,
    }
    .quantile(0.0);
    assert!((z + 7.941).abs() < 1e-3, "{z}");
}

#[test]
fn support_bounds() {
    assert_eq!(
        Distribution::Normal {
            mean: 0.0,
            std: 1.0
        }
        .support(),
        (f64::NEG_INFINITY, f64::INFINITY)
    );
    assert_eq!(
        Distribution::LogNormal {
            median: 1.0,
            sigma: 1.0
        }
        .support(),
        (0.0, f64::INFINITY)
    );
    assert_eq!(
        Distribution::Uniform { lo: -1.0, hi: 2.0 }.support(),
        (-1.0, 2.0)
    );
    assert_eq!(
        Distribution::TruncatedNormal {
            mean: 0.0,
            std: 1.0,
            lo: -1.0,
            hi: 2.0
        }
        .support(),
        (-1.0, 2.0)
    );
    assert_eq!(
        Distribution::Triangular {
            lo: 0.0,
            mode: 1.0,
            hi: 3.0
        }
        .support(),
        (0.0, 3.0)
    );
}

#[test]
fn validate_rejects_bad_parameters() {
    use DistributionError as E;
    let bad = |d: Distribution| d.validate().expect_err("should be rejected");
    assert!(matches!(
        bad(Distribution::Normal {
            mean: 0.0,
            std: -1.0
        }),
        E::NonPositiveStd { .. }
    ));
    assert!(matches!(
        bad(Distribution::Normal {
            mean: 0.0,
            std: 0.0
        }),
        E::NonPositiveStd { .. }
    ));
    assert!(matches!(
        bad(Distribution::TruncatedNormal {
            mean: 0.0,
            std: -2.0,
            lo: 0.0,
            hi: 1.0
        }),
        E::NonPositiveStd { .. }
    ));
    assert_eq!(
        bad(Distribution::Uniform { lo: 2.0, hi: 1.0 }),
        E::Inverted { lo: 2.0, hi: 1.0 }
    );
    assert_eq!(
        bad(Distribution::Uniform { lo: 1.0, hi: 1.0 }),
        E::Inverted { lo: 1.0, hi: 1.0 }
    );
    assert!(matches!(
        bad(Distribution::TruncatedNormal {
            mean: 0.0,
            std: 1.0,
            lo: 1.0,
            hi: -1.0
        }),
        E::Inverted { .. }
    ));
    assert!(matches!(
        bad(Distribution::Triangular {
            lo: 3.0,
            mode: 3.0,
            hi: 1.0
        }),
        E::Inverted { .. }
    ));
    assert_eq!(
        bad(Distribution::Triangular {
            lo: 0.0,
            mode: 2.0,
            hi: 1.0
        }),
        E::ModeOutside {
            lo: 0.0,
            mode: 2.0,
            hi: 1.0
        }
    );
    assert_eq!(
        bad(Distribution::Choice {
            values: vec![],
            weights: vec![]
        }),
        E::EmptyChoice
    );
    assert!(matches!(
        bad(Distribution::Choice {
            values: vec![1.0, 2.0],
            weights: vec![1.0]
        }),
        E::WeightCount {
            values: 2,
            weights: 1
        }
    ));
    assert!(matches!(
        bad(Distribution::Choice {
            values: vec![1.0, 2.0],
            weights: vec![1.0, 0.0]
        }),
        E::BadWeight { index: 1, .. }
    ));
    assert!(matches!(
        bad(Distribution::Choice {
            values: vec![1.0, 2.0],
            weights: vec![-1.0, 1.0]
        }),
        E::BadWeight { index: 0, .. }
    ));
    assert!(matches!(
        bad(Distribution::LogNormal {
            median: 0.0,
            sigma: 1.0
        }),
        E::NonPositiveMedian { .. }
    ));
    assert!(matches!(
        bad(Distribution::LogNormal {
            median: 1.0,
            sigma: -1.0
        }),
        E::NonPositiveSigma { .. }
    ));
    assert!(matches!(
        bad(Distribution::TruncatedNormal {
            mean: 0.0,
            std: 1.0,
            lo: 40.0,
            hi: 41.0
        }),
        E::EmptyTruncation { .. }
    ));
    // NaN / infinite parameters.
    assert!(matches!(
        bad(Distribution::Normal {
            mean: f64::NAN,
            std: 1.0
        }),
        E::NotFinite { what: "mean", .. }
    ));
    assert!(matches!(
        bad(Distribution::Normal {
            mean: 0.0,
            std: f64::NAN
        }),
        E::NotFinite { what: "std", .. }
    ));
    assert!(matches!(
        bad(Distribution::Uniform {
            lo: 0.0,
            hi: f64::INFINITY
        }),
        E::NotFinite { what: "hi", .. }
    ));
    assert!(matches!(
        bad(Distribution::TruncatedNormal {
            mean: 0.0,
            std: 1.0,
            lo: f64::NAN,
            hi: 1.0
        }),
        E::NotANumber { what: "lo" }
    ));
    assert!(matches!(
        bad(Distribution::Triangular {
            lo: 0.0,
            mode: f64::NAN,
            hi: 1.0
        }),
        E::NotFinite { what: "mode", .. }
    ));
    assert!(matches!(
        bad(Distribution::Choice {
            values: vec![1.0, f64::NAN],
            weights: vec![]
        }),
        E::NotFinite { .. }
    ));
    assert!(matches!(
        bad(Distribution::Choice {
            values: vec![1.0],
            weights: vec![f64::NAN]
        }),
        E::BadWeight { .. }
    ));
    // Messages state what is allowed, without any file or key.
    let msg = bad(Distribution::Normal {
        mean: 0.0,
        std: -1.0,
    })
    .to_string();
    assert!(msg.contains("> 0") && msg.contains("-1"), "{msg}");
    let msg = bad(Distribution::Triangular {
        lo: 0.0,
        mode: 2.0,
        hi: 1.0,
    })
    .to_string();
    assert!(msg.contains("[0, 1]") && msg.contains('2'), "{msg}");
}

#[test]
fn validate_accepts_good_parameters() {
    for d in [
        Distribution::Normal {
            mean: -5.0,
            std: 1e-9,
        },
        Distribution::TruncatedNormal {
            mean: 0.0,
            std: 1.0,
            lo: 6.0,
            hi: 8.0,
        },
        Distribution::TruncatedNormal {
            mean: 0.0,
            std: 1.0,
            lo: f64::NEG_INFINITY,
            hi: f64::INFINITY,
        },
        Distribution::Uniform { lo: -1.0, hi: 1.0 },
        Distribution::LogNormal {
            median: 1e-3,
            sigma: 3.0,
        },
        Distribution::Triangular {
            lo: 0.0,
            mode: 0.0,
            hi: 1.0,
        },
        Distribution::Triangular {
            lo: 0.0,
            mode: 1.0,
            hi: 1.0,
        },
        Distribution::Choice {
            values: vec![3.0],
            weights: vec![],
        },
        Distribution::Choice {
            values: vec![3.0, 4.0],
            weights: vec![0.1, 5.0],
        },
    ] {
        assert_eq!(d.validate(), Ok(()), "{d:?}");
    }
}

#[test]
fn design_names_round_trip() {
    for d in [
        Design::MonteCarlo,
        Design::LatinHypercube,
        Design::Sobol,
        Design::Saltelli,
    ] {
        assert_eq!(Design::from_name(d.name()), Some(d));
    }
    assert_eq!(Design::LatinHypercube.name(), "latin_hypercube");
    assert_eq!(Design::from_name("lhs"), None);
    assert_eq!(Design::from_name("Sobol"), None);
}

#[test]
fn latin_hypercube_strata_are_permutations() {
    let n = 1000u64;
    let strata = |seed: u64, d: usize| -> Vec<u64> {
        (0..n)
            .map(|i| {
                let u = unit_sample(Design::LatinHypercube, seed, n, i, d, 5);
                assert!(u > 0.0 && u < 1.0);
                (u * n as f64).floor() as u64
            })
            .collect()
    };
    for d in 0..5 {
        let s = strata(7, d);
        let mut sorted = s.clone();
        sorted.sort_unstable();
        assert_eq!(sorted, (0..n).collect::<Vec<_>>(), "dim {d}");
        // Different seeds and different dimensions give different permutations.
        assert_ne!(s, strata(8, d), "dim {d}");
        if d > 0 {
            assert_ne!(s, strata(7, d - 1));
        }
    }
    // Same (seed, i, n, d) → same value, whatever was computed before.
    let a = unit_sample(Design::LatinHypercube, 3, n, 123, 2, 5);
    let _ = unit_sample(Design::LatinHypercube, 3, n, 999, 2, 5);
    assert_eq!(a, unit_sample(Design::LatinHypercube, 3, n, 123, 2, 5));
    // The number of inputs does not matter.
    assert_eq!(a, unit_sample(Design::LatinHypercube, 3, n, 123, 2, 9));
    // The campaign size does (strata depend on n).
    assert_ne!(a, unit_sample(Design::LatinHypercube, 3, n + 1, 123, 2, 5));
}

#[test]
fn latin_hypercube_edge_sizes() {
    for n in [1u64, 2, 3, 7, 64, 65, 4097] {
        let mut seen = vec![false; n as usize];
        for i in 0..n {
            let u = unit_sample(Design::LatinHypercube, 11, n, i, 0, 1);
            assert!(u > 0.0 && u < 1.0);
            let s = (u * n as f64).floor() as usize;
            assert!(!seen[s], "n = {n}: stratum {s} twice");
            seen[s] = true;
        }
    }
    // Out-of-contract arguments do not panic and stay in (0, 1).
    for (n, i) in [
        (0u64, 0u64),
        (0, 5),
        (10, 10),
        (10, u64::MAX),
        (u64::MAX, u64::MAX - 1),
        (1 << 63, 12345),
    ] {
        let u = unit_sample(Design::LatinHypercube, 1, n, i, 3, 4);
        assert!(u > 0.0 && u < 1.0, "n = {n}, i = {i}: {u}");
    }
}

/// Largest number of the first `2^m` points of dimensions (d0, d1) in any elementary interval of
/// area 2^-m (boxes of 2^-a × 2^-(m-a)): 1 for a (0, m, 2)-net, 2^t for a (t, m, 2)-net.
fn max_elementary_count(seed: u64, m: u32, d0: usize, d1: usize) -> u32 {
    let n = 1u64 << m;
    let mut worst = 0;
    for a in 0..=m {
        let mut cells = vec![0u32; n as usize];
        for i in 0..n {
            let x = unit_sample(Design::Sobol, seed, n, i, d0, 64);
            let y = unit_sample(Design::Sobol, seed, n, i, d1, 64);
            assert!(x > 0.0 && x < 1.0 && y > 0.0 && y < 1.0);
            let cx = (x * (1u64 << a) as f64) as usize;
            let cy = (y * (1u64 << (m - a)) as f64) as usize;
            cells[(cx << (m - a)) | cy] += 1;
        }
        worst = worst.max(cells.iter().copied().max().unwrap_or(0));
    }
    worst
}

#[test]
fn sobol_is_a_net() {
    for seed in [0u64, 42, 123_456_789] {
        // Dimensions 0 and 1: 1024 points, one in each of the 32 × 32 equal cells (and in every
        // other elementary interval of area 1/1024) — a (0, 10, 2)-net, preserved by Owen scrambling.
        let mut cells = vec![0u32; 32 * 32];
        for i in 0..1024 {
            let x = unit_sample(Design::Sobol, seed, 1024, i, 0, 2);
            let y = unit_sample(Design::Sobol, seed, 1024, i, 1, 2);
            assert!(x > 0.0 && x < 1.0 && y > 0.0 && y < 1.0);
            cells[(x * 32.0) as usize * 32 + (y * 32.0) as usize] += 1;
        }
        assert!(
            cells.iter().all(|&c| c == 1),
            "seed {seed}: not one point per cell"
        );
        assert_eq!(max_elementary_count(seed, 10, 0, 1), 1);
        // Every single dimension: one point per 1/1024 stratum (a (0, 10, 1)-net).
        for d in [0usize, 1, 2, 7, 63, 255] {
            let mut strata = vec![0u32; 1024];
            for i in 0..1024 {
                strata[(unit_sample(Design::Sobol, seed, 1024, i, d, 256) * 1024.0) as usize] += 1;
            }
            assert!(strata.iter().all(|&c| c == 1), "seed {seed}, dim {d}");
        }
        // Other pairs of the Joe–Kuo sequence are (t, m, 2)-nets with a small t > 0, which the
        // scrambling preserves: at most 2^t points per elementary interval.
        assert!(max_elementary_count(seed, 10, 2, 5) <= 2);
        assert!(max_elementary_count(seed, 10, 30, 31) <= 4);
    }
    // Seeds give different scrambles; same inputs the same value; n and k do not matter.
    let a = unit_sample(Design::Sobol, 1, 1024, 5, 0, 2);
    assert_ne!(a, unit_sample(Design::Sobol, 2, 1024, 5, 0, 2));
    assert_eq!(a, unit_sample(Design::Sobol, 1, 1024, 5, 0, 2));
    assert_eq!(a, unit_sample(Design::Sobol, 1, 4096, 5, 0, 7));
}

#[test]
fn sobol_beyond_its_limits() {
    // Past 2^16 points: each further block of 2^16 is its own scrambled net.
    let base = 1u64 << 16;
    let mut cells = vec![0u32; 16 * 16];
    for i in base..base + 256 {
        let x = unit_sample(Design::Sobol, 5, 0, i, 0, 2);
        let y = unit_sample(Design::Sobol, 5, 0, i, 1, 2);
        cells[(x * 16.0) as usize * 16 + (y * 16.0) as usize] += 1;
    }
    assert!(cells.iter().all(|&c| c == 1));
    assert_ne!(
        unit_sample(Design::Sobol, 5, 0, 3, 0, 2),
        unit_sample(Design::Sobol, 5, 0, base + 3, 0, 2)
    );
    // Huge indices and padded dimensions: no panic, strictly inside (0, 1).
    for (i, d) in [
        (u64::MAX, 0usize),
        (u64::from(u32::MAX), 255),
        (0, MAX_SOBOL_DIMS),
        (7, 10_000),
        (7, usize::MAX),
    ] {
        for design in [Design::Sobol, Design::Saltelli] {
            let u = unit_sample(design, 1, 0, i, d, 3);
            assert!(u > 0.0 && u < 1.0, "{design:?} i = {i}, d = {d}: {u}");
        }
    }
    assert_ne!(
        unit_sample(Design::Sobol, 1, 0, 7, 0, 1),
        unit_sample(Design::Sobol, 1, 0, 7, MAX_SOBOL_DIMS, 1)
    );
    assert_eq!(MAX_SOBOL_DIMS, 256);
}

#[test]
fn monte_carlo_is_uniform_and_reproducible() {
    let n = 100_000u64;
    let mut sum = 0.0;
    for i in 0..n {
        let u = unit_sample(Design::MonteCarlo, 2024, n, i, 0, 1);
        assert!(u > 0.0 && u < 1.0);
        sum += u;
    }
    let mean = sum / n as f64;
    let sigma = (1.0 / 12.0 / n as f64).sqrt();
    assert!((mean - 0.5).abs() < 5.0 * sigma, "mean {mean}");

    let u = |seed: u64, i: u64, d: usize| unit_sample(Design::MonteCarlo, seed, n, i, d, 4);
    assert_eq!(u(1, 10, 2), u(1, 10, 2));
    assert_ne!(u(1, 10, 2), u(1, 10, 3));
    assert_ne!(u(1, 10, 2), u(1, 11, 2));
    assert_ne!(u(1, 10, 2), u(2, 10, 2));
    // n and k_inputs do not matter for Monte Carlo.
    assert_eq!(u(1, 10, 2), unit_sample(Design::MonteCarlo, 1, 7, 10, 2, 1));
    // Two dimensions are uncorrelated.
    let m = 20_000u64;
    let (mut sxy, mut sx, mut sy) = (0.0, 0.0, 0.0);
    for i in 0..m {
        let (x, y) = (u(3, i, 0), u(3, i, 1));
        sx += x;
        sy += y;
        sxy += x * y;
    }
    let cov = sxy / m as f64 - (sx / m as f64) * (sy / m as f64);
    let corr = cov * 12.0;
    assert!(corr.abs() < 5.0 / (m as f64).sqrt(), "corr {corr}");
}

/// Pearson correlation of two samples.
fn pearson(x: &[f64], y: &[f64]) -> f64 {
    let n = x.len() as f64;
    let (mx, my) = (x.iter().sum::<f64>() / n, y.iter().sum::<f64>() / n);
    let (mut sxy, mut sxx, mut syy) = (0.0, 0.0, 0.0);
    for (a, b) in x.iter().zip(y) {
        sxy += (a - mx) * (b - my);
        sxx += (a - mx).powi(2);
        syy += (b - my).powi(2);
    }
    sxy / (sxx * syy).sqrt()
}

#[test]
fn correlate_gives_the_requested_normal_correlation() {
    let std_normal = Distribution::Normal {
        mean: 0.0,
        std: 1.0,
    };
    let n = 20_000u64;
    for rho in [0.7, -0.4, 0.0] {
        let (mut z1, mut z2) = (Vec::new(), Vec::new());
        for i in 0..n {
            let u1 = unit_sample(Design::MonteCarlo, 99, n, i, 0, 2);
            let u2 = unit_sample(Design::MonteCarlo, 99, n, i, 1, 2);
            let (v1, v2) = correlate(u1, u2, rho);
            assert_eq!(v1, u1);
            assert!(v2 > 0.0 && v2 < 1.0);
            z1.push(std_normal.quantile(v1));
            z2.push(std_normal.quantile(v2));
        }
        let r = pearson(&z1, &z2);
        assert!((r - rho).abs() < 0.02, "rho {rho}: sample correlation {r}");
    }
    // rho = 0 leaves u2 unchanged (to rounding); extremes stay inside (0, 1).
    let (_, u2) = correlate(0.3, 0.8, 0.0);
    assert!((u2 - 0.8).abs() < 1e-14, "{u2}");
    for (u1, u2, rho) in [
        (1e-300, 1e-300, 0.99),
        (1.0, 1.0, 0.99),
        (0.0, 1.0, -0.99),
        (0.5, 0.5, 1.0),
        (0.5, 0.5, f64::NAN),
    ] {
        let (_, v) = correlate(u1, u2, rho);
        assert!(v > 0.0 && v < 1.0, "({u1}, {u2}, {rho}) → {v}");
    }
}

#[test]
fn saltelli_layout_round_trip() {
    for k in [0usize, 1, 3, 8] {
        let period = k as u64 + 2;
        for b in 0..5u64 {
            let mut rows = Vec::new();
            for i in b * period..(b + 1) * period {
                let (base, row) = saltelli_layout(i, k);
                assert_eq!(base, b);
                rows.push(row);
            }
            // Each group of k + 2 rows holds A, B and every AB(m) exactly once.
            assert_eq!(rows.iter().filter(|r| **r == SaltelliRow::A).count(), 1);
            assert_eq!(rows.iter().filter(|r| **r == SaltelliRow::B).count(), 1);
            for m in 0..k {
                assert_eq!(rows.iter().filter(|r| **r == SaltelliRow::AB(m)).count(), 1);
            }
            assert!(rows
                .iter()
                .all(|r| !matches!(r, SaltelliRow::AB(m) if *m >= k)));
        }
    }
    assert_eq!(saltelli_layout(0, 3), (0, SaltelliRow::A));
}

#[test]
fn saltelli_rows_share_columns() {
    let k = 4usize;
    let period = k as u64 + 2;
    let n = 16 * period;
    let seed = 77;
    for b in 0..16u64 {
        let find = |want: SaltelliRow| {
            (b * period..(b + 1) * period)
                .find(|&i| saltelli_layout(i, k).1 == want)
                .expect("row present")
        };
        let row = |i: u64| -> Vec<f64> {
            (0..k)
                .map(|j| unit_sample(Design::Saltelli, seed, n, i, j, k))
                .collect()
        };
        let a = row(find(SaltelliRow::A));
        let bb = row(find(SaltelliRow::B));
        // A and B are Sobol dimensions 0..k and k..2k of base point b.
        for j in 0..k {
            assert_eq!(a[j], unit_sample(Design::Sobol, seed, 0, b, j, 0));
            assert_eq!(bb[j], unit_sample(Design::Sobol, seed, 0, b, k + j, 0));
            assert_ne!(a[j], bb[j]);
        }
        for m in 0..k {
            let ab = row(find(SaltelliRow::AB(m)));
            for j in 0..k {
                assert_eq!(
                    ab[j],
                    if j == m { bb[j] } else { a[j] },
                    "b {b}, AB({m}), column {j}"
                );
            }
        }
    }
}
