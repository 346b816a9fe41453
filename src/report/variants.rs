//! `cryoslosh report DIR` for the results of a campaign with `[[variants]]`: each variant's own
//! report (its directory `DIR/variants/<name>/` is a complete run) under
//! `REPORT/variants/<name>/`, and a front page with the variants side by side — each one's
//! statistics of the QoIs a design trade is judged on, and the paired differences against the
//! baseline from `differences.parquet` with their paired and unpaired intervals.

use super::data::{self, unit_of, StatRow};
use super::html::{escape, num};
use super::{report, ReportError, ReportOptions, ReportSummary};
use crate::campaign::Campaign;
use crate::montecarlo::differences::{side_by_side_lines, DiffRow};
use crate::montecarlo::table;
use crate::montecarlo::variants::variant_dir;
use crate::output::results_dir::Staging;
use arrow_array::{Array, Float64Array, StringArray, UInt64Array};
use parquet::arrow::arrow_reader::ParquetRecordBatchReaderBuilder;
use std::fmt::Write as _;
use std::path::Path;

/// Every row of `differences.parquet` (nulls as NaN).
pub fn differences(path: &Path) -> Result<Vec<DiffRow>, ReportError> {
    let file = std::fs::File::open(path).map_err(|e| ReportError::read(path, e))?;
    let reader = ParquetRecordBatchReaderBuilder::try_new(file)
        .and_then(|b| b.build())
        .map_err(|e| ReportError::read(path, e))?;
    let bad = |name: &str, what: &str| {
        ReportError::Input(format!(
            "{}: {name} is missing or not {what}: not a cryoslosh differences file",
            path.display()
        ))
    };
    let mut rows = Vec::new();
    for batch in reader {
        let batch = batch.map_err(|e| ReportError::read(path, e))?;
        let strings = |name: &str| -> Result<StringArray, ReportError> {
            batch
                .column_by_name(name)
                .and_then(|c| c.as_any().downcast_ref::<StringArray>().cloned())
                .ok_or_else(|| bad(name, "text"))
        };
        let floats = |name: &str| -> Result<Vec<f64>, ReportError> {
            let a = batch
                .column_by_name(name)
                .and_then(|c| c.as_any().downcast_ref::<Float64Array>().cloned())
                .ok_or_else(|| bad(name, "f64"))?;
            Ok(a.iter().map(|v| v.unwrap_or(f64::NAN)).collect())
        };
        let [variant, baseline, quantity, statistic] =
            ["variant", "baseline", "quantity", "statistic"].map(strings);
        let (variant, baseline, quantity, statistic) = (variant?, baseline?, quantity?, statistic?);
        let [threshold, probability, confidence, value, lo, hi, ulo, uhi] = [
            "threshold",
            "probability",
            "confidence",
            "value",
            "ci_low",
            "ci_high",
            "unpaired_ci_low",
            "unpaired_ci_high",
        ]
        .map(floats);
        let n = batch
            .column_by_name("n")
            .and_then(|c| c.as_any().downcast_ref::<UInt64Array>().cloned())
            .ok_or_else(|| bad("n", "u64"))?;
        let (threshold, probability, confidence, value) =
            (threshold?, probability?, confidence?, value?);
        let (lo, hi, ulo, uhi) = (lo?, hi?, ulo?, uhi?);
        for r in 0..batch.num_rows() {
            rows.push(DiffRow {
                variant: variant.value(r).to_string(),
                baseline: baseline.value(r).to_string(),
                quantity: quantity.value(r).to_string(),
                statistic: statistic.value(r).to_string(),
                threshold: threshold[r],
                probability: probability[r],
                confidence: confidence[r],
                value: value[r],
                ci_low: lo[r],
                ci_high: hi[r],
                unpaired_ci_low: ulo[r],
                unpaired_ci_high: uhi[r],
                n: n.value(r),
            });
        }
    }
    Ok(rows)
}

/// A variant: its name, its overrides as `--set` spells them, its statistics.
struct Column {
    name: String,
    overrides: String,
    stats: Vec<StatRow>,
}

/// The report of the variants run in `dir` (see the module doc), published whole at
/// `opts.out` (default `dir/report`).
pub fn report_variants(dir: &Path, opts: &ReportOptions) -> Result<ReportSummary, ReportError> {
    let diff_path = dir.join("differences.parquet");
    let meta = table::read_metadata(&diff_path).map_err(|e| ReportError::read(&diff_path, e))?;
    let get = |key: &str| {
        meta.iter()
            .find(|(k, _)| k == key)
            .map(|(_, v)| v.clone())
            .unwrap_or_default()
    };
    let path = Some(get("cryoslosh.campaign_path"))
        .filter(|p| !p.is_empty())
        .unwrap_or_else(|| "campaign.toml".into());
    let campaign = Campaign::from_text(Path::new(&path), &get("cryoslosh.campaign"), &[])
        .map_err(|e| ReportError::Input(format!("{}: {e}", diff_path.display())))?;
    let rows = differences(&diff_path)?;
    let out = opts.out.clone().unwrap_or_else(|| dir.join("report"));
    let staging = Staging::begin_kind(&out, true, false, "index.html")?;
    let at = staging.path().to_path_buf();
    let (mut plots, mut replays) = (0, 0);
    let mut columns = Vec::new();
    for (k, v) in campaign.variants.iter().enumerate() {
        if opts.progress {
            let n = campaign.variants.len();
            crate::eprintln_lossy!("report: variant {} ({}/{n})", v.name, k + 1);
        }
        let own = variant_dir(dir, &v.name);
        let sub = ReportOptions {
            out: Some(at.join("variants").join(&v.name)),
            ..opts.clone()
        };
        let r = report(&own, &sub)?;
        plots += r.plots;
        replays += r.replays;
        columns.push(Column {
            name: v.name.clone(),
            overrides: v.describe(),
            stats: data::statistics(&own)?,
        });
    }
    // The variants' own staging left their lock files beside them (not part of the report).
    crate::montecarlo::variants::drop_locks(&at);
    let page = render(&campaign, dir, &get("cryoslosh.seed"), &columns, &rows);
    let index = at.join("index.html");
    std::fs::write(&index, page).map_err(|source| ReportError::Io {
        path: out.join("index.html"),
        source,
    })?;
    staging.publish()?;
    Ok(ReportSummary {
        out,
        plots,
        replays,
    })
}

/// The value of statistic `statistic` of `q` (at `threshold` for a probability) in `stats`.
fn value_of(stats: &[StatRow], q: &str, statistic: &str, threshold: f64) -> f64 {
    stats
        .iter()
        .find(|r| {
            r.quantity == q
                && r.statistic == statistic
                && r.input.is_none()
                && (!threshold.is_finite() || r.threshold == threshold)
        })
        .map_or(f64::NAN, |r| r.value)
}

/// A signed value (`+1.5`, `–` for none).
fn signed(v: f64) -> String {
    if v.is_finite() && v >= 0.0 {
        format!("+{}", num(v))
    } else {
        num(v)
    }
}

/// The front page.
fn render(c: &Campaign, dir: &Path, seed: &str, columns: &[Column], rows: &[DiffRow]) -> String {
    let mut h = String::new();
    let _ = write!(
        h,
        "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n\
         <title>cryoslosh report: {n} (variants)</title>\n<style>{style}</style>\n</head>\n\
         <body>\n<h1>Campaign <code>{n}</code>: {k} design variants</h1>\n",
        n = escape(&c.name),
        style = super::html::STYLE,
        k = columns.len()
    );
    let _ = writeln!(
        h,
        "<table class=\"kv\">\n<tr><th>results directory</th><td>{}</td></tr>\n\
         <tr><th>campaign file</th><td>{}</td></tr>\n<tr><th>seed</th><td>{}</td></tr>\n</table>",
        escape(&dir.display().to_string()),
        escape(&c.path.display().to_string()),
        escape(seed)
    );
    h.push_str(
        "<p class=\"note\">Every variant integrated the same dispersed instances (common random \
         numbers): row i of each variant's <code>instances.parquet</code> has the same inputs. \
         The first variant is the baseline of every difference.</p>\n\
         <table><tr><th>variant</th><th>overrides</th><th>report</th></tr>\n",
    );
    for (k, col) in columns.iter().enumerate() {
        let role = if k == 0 { " (baseline)" } else { "" };
        let _ = writeln!(
            h,
            "<tr><td>{n}{role}</td><td>{}</td><td><a href=\"variants/{n}/index.html\">\
             variants/{n}/</a></td></tr>",
            escape(&col.overrides),
            n = escape(&col.name)
        );
    }
    h.push_str("</table>\n");
    side_by_side(&mut h, columns, rows);
    paired(&mut h, columns, rows);
    h.push_str("</body>\n</html>\n");
    h
}

/// Each variant's mean and top quantile of every difference QoI, and its threshold
/// probabilities (`–`: no value, e.g. a QoI its fidelity does not model).
fn side_by_side(h: &mut String, columns: &[Column], rows: &[DiffRow]) {
    h.push_str(
        "<h2 id=\"statistics\">Statistics per variant</h2>\n<p class=\"note\">From each \
         variant's <code>statistics.parquet</code> (– where the variant has no value).</p>\n\
         <table><tr><th>quantity</th><th>statistic</th>",
    );
    for col in columns {
        let _ = write!(h, "<th>{}</th>", escape(&col.name));
    }
    h.push_str("</tr>\n");
    let second = columns.get(1).map(|c| c.name.as_str()).unwrap_or_default();
    let lines = side_by_side_lines(rows, second, |flag| {
        columns.iter().flat_map(|c| &c.stats).any(|r| {
            r.quantity == flag && r.statistic == "fraction" && r.input.is_none() && r.value > 0.0
        })
    });
    for (q, stat, threshold) in &lines {
        let label = if threshold.is_finite() {
            let op = if stat == "prob_exceed" {
                "&gt;"
            } else {
                "&lt;"
            };
            format!(
                "<td><code>{}</code> {op} {} {}</td><td>probability</td>",
                escape(q),
                num(*threshold),
                escape(unit_of(q))
            )
        } else {
            // A flag's fraction is a share of the variant's valid instances, not in a unit.
            let unit = if stat == "fraction" {
                "share of valid instances"
            } else {
                unit_of(q)
            };
            format!(
                "<td><code>{}</code> ({})</td><td>{}</td>",
                escape(q),
                escape(unit),
                escape(stat)
            )
        };
        let _ = write!(h, "<tr>{label}");
        for col in columns {
            let v = value_of(&col.stats, q, stat, *threshold);
            // As the run summary's table prints them (a 4-decimal probability showed a rare
            // exceedance as 0.0000 here and as a number there).
            let _ = write!(h, "<td>{}</td>", num(v));
        }
        h.push_str("</tr>\n");
    }
    h.push_str("</table>\n");
}

/// Every row of `differences.parquet`: variant − baseline with the paired interval (a bootstrap
/// of the pairs; Newcombe's paired score interval for a probability) and the unpaired one.
fn paired(h: &mut String, columns: &[Column], rows: &[DiffRow]) {
    let level = rows.first().map_or(0.95, |r| r.confidence);
    let _ = writeln!(
        h,
        "<h2 id=\"differences\">Paired differences against the baseline</h2>\n\
         <p class=\"note\"><code>differences.parquet</code>: variant − baseline over the pairs of \
         instances where both have a value (<code>n</code>; 0 and – where one of them has none), \
         with {:.0} % intervals: paired (what these common random numbers resolve) and unpaired \
         (what two independent campaigns of the same size would give).</p>",
        100.0 * level
    );
    for col in columns.iter().skip(1) {
        let _ = writeln!(
            h,
            "<h3><code>{}</code> − <code>{}</code></h3>\n<table><tr><th>quantity</th>\
             <th>statistic</th><th>threshold</th><th>difference</th><th>paired ci_low</th>\
             <th>paired ci_high</th><th>unpaired ci_low</th><th>unpaired ci_high</th><th>n</th></tr>",
            escape(&col.name),
            escape(&columns[0].name)
        );
        for r in rows.iter().filter(|r| r.variant == col.name) {
            let threshold = if r.threshold.is_finite() {
                format!("{} {}", num(r.threshold), unit_of(&r.quantity))
            } else {
                "–".into()
            };
            let _ = writeln!(
                h,
                "<tr><td><code>{}</code></td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td>\
                 <td>{}</td><td>{}</td><td>{}</td></tr>",
                escape(&r.quantity),
                escape(&r.statistic),
                escape(&threshold),
                signed(r.value),
                signed(r.ci_low),
                signed(r.ci_high),
                signed(r.unpaired_ci_low),
                signed(r.unpaired_ci_high),
                r.n
            );
        }
        h.push_str("</table>\n");
    }
}
