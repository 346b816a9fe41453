//! Paired differences of design variants against the baseline (the first variant), from the
//! variants' `instances.parquet` files whose row i is instance i under the same dispersed
//! inputs: `differences.parquet` and the side-by-side table of the run summary.
//!
//! Per variant and QoI of [`DIFFERENCE_QOIS`]: `mean_diff` and `<pNN>_diff` (the plan's
//! quantiles) with paired and unpaired percentile-bootstrap intervals, and per threshold of the
//! baseline campaign `prob_exceed_diff` / `prob_below_diff` with Newcombe's paired hybrid score
//! interval (and the unpaired one). Only pairs where both instances are valid count (`n`).
//! Every value is a function of the rows and the seed only: bit-identical for any thread count,
//! shard split or merge.

use super::statistics::{self as st, Spec};
use super::table::{read_f64, ReadError};
use crate::campaign::statistics::{quantile_name, Side, Threshold};
use crate::output::{ColumnData, ColumnKind, ColumnSpec, OutputError, TableWriter};
use crate::stats::{newcombe_paired, newcombe_unpaired, paired_differences, PairedTable};
use rayon::prelude::*;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// QoIs whose differences are reported: the margins a design trade is judged on.
pub const DIFFERENCE_QOIS: [&str; 9] = [
    "peak_pressure_pa",
    "boiloff_kg",
    "vented_kg",
    "tvs_vented_kg",
    "pressurant_used_kg",
    "min_cavitation_margin_m",
    "max_slosh_angle_rad",
    "peak_slosh_force_n",
    "final_stratification_k",
];

/// A row of `differences.parquet` (NaN: null).
#[derive(Clone, Debug, PartialEq)]
pub struct DiffRow {
    pub variant: String,
    pub baseline: String,
    pub quantity: String,
    /// `mean_diff`, `<pNN>_diff`, `prob_exceed_diff`, `prob_below_diff`.
    pub statistic: String,
    pub threshold: f64,
    /// The quantile's p.
    pub probability: f64,
    pub confidence: f64,
    /// variant − baseline.
    pub value: f64,
    /// The paired interval.
    pub ci_low: f64,
    pub ci_high: f64,
    /// The interval two independent samples of the same size would give.
    pub unpaired_ci_low: f64,
    pub unpaired_ci_high: f64,
    /// Pairs used.
    pub n: u64,
}

/// Bootstrap seed of (variant k, quantity j): distinct streams, fixed by the campaign seed.
fn stream_seed(seed: u64, k: usize, j: usize) -> u64 {
    let tag = ((k as u64) << 32) | j as u64;
    seed ^ tag.wrapping_add(1).wrapping_mul(0x9E37_79B9_7F4A_7C15)
}

/// The differences of every variant's `instances.parquet` (`files[0]` the baseline) against the
/// baseline, with the baseline's `spec` (its thresholds, confidence, quantiles, resamples, seed).
pub fn compute(
    names: &[String],
    files: &[PathBuf],
    spec: &Spec,
) -> Result<Vec<DiffRow>, ReadError> {
    let plan = &spec.plan;
    let level = plan.confidence;
    let columns: Vec<Vec<Vec<f64>>> = files
        .iter()
        .map(|f| DIFFERENCE_QOIS.iter().map(|q| read_f64(f, q)).collect())
        .collect::<Result<_, _>>()?;
    let thresholds: Vec<Threshold> = st::thresholds(spec)
        .into_iter()
        .filter(|t| DIFFERENCE_QOIS.contains(&t.quantity.as_str()))
        .collect();
    let tasks: Vec<(usize, usize)> = (1..files.len())
        .flat_map(|k| (0..DIFFERENCE_QOIS.len()).map(move |j| (k, j)))
        .collect();
    let blocks: Vec<Vec<DiffRow>> = tasks
        .par_iter()
        .map(|&(k, j)| {
            let (base, var) = (&columns[0][j], &columns[k][j]);
            let row =
                |statistic: String, value, paired: (f64, f64), unpaired: (f64, f64), n| DiffRow {
                    variant: names[k].clone(),
                    baseline: names[0].clone(),
                    quantity: DIFFERENCE_QOIS[j].into(),
                    statistic,
                    threshold: f64::NAN,
                    probability: f64::NAN,
                    confidence: level,
                    value,
                    ci_low: paired.0,
                    ci_high: paired.1,
                    unpaired_ci_low: unpaired.0,
                    unpaired_ci_high: unpaired.1,
                    n,
                };
            let d = paired_differences(
                base,
                var,
                &plan.quantiles,
                level,
                plan.bootstrap as usize,
                stream_seed(spec.seed, k, j),
            );
            let mut rows = vec![row(
                "mean_diff".into(),
                d.mean.value,
                d.mean.paired,
                d.mean.unpaired,
                d.n,
            )];
            for (p, e) in plan.quantiles.iter().zip(&d.quantiles) {
                rows.push(DiffRow {
                    probability: *p,
                    ..row(
                        format!("{}_diff", quantile_name(*p)),
                        e.value,
                        e.paired,
                        e.unpaired,
                        d.n,
                    )
                });
            }
            for t in thresholds
                .iter()
                .filter(|t| t.quantity == DIFFERENCE_QOIS[j])
            {
                let hit = |x: f64| match t.side {
                    Side::Above => x > t.value,
                    Side::Below => x < t.value,
                };
                let mut table = PairedTable::default();
                for (&b, &v) in base.iter().zip(var) {
                    if !(b.is_finite() && v.is_finite()) {
                        continue;
                    }
                    match (hit(v), hit(b)) {
                        (true, true) => table.both += 1,
                        (true, false) => table.only_first += 1,
                        (false, true) => table.only_second += 1,
                        (false, false) => table.neither += 1,
                    }
                }
                let n = table.n();
                let (kv, kb) = (
                    table.both + table.only_first,
                    table.both + table.only_second,
                );
                let statistic = match t.side {
                    Side::Above => "prob_exceed_diff",
                    Side::Below => "prob_below_diff",
                };
                rows.push(DiffRow {
                    threshold: t.value,
                    ..row(
                        statistic.into(),
                        table.difference(),
                        newcombe_paired(&table, level),
                        newcombe_unpaired(kv, n, kb, n, level),
                        n,
                    )
                });
            }
            rows
        })
        .collect();
    Ok(blocks.into_iter().flatten().collect())
}

/// Write `rows` atomically: variant, baseline, quantity, statistic, threshold, probability,
/// confidence, value, ci_low, ci_high, unpaired_ci_low, unpaired_ci_high, n (NaN → null).
pub fn write(
    path: &Path,
    rows: &[DiffRow],
    metadata: Vec<(String, String)>,
) -> Result<u64, OutputError> {
    let specs = vec![
        ColumnSpec::new("variant", ColumnKind::Utf8),
        ColumnSpec::new("baseline", ColumnKind::Utf8),
        ColumnSpec::new("quantity", ColumnKind::Utf8),
        ColumnSpec::new("statistic", ColumnKind::Utf8),
        ColumnSpec::new("threshold", ColumnKind::F64),
        ColumnSpec::new("probability", ColumnKind::F64),
        ColumnSpec::new("confidence", ColumnKind::F64),
        ColumnSpec::new("value", ColumnKind::F64),
        ColumnSpec::new("ci_low", ColumnKind::F64),
        ColumnSpec::new("ci_high", ColumnKind::F64),
        ColumnSpec::new("unpaired_ci_low", ColumnKind::F64),
        ColumnSpec::new("unpaired_ci_high", ColumnKind::F64),
        ColumnSpec::new("n", ColumnKind::U64),
    ];
    let strings =
        |f: fn(&DiffRow) -> &str| rows.iter().map(|r| f(r).to_string()).collect::<Vec<_>>();
    let floats = |f: fn(&DiffRow) -> f64| rows.iter().map(f).collect::<Vec<_>>();
    let n: Vec<u64> = rows.iter().map(|r| r.n).collect();
    let mut w = TableWriter::create(path, specs, metadata)?;
    w.write_chunk(&[
        ColumnData::Utf8(&strings(|r| &r.variant)),
        ColumnData::Utf8(&strings(|r| &r.baseline)),
        ColumnData::Utf8(&strings(|r| &r.quantity)),
        ColumnData::Utf8(&strings(|r| &r.statistic)),
        ColumnData::F64(&floats(|r| r.threshold)),
        ColumnData::F64(&floats(|r| r.probability)),
        ColumnData::F64(&floats(|r| r.confidence)),
        ColumnData::F64(&floats(|r| r.value)),
        ColumnData::F64(&floats(|r| r.ci_low)),
        ColumnData::F64(&floats(|r| r.ci_high)),
        ColumnData::F64(&floats(|r| r.unpaired_ci_low)),
        ColumnData::F64(&floats(|r| r.unpaired_ci_high)),
        ColumnData::U64(&n),
    ])?;
    w.finish()
}

/// Six significant digits, `–` for a missing value.
fn num(v: f64) -> String {
    if v.is_finite() {
        crate::campaign::number(v)
    } else {
        "–".into()
    }
}

/// A signed difference with its interval: `+1.5 [+0.2, +2.9]`.
fn signed(v: f64, lo: f64, hi: f64) -> String {
    let s = |x: f64| {
        if x.is_finite() {
            format!("{}{}", if x >= 0.0 { "+" } else { "" }, num(x))
        } else {
            "–".into()
        }
    };
    format!("{} [{}, {}]", s(v), s(lo), s(hi))
}

/// The highest quantile probability among the differences (NaN without one): the quantile the
/// side-by-side tables show beside the mean.
pub fn top_probability(rows: &[DiffRow]) -> f64 {
    rows.iter()
        .filter(|r| r.statistic.ends_with("_diff") && r.probability.is_finite())
        .map(|r| r.probability)
        .fold(f64::NAN, f64::max)
}

/// The rows of a side-by-side table of the variants (the run summary's and the report's), as
/// (quantity, statistic, threshold; NaN for none): the mean and [`top_probability`] quantile of
/// every [`DIFFERENCE_QOIS`], the threshold probabilities compared for variant `second`, then
/// the outcome and validity flags for which `raised(flag)` (some variant has a share above 0).
/// A variant mostly `slosh_out_of_range` (the unbaffled trade baseline) compares numbers the
/// model does not stand behind, and a table without the flag said nothing of it.
pub fn side_by_side_lines(
    rows: &[DiffRow],
    second: &str,
    raised: impl Fn(&str) -> bool,
) -> Vec<(String, String, f64)> {
    let top = top_probability(rows);
    let mut lines: Vec<(String, String, f64)> = Vec::new();
    for q in DIFFERENCE_QOIS {
        lines.push((q.into(), "mean".into(), f64::NAN));
        if top.is_finite() {
            lines.push((q.into(), quantile_name(top), f64::NAN));
        }
    }
    for r in rows.iter().filter(|r| r.variant == second) {
        if let Some(stat) = r.statistic.strip_suffix("_diff") {
            if stat.starts_with("prob_") {
                lines.push((r.quantity.clone(), stat.to_string(), r.threshold));
            }
        }
    }
    for flag in ["depleted", "pressurant_exhausted", "slosh_out_of_range"] {
        if raised(flag) {
            lines.push((flag.into(), "fraction".into(), f64::NAN));
        }
    }
    lines
}

/// The side-by-side table of the run summary: each variant's mean and upper quantile of every
/// difference QoI and its threshold probabilities, then each variant's paired differences
/// against the baseline with the paired interval and, for the mean, the unpaired one.
pub fn side_by_side(names: &[String], stats: &[Vec<st::Row>], rows: &[DiffRow]) -> String {
    let mut out = String::new();
    let width = names.iter().map(String::len).max().unwrap_or(8).max(12) + 2;
    let _ = write!(out, "{:<34}", "variants (same dispersed inputs)");
    for n in names {
        let _ = write!(out, "{n:>width$}");
    }
    out.push('\n');
    let top = top_probability(rows);
    let second = names.get(1).map(String::as_str).unwrap_or_default();
    let lines = side_by_side_lines(rows, second, |flag| {
        stats.iter().flatten().any(|r| {
            r.stat.quantity == flag && r.stat.statistic == "fraction" && r.stat.value > 0.0
        })
    });
    for (q, stat, threshold) in &lines {
        let label = if threshold.is_finite() {
            let op = if stat == "prob_exceed" { ">" } else { "<" };
            format!("P({q} {op} {})", num(*threshold))
        } else {
            format!("{q} {stat}")
        };
        let _ = write!(out, "{label:<34}");
        for s in stats {
            let v = s
                .iter()
                .find(|r| {
                    &r.stat.quantity == q
                        && &r.stat.statistic == stat
                        && r.input.is_empty()
                        && (!threshold.is_finite() || r.stat.threshold == *threshold)
                })
                .map_or(f64::NAN, |r| r.stat.value);
            let _ = write!(out, "{:>width$}", num(v));
        }
        out.push('\n');
    }
    let level = rows.first().map_or(0.95, |r| r.confidence);
    for v in names.iter().skip(1) {
        let _ = writeln!(
            out,
            "{v} − {}, paired over the same instances ({:.0} % intervals):",
            names[0],
            100.0 * level
        );
        for r in rows.iter().filter(|r| &r.variant == v) {
            let top_row = r.probability == top;
            if !(r.statistic == "mean_diff" || top_row || r.statistic.starts_with("prob_")) {
                continue;
            }
            let label = if r.threshold.is_finite() {
                let op = if r.statistic == "prob_exceed_diff" {
                    ">"
                } else {
                    "<"
                };
                format!("  ΔP({} {op} {})", r.quantity, num(r.threshold))
            } else {
                format!(
                    "  Δ{} {}",
                    r.quantity,
                    r.statistic.trim_end_matches("_diff")
                )
            };
            let _ = writeln!(
                out,
                "{label:<40}{:<40} unpaired [{}, {}]  n {}",
                signed(r.value, r.ci_low, r.ci_high),
                num(r.unpaired_ci_low),
                num(r.unpaired_ci_high),
                r.n
            );
        }
    }
    out
}
