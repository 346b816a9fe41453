//! Campaign statistics from a finished `instances.parquet`, read back one column at a time
//! (bounded memory), written as the tidy `statistics.parquet`.
//!
//! Diverged and rejected instances are excluded from every statistic and counted separately.

use super::table::{read_bool, read_f64, ReadError, QOI_F64};
use crate::campaign::dispersion::Dispersions;
use crate::output::{ColumnData, ColumnKind, ColumnSpec, OutputError, TableWriter};
use crate::sampling::{saltelli_layout, Design, SaltelliRow};
use crate::stats::{describe, exceedance, sobol_indices, spearman, Direction, StatRow};
use std::path::Path;

/// A statistics row with the dispersed input it refers to (sensitivities), "" otherwise.
#[derive(Clone, Debug, PartialEq)]
pub struct Row {
    pub stat: StatRow,
    pub input: String,
}

fn plain(stat: StatRow) -> Row {
    Row {
        stat,
        input: String::new(),
    }
}

/// Thresholds of the exceedance probabilities.
#[derive(Clone, Copy, Debug)]
pub struct Thresholds {
    pub meop_pa: f64,
    pub boiloff_budget_kg: Option<f64>,
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

fn exceed_row(
    quantity: &str,
    statistic: &str,
    values: &[f64],
    threshold: f64,
    dir: Direction,
    level: f64,
) -> Row {
    let e = exceedance(values, threshold, dir, level);
    plain(StatRow {
        quantity: quantity.into(),
        statistic: statistic.into(),
        threshold,
        value: e.p,
        ci_low: e.ci_low,
        ci_high: e.ci_high,
        n: e.n,
    })
}

/// Every statistic of the campaign in `path`.
pub fn compute(
    path: &Path,
    d: &Dispersions,
    thresholds: Thresholds,
    total: u64,
) -> Result<Vec<Row>, ReadError> {
    let diverged = read_bool(path, "diverged")?;
    let rejected = read_bool(path, "rejected")?;
    let valid: Vec<bool> = diverged
        .iter()
        .zip(&rejected)
        .map(|(d, r)| !d && !r)
        .collect();
    let keep = |v: Vec<f64>| -> Vec<f64> {
        v.into_iter()
            .zip(&valid)
            .map(|(x, &ok)| if ok { x } else { f64::NAN })
            .collect()
    };
    let level = d.confidence;
    let mut rows = Vec::new();

    for (name, flags) in [("diverged", &diverged), ("rejected", &rejected)] {
        let ones: Vec<f64> = flags.iter().map(|&x| f64::from(u8::from(x))).collect();
        rows.push(exceed_row(
            name,
            "fraction",
            &ones,
            0.5,
            Direction::Above,
            level,
        ));
    }

    // Outcomes among the valid instances, with their Clopper–Pearson intervals.
    for name in ["depleted", "pressurant_exhausted"] {
        let ones: Vec<f64> = read_bool(path, name)?
            .iter()
            .map(|&x| f64::from(u8::from(x)))
            .collect();
        rows.push(exceed_row(
            name,
            "fraction",
            &keep(ones),
            0.5,
            Direction::Above,
            level,
        ));
    }

    // Tail probabilities of the design margins, computed while their column is loaded.
    let exceedances = [
        (
            "peak_pressure_pa",
            "prob_exceed",
            Some(thresholds.meop_pa),
            Direction::Above,
        ),
        (
            "min_cavitation_margin_m",
            "prob_below",
            Some(0.0),
            Direction::Below,
        ),
        (
            "boiloff_kg",
            "prob_exceed",
            thresholds.boiloff_budget_kg,
            Direction::Above,
        ),
    ];
    for (name, _) in QOI_F64 {
        let values = keep(read_f64(path, name)?);
        rows.extend(describe(name, &values).into_iter().map(plain));
        for (q, statistic, threshold, dir) in exceedances {
            if let Some(threshold) = threshold.filter(|_| q == name) {
                rows.push(exceed_row(name, statistic, &values, threshold, dir, level));
            }
        }
    }

    // One input column in memory at a time: at ten million rows each column is 80 MB and the
    // rank correlation needs several working copies.
    for input in &d.inputs {
        let x = keep(read_f64(path, &input.column)?);
        for q in SENSITIVITY_QOIS {
            let y = keep(read_f64(path, q)?);
            let n = x
                .iter()
                .zip(&y)
                .filter(|(a, b)| a.is_finite() && b.is_finite())
                .count() as u64;
            rows.push(Row {
                stat: StatRow {
                    quantity: q.into(),
                    statistic: "spearman".into(),
                    threshold: f64::NAN,
                    value: spearman(&x, &y),
                    ci_low: f64::NAN,
                    ci_high: f64::NAN,
                    n,
                },
                input: input.column.clone(),
            });
        }
    }
    if d.design == Design::Saltelli && !d.inputs.is_empty() {
        for q in SENSITIVITY_QOIS {
            rows.extend(sobol_rows(q, &keep(read_f64(path, q)?), d, total));
        }
    }
    Ok(rows)
}

/// Sobol first-order and total indices of `q` from the Saltelli rows (instance order).
fn sobol_rows(q: &str, y: &[f64], d: &Dispersions, total: u64) -> Vec<Row> {
    let k = d.inputs.len();
    let bases = (total as usize) / (k + 2);
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
    let mut rows = Vec::new();
    for (input, fab) in d.inputs.iter().zip(&f_ab) {
        let s = sobol_indices(&f_a, &f_b, fab);
        for (stat, value) in [("sobol_first", s.first), ("sobol_total", s.total)] {
            rows.push(Row {
                stat: StatRow {
                    quantity: q.into(),
                    statistic: stat.into(),
                    threshold: f64::NAN,
                    value,
                    ci_low: f64::NAN,
                    ci_high: f64::NAN,
                    n: bases as u64,
                },
                input: input.column.clone(),
            });
        }
    }
    rows
}

/// Write `rows` to `path` atomically: quantity, statistic, input, threshold, value, ci_low,
/// ci_high, n.
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
    let (lo, hi) = (floats(|r| r.stat.ci_low), floats(|r| r.stat.ci_high));
    let n: Vec<u64> = rows.iter().map(|r| r.stat.n).collect();
    let mut w = TableWriter::create(path, specs, metadata)?;
    w.write_chunk(&[
        ColumnData::Utf8(&quantity),
        ColumnData::Utf8(&statistic),
        ColumnData::Utf8(&input),
        ColumnData::F64(&threshold),
        ColumnData::F64(&value),
        ColumnData::F64(&lo),
        ColumnData::F64(&hi),
        ColumnData::U64(&n),
    ])?;
    w.finish()
}

/// Look a statistic up (for the terminal summary and tests).
pub fn find<'a>(rows: &'a [Row], quantity: &str, statistic: &str) -> Option<&'a StatRow> {
    rows.iter()
        .find(|r| {
            r.stat.quantity == quantity && r.stat.statistic == statistic && r.input.is_empty()
        })
        .map(|r| &r.stat)
}
