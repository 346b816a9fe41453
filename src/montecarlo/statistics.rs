//! Campaign statistics from a finished `instances.parquet`, read back one column at a time
//! (bounded memory), written as the tidy `statistics.parquet`.
//!
//! Diverged and rejected instances are excluded from every statistic and counted separately.
//! Every estimate a margin is signed with carries an interval: quantiles their distribution-free
//! order-statistic interval, tail probabilities Clopper–Pearson, Spearman's ρ the Fisher-z
//! interval with the Bonett–Wright variance, Sobol indices a bootstrap over complete groups; and
//! the campaign's one-sided (Wilks) tolerance bounds are reported beside them.

use super::table::{read_bool, read_f64, read_flag, statistic_names, ReadError};
use crate::campaign::dispersion::Dispersions;
use crate::campaign::statistics::{quantile_name, Side, StatisticsPlan, Threshold};
use crate::output::{ColumnData, ColumnKind, ColumnSpec, OutputError, TableWriter};
use crate::sampling::{saltelli_layout, Design, SaltelliRow};
use crate::stats::{
    describe, exceedance, is_constant, percentile, quantile_interval, sobol_analysis, spearman,
    spearman_interval, tolerance_bound, wilks_min_samples, Direction, SobolOptions, StatRow,
};
use std::path::Path;

/// A statistics row: the tidy [`StatRow`] plus the dispersed input it refers to (sensitivities;
/// "" = null otherwise), the probability level (a quantile's p, a tolerance bound's coverage)
/// and the confidence level of its interval or bound (NaN = null where there is none).
#[derive(Clone, Debug, PartialEq)]
pub struct Row {
    pub stat: StatRow,
    pub input: String,
    pub probability: f64,
    pub confidence: f64,
}

fn plain(stat: StatRow) -> Row {
    Row {
        stat,
        input: String::new(),
        probability: f64::NAN,
        confidence: f64::NAN,
    }
}

/// What the statistics of a campaign are computed with.
#[derive(Clone, Debug)]
pub struct Spec {
    pub dispersions: Dispersions,
    pub plan: StatisticsPlan,
    /// Maximum expected operating pressure, Pa (the `prob_exceed` row of `peak_pressure_pa`).
    pub meop_pa: f64,
    /// Boil-off budget, kg (a `prob_exceed` row of `boiloff_kg` when set).
    pub boiloff_budget_kg: Option<f64>,
    /// Instances in the campaign (the Saltelli groups come from it).
    pub total: u64,
    /// Seed of the bootstrap resamples (the campaign's seed: statistics are reproducible).
    pub seed: u64,
    /// The campaign's phase names (its per-phase QoI columns, `table::qoi_names`).
    pub phases: Vec<String>,
}

/// QoIs whose sensitivities are reported (the margins a designer sizes a tank against).
pub const SENSITIVITY_QOIS: [&str; 6] = [
    "peak_pressure_pa",
    "boiloff_kg",
    "vented_kg",
    "min_cavitation_margin_m",
    "max_slosh_angle_rad",
    "peak_slosh_force_n",
];

/// The `prob_exceed` (above) or `prob_below` row of a threshold, with its Clopper–Pearson
/// interval.
fn threshold_row(t: &Threshold, values: &[f64], level: f64) -> Row {
    let (dir, statistic) = match t.side {
        Side::Above => (Direction::Above, "prob_exceed"),
        Side::Below => (Direction::Below, "prob_below"),
    };
    let e = exceedance(values, t.value, dir, level);
    Row {
        confidence: level,
        ..plain(StatRow {
            quantity: t.quantity.clone(),
            statistic: statistic.into(),
            threshold: t.value,
            value: e.p,
            ci_low: e.ci_low,
            ci_high: e.ci_high,
            n: e.n,
        })
    }
}

/// `values` with NaN (= not counted) where `valid` is false.
fn mask(values: Vec<f64>, valid: &[bool]) -> Vec<f64> {
    values
        .into_iter()
        .zip(valid)
        .map(|(x, &ok)| if ok { x } else { f64::NAN })
        .collect()
}

/// The share of `ones` (1 = yes, 0 = no, NaN = not counted) with its Clopper–Pearson interval.
fn fraction_row(name: &str, ones: &[f64], level: f64) -> Row {
    let e = exceedance(ones, 0.5, Direction::Above, level);
    Row {
        confidence: level,
        ..plain(StatRow {
            quantity: name.into(),
            statistic: "fraction".into(),
            threshold: f64::NAN,
            value: e.p,
            ci_low: e.ci_low,
            ci_high: e.ci_high,
            n: e.n,
        })
    }
}

/// The thresholds reported: MEOP, cavitation margin < 0, the boil-off budget, then the
/// campaign's own (a repeat of one of these is reported once).
pub fn thresholds(spec: &Spec) -> Vec<Threshold> {
    let t = |quantity: &str, side, value| Threshold {
        key: String::new(),
        quantity: quantity.into(),
        side,
        value,
    };
    let mut all = vec![
        t("peak_pressure_pa", Side::Above, spec.meop_pa),
        t("min_cavitation_margin_m", Side::Below, 0.0),
    ];
    if let Some(b) = spec.boiloff_budget_kg {
        all.push(t("boiloff_kg", Side::Above, b));
    }
    for u in &spec.plan.thresholds {
        let seen = all
            .iter()
            .any(|a| a.quantity == u.quantity && a.side == u.side && a.value == u.value);
        if !seen {
            all.push(u.clone());
        }
    }
    all
}

/// Moments and extremes, the plan's quantiles with their intervals, and its tolerance bounds.
fn distribution_rows(name: &str, values: &[f64], plan: &StatisticsPlan) -> Vec<Row> {
    let mut sorted: Vec<f64> = values.iter().copied().filter(|v| v.is_finite()).collect();
    sorted.sort_by(f64::total_cmp);
    let n = sorted.len() as u64;
    // mean, std, min, max from `describe`; its fixed percentiles are replaced by the plan's.
    let mut rows: Vec<Row> = describe(name, values)
        .into_iter()
        .take(4)
        .map(plain)
        .collect();
    let level = plan.confidence;
    for &p in &plan.quantiles {
        let (lo, hi) = quantile_interval(&sorted, p, level);
        rows.push(Row {
            probability: p,
            confidence: level,
            ..plain(StatRow {
                quantity: name.into(),
                statistic: quantile_name(p),
                threshold: f64::NAN,
                value: percentile(&sorted, p),
                ci_low: lo,
                ci_high: hi,
                n,
            })
        });
    }
    for &(coverage, confidence) in &plan.tolerance {
        for (side, statistic) in [
            (crate::stats::Side::Upper, "tolerance_upper"),
            (crate::stats::Side::Lower, "tolerance_lower"),
        ] {
            let t = tolerance_bound(&sorted, coverage, confidence, side);
            rows.push(Row {
                probability: coverage,
                confidence,
                ..plain(StatRow {
                    quantity: name.into(),
                    statistic: statistic.into(),
                    threshold: f64::NAN,
                    value: t.value,
                    ci_low: f64::NAN,
                    ci_high: f64::NAN,
                    n,
                })
            });
        }
    }
    if n > 0 && is_constant(&sorted) {
        rows.push(plain(StatRow {
            quantity: name.into(),
            statistic: "constant".into(),
            threshold: f64::NAN,
            value: sorted[sorted.len() - 1] - sorted[0],
            ci_low: f64::NAN,
            ci_high: f64::NAN,
            n,
        }));
    }
    rows
}

/// Every statistic of the campaign in `path`.
pub fn compute(path: &Path, spec: &Spec) -> Result<Vec<Row>, ReadError> {
    let d = &spec.dispersions;
    let diverged = read_bool(path, "diverged")?;
    let rejected = read_bool(path, "rejected")?;
    // Under the saltelli design the AB rows repeat the A row but for one input: as draws of the
    // population they are near-copies, so the distribution, probabilities and rank correlations
    // use the independent A and B rows only (the Sobol indices use every row).
    let k = d.inputs.len();
    let independent = |i: usize| {
        d.design != Design::Saltelli
            || matches!(
                saltelli_layout(i as u64, k).1,
                SaltelliRow::A | SaltelliRow::B
            )
    };
    let all_valid: Vec<bool> = diverged
        .iter()
        .zip(&rejected)
        .map(|(d, r)| !d && !r)
        .collect();
    let valid: Vec<bool> = all_valid
        .iter()
        .enumerate()
        .map(|(i, &ok)| ok && independent(i))
        .collect();
    let keep = |v: Vec<f64>| mask(v, &valid);
    let keep_all = |v: Vec<f64>| mask(v, &all_valid);
    let level = spec.plan.confidence;
    let mut rows = Vec::new();
    for (name, flags) in [("diverged", &diverged), ("rejected", &rejected)] {
        let ones: Vec<f64> = flags.iter().map(|&x| f64::from(u8::from(x))).collect();
        rows.push(fraction_row(name, &ones, level));
    }
    // Outcomes among the valid instances, with their Clopper–Pearson intervals.
    for name in ["depleted", "pressurant_exhausted"] {
        let ones: Vec<f64> = read_bool(path, name)?
            .iter()
            .map(|&x| f64::from(u8::from(x)))
            .collect();
        rows.push(fraction_row(name, &keep(ones), level));
    }
    // The slosh analog out of its range is a validity flag, counted among the valid instances
    // where the fidelity models slosh (null in every row at the homogeneous level): 35 of 40
    // unbaffled instances of the design trade whirled through hundreds of radians and neither
    // the run's summary nor the statistics said so.
    let slosh = read_flag(path, "slosh_out_of_range")?;
    if slosh.iter().zip(&valid).any(|(x, &ok)| ok && x.is_some()) {
        let ones: Vec<f64> = slosh
            .iter()
            .map(|&x| f64::from(u8::from(x.unwrap_or(false))))
            .collect();
        rows.push(fraction_row("slosh_out_of_range", &keep(ones), level));
    }

    let thresholds = thresholds(spec);
    // QoIs without sensitivities: constant ones and those with no value at all.
    let mut constant = Vec::new();
    let names = statistic_names(&spec.phases);
    for name in names.iter().map(String::as_str) {
        let values = keep(read_f64(path, name)?);
        let described = distribution_rows(name, &values, &spec.plan);
        if described.iter().any(|r| {
            r.stat.statistic == "constant" || (r.stat.statistic == "mean" && r.stat.n == 0)
        }) {
            constant.push(name);
        }
        rows.extend(described);
        for t in thresholds.iter().filter(|t| t.quantity == name) {
            rows.push(threshold_row(t, &values, level));
        }
    }

    // No sensitivities for a QoI whose spread is below rounding (any ranking would be noise) or
    // that has no value.
    let analysed: Vec<&str> = SENSITIVITY_QOIS
        .into_iter()
        .filter(|q| !constant.contains(q))
        .collect();
    // One input column in memory at a time: at ten million rows each column is 80 MB and the
    // rank correlation needs several working copies.
    for input in &d.inputs {
        let x = keep(read_f64(path, &input.column)?);
        for &q in &analysed {
            let y = keep(read_f64(path, q)?);
            let n = x
                .iter()
                .zip(&y)
                .filter(|(a, b)| a.is_finite() && b.is_finite())
                .count() as u64;
            let rho = spearman(&x, &y);
            let (lo, hi) = spearman_interval(rho, n, level);
            rows.push(Row {
                stat: StatRow {
                    quantity: q.into(),
                    statistic: "spearman".into(),
                    threshold: f64::NAN,
                    value: rho,
                    ci_low: lo,
                    ci_high: hi,
                    n,
                },
                input: input.column.clone(),
                probability: f64::NAN,
                confidence: level,
            });
        }
    }
    if d.design == Design::Saltelli && !d.inputs.is_empty() {
        for &q in &analysed {
            rows.extend(sobol_rows(q, &keep_all(read_f64(path, q)?), spec));
        }
    }
    Ok(rows)
}

/// Sobol first-order and total indices of `q` from the Saltelli rows (instance order), with
/// bootstrap intervals; `n` is the number of complete groups (every row of the group valid).
fn sobol_rows(q: &str, y: &[f64], spec: &Spec) -> Vec<Row> {
    let d = &spec.dispersions;
    let k = d.inputs.len();
    let bases = (spec.total / d.group_size()) as usize;
    let mut f_a = vec![f64::NAN; bases];
    let mut f_b = vec![f64::NAN; bases];
    let mut f_ab = vec![vec![f64::NAN; bases]; k];
    for (i, &v) in y.iter().enumerate() {
        let (b, kind) = saltelli_layout(i as u64, k);
        let b = b as usize;
        if b >= bases {
            continue;
        }
        match kind {
            SaltelliRow::A => f_a[b] = v,
            SaltelliRow::B => f_b[b] = v,
            SaltelliRow::AB(j) => f_ab[j][b] = v,
        }
    }
    let level = spec.plan.confidence;
    let analysis = sobol_analysis(
        &f_a,
        &f_b,
        &f_ab,
        SobolOptions {
            bootstrap: spec.plan.bootstrap as usize,
            level,
            seed: spec.seed,
        },
    );
    let mut rows = Vec::new();
    for (input, s) in d.inputs.iter().zip(&analysis.inputs) {
        for (stat, value, lo, hi) in [
            ("sobol_first", s.first, s.first_ci_low, s.first_ci_high),
            ("sobol_total", s.total, s.total_ci_low, s.total_ci_high),
        ] {
            rows.push(Row {
                stat: StatRow {
                    quantity: q.into(),
                    statistic: stat.into(),
                    threshold: f64::NAN,
                    value,
                    ci_low: lo,
                    ci_high: hi,
                    n: analysis.n,
                },
                input: input.column.clone(),
                probability: f64::NAN,
                confidence: level,
            });
        }
    }
    rows
}

/// The smallest sample a (coverage, confidence) tolerance bound needs (its extreme value).
pub fn tolerance_min_n(coverage: f64, confidence: f64) -> u64 {
    wilks_min_samples(coverage, confidence, 1)
}

/// Write `rows` to `path` atomically: quantity, statistic, input, threshold, probability,
/// confidence, value, ci_low, ci_high, n. Missing values are nulls.
pub fn write(
    path: &Path,
    rows: &[Row],
    metadata: Vec<(String, String)>,
) -> Result<u64, OutputError> {
    let specs = vec![
        ColumnSpec::new("quantity", ColumnKind::Utf8),
        ColumnSpec::new("statistic", ColumnKind::Utf8),
        ColumnSpec::optional("input", ColumnKind::Utf8),
        ColumnSpec::new("threshold", ColumnKind::F64),
        ColumnSpec::new("probability", ColumnKind::F64),
        ColumnSpec::new("confidence", ColumnKind::F64),
        ColumnSpec::new("value", ColumnKind::F64),
        ColumnSpec::new("ci_low", ColumnKind::F64),
        ColumnSpec::new("ci_high", ColumnKind::F64),
        ColumnSpec::new("n", ColumnKind::U64),
    ];
    let strings = |f: fn(&Row) -> &str| rows.iter().map(|r| f(r).to_string()).collect::<Vec<_>>();
    let floats = |f: fn(&Row) -> f64| rows.iter().map(f).collect::<Vec<_>>();
    let (quantity, statistic, input) = (
        strings(|r| &r.stat.quantity),
        strings(|r| &r.stat.statistic),
        strings(|r| &r.input),
    );
    let (threshold, value) = (floats(|r| r.stat.threshold), floats(|r| r.stat.value));
    let (probability, confidence) = (floats(|r| r.probability), floats(|r| r.confidence));
    let (lo, hi) = (floats(|r| r.stat.ci_low), floats(|r| r.stat.ci_high));
    let n: Vec<u64> = rows.iter().map(|r| r.stat.n).collect();
    let mut w = TableWriter::create(path, specs, metadata)?;
    w.write_chunk(&[
        ColumnData::Utf8(&quantity),
        ColumnData::Utf8(&statistic),
        ColumnData::Utf8(&input),
        ColumnData::F64(&threshold),
        ColumnData::F64(&probability),
        ColumnData::F64(&confidence),
        ColumnData::F64(&value),
        ColumnData::F64(&lo),
        ColumnData::F64(&hi),
        ColumnData::U64(&n),
    ])?;
    w.finish()
}

/// Look a statistic up (for the terminal summary and tests).
pub fn find<'a>(rows: &'a [Row], quantity: &str, statistic: &str) -> Option<&'a StatRow> {
    find_row(rows, quantity, statistic).map(|r| &r.stat)
}

/// Look a row up by quantity and statistic (no input).
pub fn find_row<'a>(rows: &'a [Row], quantity: &str, statistic: &str) -> Option<&'a Row> {
    rows.iter().find(|r| {
        r.stat.quantity == quantity && r.stat.statistic == statistic && r.input.is_empty()
    })
}
