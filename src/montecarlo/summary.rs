//! The terminal summary of a run: counts, the margins with their intervals and tolerance bounds,
//! tail probabilities, outcomes, and the drivers of each margin with their intervals.

use super::statistics::{find, find_row, tolerance_min_n, Row, SENSITIVITY_QOIS};
use super::RunReport;
use crate::campaign::statistics::quantile_name;
use std::fmt::Write;

/// A value as the summary prints it: `digits` decimals, "–" for a missing one, never "-0.00".
fn num(v: f64, digits: usize) -> String {
    if v.is_finite() {
        let s = format!("{v:.digits$}");
        match s.strip_prefix('-') {
            Some(rest) if rest.chars().all(|c| c == '0' || c == '.') => rest.to_string(),
            _ => s,
        }
    } else {
        "–".into()
    }
}

/// A correlation with its sign, two decimals ("+0.00", never "-0.00").
fn signed(v: f64) -> String {
    let s = num(v, 2);
    if s.starts_with('-') || s == "–" {
        s
    } else {
        format!("+{s}")
    }
}

/// `X [lo, hi]` of a row (the interval only where it exists).
fn with_interval(r: &Row, digits: usize) -> String {
    let s = &r.stat;
    if s.ci_low.is_finite() || s.ci_high.is_finite() {
        format!(
            "{} [{}, {}]",
            num(s.value, digits),
            num(s.ci_low, digits),
            num(s.ci_high, digits)
        )
    } else {
        num(s.value, digits)
    }
}

/// The tolerance bounds of `q` on `side` (`tolerance_upper` / `_lower`), or the sample size each
/// needs when there are too few valid instances.
fn tolerance(rows: &[Row], q: &str, side: &str, digits: usize) -> String {
    let statistic = format!("tolerance_{side}");
    let parts: Vec<String> = rows
        .iter()
        .filter(|r| r.stat.quantity == q && r.stat.statistic == statistic)
        .map(|r| {
            let level = format!(
                "{}/{}",
                crate::campaign::number(100.0 * r.probability),
                crate::campaign::number(100.0 * r.confidence)
            );
            if r.stat.value.is_finite() {
                format!("{level} {side} bound {}", num(r.stat.value, digits))
            } else {
                format!(
                    "{level} {side} bound needs ≥ {} valid instances (have {})",
                    tolerance_min_n(r.probability, r.confidence),
                    r.stat.n
                )
            }
        })
        .collect();
    parts.join("; ")
}

/// `P = p [lo, hi]` of a probability row with its threshold.
fn probability(r: &Row) -> String {
    let s = &r.stat;
    format!(
        "P = {:.4} [{:.4}, {:.4}] at {}",
        s.value, s.ci_low, s.ci_high, s.threshold
    )
}

/// The terminal summary: margins, tail probabilities, top drivers.
pub fn summary_text(r: &RunReport) -> String {
    let s = &r.statistics;
    // The rate is of the work done now: a resumed run's steps from its checkpoint took no time.
    let mut out = format!(
        "{} instance{} ({} diverged, {} rejected), {} on {}\n",
        r.instances,
        if r.instances == 1 { "" } else { "s" },
        r.diverged,
        r.rejected,
        r.cost_text(),
        r.device
    );
    if !r.dispersed {
        out += "note: the campaign has no [dispersions]: every instance is the nominal\n";
    }
    if let Some((u, json)) = &r.until {
        let _ = writeln!(out, "until              {u}");
        if json["reached"] == false {
            out += "warning: the precision target was not reached: raise --instances or relax it\n";
        }
    }
    if !r.rejected_by.is_empty() {
        let list: Vec<String> = r
            .rejected_by
            .iter()
            .map(|(k, n)| format!("{k} {n}"))
            .collect();
        let _ = writeln!(out, "rejected by        {}", list.join(", "));
    }
    let valid = find(s, "peak_pressure_pa", "mean").map_or(0, |x| x.n);
    if valid == 0 {
        out += "no valid instance: every statistic is null\n";
        return out;
    }
    let stat = |q: &str, st: &str| find(s, q, st).map_or(f64::NAN, |x| x.value);
    let quantile = |q: &str, p: f64, digits: usize| {
        let name = quantile_name(p);
        find_row(s, q, &name).map_or_else(String::new, |row| {
            format!("{name} {}", with_interval(row, digits))
        })
    };
    let prob = |q: &str, st: &str| find_row(s, q, st).map_or_else(String::new, probability);
    // "p50 X unit  p99 X [lo, hi] unit  max X unit": the pieces the campaign's quantiles have.
    let pieces = |q: &str, ps: &[f64], extreme: &str, digits: usize, unit: &str| {
        let mut v: Vec<String> = ps
            .iter()
            .map(|&p| quantile(q, p, digits))
            .filter(|x| !x.is_empty())
            .map(|x| format!("{x} {unit}"))
            .collect();
        v.push(format!(
            "{extreme} {} {unit}",
            num(stat(q, extreme), digits)
        ));
        v.join("  ")
    };
    let _ = writeln!(
        out,
        "peak pressure      {}; above MEOP: {}",
        pieces("peak_pressure_pa", &[0.5, 0.99], "max", 0, "Pa"),
        prob("peak_pressure_pa", "prob_exceed")
    );
    let tol = tolerance(s, "peak_pressure_pa", "upper", 0);
    if !tol.is_empty() {
        let _ = writeln!(out, "                   {tol} (Pa)");
    }
    if find(s, "min_cavitation_margin_m", "mean").is_some_and(|x| x.n > 0) {
        let _ = writeln!(
            out,
            "cavitation margin  {}; below 0: {}",
            pieces("min_cavitation_margin_m", &[0.01, 0.5], "min", 3, "m"),
            prob("min_cavitation_margin_m", "prob_below")
        );
        let tol = tolerance(s, "min_cavitation_margin_m", "lower", 3);
        if !tol.is_empty() {
            let _ = writeln!(out, "                   {tol} (m)");
        }
    }
    let budget = find_row(s, "boiloff_kg", "prob_exceed").map_or_else(String::new, |row| {
        format!("; over budget: {}", probability(row))
    });
    let _ = writeln!(
        out,
        "boil-off           {}{budget}",
        pieces("boiloff_kg", &[0.5, 0.99], "max", 4, "kg"),
    );
    let _ = writeln!(
        out,
        "vented             {};  max slosh angle {} rad",
        pieces("vented_kg", &[0.5, 0.99], "max", 4, "kg"),
        num(stat("max_slosh_angle_rad", "max"), 4)
    );
    // The campaign's own thresholds (the three above are printed with their margins).
    let shown = |q: &str| {
        matches!(
            q,
            "peak_pressure_pa" | "min_cavitation_margin_m" | "boiloff_kg"
        )
    };
    for row in s.iter().filter(|x| {
        matches!(x.stat.statistic.as_str(), "prob_exceed" | "prob_below")
            && (!shown(&x.stat.quantity)
                || find_row(s, &x.stat.quantity, &x.stat.statistic)
                    .is_some_and(|f| !std::ptr::eq(f, *x)))
    }) {
        let side = if row.stat.statistic == "prob_exceed" {
            ">"
        } else {
            "<"
        };
        let st = &row.stat;
        if st.n == 0 {
            let _ = writeln!(
                out,
                "P({} {side} {}): no valid instance has a value of {}",
                st.quantity, st.threshold, st.quantity
            );
            continue;
        }
        let _ = writeln!(
            out,
            "P({} {side} {}) = {:.4} [{:.4}, {:.4}] of {}",
            st.quantity, st.threshold, st.value, st.ci_low, st.ci_high, st.n
        );
    }
    for (name, what) in [
        ("depleted", "ran dry (depleted)"),
        ("pressurant_exhausted", "pressurant exhausted"),
        ("slosh_out_of_range", "slosh out of range"),
    ] {
        if let Some(x) = find(s, name, "fraction").filter(|x| x.value > 0.0) {
            let _ = writeln!(
                out,
                "{what:18} P = {:.4} [{:.4}, {:.4}] of {} valid instances",
                x.value, x.ci_low, x.ci_high, x.n
            );
        }
    }
    drivers(&mut out, r);
    for note in &r.histories {
        let _ = writeln!(out, "history            {note}");
    }
    out
}

/// Spearman drivers of each margin with their intervals (or "constant"), then the Sobol indices
/// under a Saltelli design, warning when diverged or rejected instances broke groups.
fn drivers(out: &mut String, r: &RunReport) {
    let s = &r.statistics;
    let empty: Vec<&str> = SENSITIVITY_QOIS
        .into_iter()
        .filter(|q| find(s, q, "mean").is_some_and(|m| m.n == 0))
        .collect();
    if !empty.is_empty() {
        let _ = writeln!(
            out,
            "no value in any valid instance (not modelled at this fidelity, or no valid instance), \
             so no drivers: {}",
            empty.join(", ")
        );
    }
    let constant: Vec<&str> = SENSITIVITY_QOIS
        .into_iter()
        .filter(|q| find(s, q, "constant").is_some())
        .collect();
    if !constant.is_empty() {
        let _ = writeln!(
            out,
            "constant across the valid instances (spread below rounding), so no drivers: {}",
            constant.join(", ")
        );
    }
    for q in SENSITIVITY_QOIS {
        if constant.contains(&q) {
            continue;
        }
        let mut rho: Vec<&Row> = s
            .iter()
            .filter(|x| {
                x.stat.quantity == q && x.stat.statistic == "spearman" && x.stat.value.is_finite()
            })
            .collect();
        rho.sort_by(|a, b| b.stat.value.abs().total_cmp(&a.stat.value.abs()));
        if !rho.is_empty() {
            let top: Vec<String> = rho
                .iter()
                .take(3)
                .map(|d| {
                    format!(
                        "{} {} [{}, {}]",
                        d.input,
                        signed(d.stat.value),
                        signed(d.stat.ci_low),
                        signed(d.stat.ci_high)
                    )
                })
                .collect();
            let _ = writeln!(out, "drivers of {q:24} (Spearman) {}", top.join(", "));
        }
        let mut sobol: Vec<&Row> = s
            .iter()
            .filter(|x| x.stat.quantity == q && x.stat.statistic == "sobol_total")
            .collect();
        if sobol.is_empty() {
            continue;
        }
        sobol.sort_by(|a, b| b.stat.value.total_cmp(&a.stat.value));
        let groups = sobol[0].stat.n;
        let top: Vec<String> = sobol
            .iter()
            .take(3)
            .map(|t| {
                let first = s
                    .iter()
                    .find(|x| {
                        x.stat.quantity == q
                            && x.stat.statistic == "sobol_first"
                            && x.input == t.input
                    })
                    .map_or_else(String::new, |f| format!("S1 {}", with_interval(f, 2)));
                format!("{} {first} ST {}", t.input, with_interval(t, 2))
            })
            .collect();
        let _ = writeln!(out, "Sobol of {q:26} ({groups} groups) {}", top.join("; "));
        let k = s
            .iter()
            .filter(|x| x.stat.quantity == q && x.stat.statistic == "sobol_total")
            .count() as u64;
        let all = r.instances / (k + 2);
        if groups < all {
            let _ = writeln!(
                out,
                "warning: the Sobol indices of {q} come from {groups} of {all} groups: {} were \
                 broken by diverged or rejected instances",
                all - groups
            );
        }
    }
}
