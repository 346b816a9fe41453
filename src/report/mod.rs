//! `cryoslosh report DIR`: a results directory (a run or a merge) as a designer reads it — a
//! static `index.html` with SVG plots beside it (no network, no script): the run's header, each
//! QoI's histogram and exceedance curve with the campaign's thresholds and the statistics
//! file's quantiles, the sensitivities, every probability, and the worst instances' time
//! histories re-simulated by exact replay. A run with `[[variants]]` gets one report per
//! variant and a front page comparing them (`variants.rs`).
//!
//! Memory stays bounded by one instances column at a time (and its sorted copy): QoIs are read,
//! drawn and dropped one after another; everything else comes from `statistics.parquet`. The
//! report directory is published whole or not at all, like a results directory
//! ([`crate::output::results_dir::Staging`]).

pub mod data;
mod html;
pub mod plots;
mod sensitivity;
pub mod variants;
mod worst;

use crate::output::results_dir::{ResultsDirError, Staging};
use data::StatRow;
use plots::{Marker, MARKER_COLOURS};
use sensitivity::{sensitivity, sensitivity_qois, SensitivitySection};
use std::path::{Path, PathBuf};

pub use worst::HEADLINE;

/// Why a report could not be written.
#[derive(Debug, thiserror::Error)]
pub enum ReportError {
    /// The directory is not a results directory, or a file in it is not what cryoslosh writes.
    #[error("{0}")]
    Input(String),
    /// A file of the results directory could not be read.
    #[error("cannot read {path}: {message}")]
    Read { path: PathBuf, message: String },
    /// A plot could not be drawn or written.
    #[error("cannot draw {path}: {message}")]
    Plot { path: PathBuf, message: String },
    /// The exact replay of a worst instance failed.
    #[error("replaying instance {instance} for its time history: {message}")]
    Replay { instance: u64, message: String },
    /// The report directory could not be staged or published.
    #[error(transparent)]
    Dir(#[from] ResultsDirError),
    /// Writing a file of the report failed.
    #[error("cannot write {path}: {source}")]
    Io {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
}

impl ReportError {
    /// Whether the error is the user's input (exit code 2) rather than a runtime failure.
    pub fn is_bad_input(&self) -> bool {
        match self {
            ReportError::Input(_) => true,
            ReportError::Dir(e) => !matches!(e, ResultsDirError::Io { .. }),
            _ => false,
        }
    }

    pub(crate) fn read(path: &Path, e: impl std::fmt::Display) -> Self {
        ReportError::Read {
            path: path.to_path_buf(),
            message: e.to_string(),
        }
    }
}

/// What to write.
#[derive(Clone, Debug, Default)]
pub struct ReportOptions {
    /// The report directory (default: `DIR/report`); a previous report there is replaced.
    pub out: Option<PathBuf>,
    /// Re-simulate and draw the worst instance of each headline QoI.
    pub worst_cases: bool,
    /// A line on stderr per re-simulation.
    pub progress: bool,
}

/// What was written.
#[derive(Clone, Debug)]
pub struct ReportSummary {
    /// The report directory.
    pub out: PathBuf,
    /// SVG files written.
    pub plots: usize,
    /// Worst instances re-simulated.
    pub replays: usize,
}

/// One QoI's section: its plots and its statistics rows.
#[derive(Debug)]
pub(crate) struct QoiSection {
    pub name: String,
    pub n: usize,
    pub histogram: String,
    pub exceedance: String,
    /// Thresholds outside the plotted range, named for the caption.
    pub off_scale: Vec<String>,
    pub rows: Vec<StatRow>,
}

/// File-name form of a column name (`peak_pressure_pa.burn` → `peak_pressure_pa-burn`).
pub(crate) fn file_stem(column: &str) -> String {
    column
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '_' {
                c
            } else {
                '-'
            }
        })
        .collect()
}

/// Write the report of the results directory `dir` (of a run with `[[variants]]`: each
/// variant's report and the front page of [`variants::report_variants`]).
pub fn report(dir: &Path, opts: &ReportOptions) -> Result<ReportSummary, ReportError> {
    if crate::montecarlo::variants::is_variants_dir(dir) {
        return variants::report_variants(dir, opts);
    }
    let info = data::run_info(dir)?;
    let stats = data::statistics(dir)?;
    let out = opts.out.clone().unwrap_or_else(|| dir.join("report"));
    let staging = Staging::begin_kind(&out, true, false, "index.html")?;
    let at = staging.path().to_path_buf();
    let confidence = stats
        .iter()
        .map(|r| r.confidence)
        .find(|c| c.is_finite())
        .unwrap_or(0.95);
    let mut plots = 0usize;
    let mut sections = Vec::new();
    let mut skipped = Vec::new();
    for q in info.qoi_columns() {
        let sorted = data::sorted_column(&info, &q)?;
        if sorted.is_empty() {
            skipped.push(format!("{q}: no value in any valid instance"));
            continue;
        }
        if crate::stats::is_constant(&sorted) {
            let unit = match data::unit_of(&q) {
                "1" => String::new(),
                u => format!(" {u}"),
            };
            skipped.push(format!(
                "{q}: constant at {}{unit}",
                plots::fmt_tick(sorted[0])
            ));
            continue;
        }
        let markers = thresholds(&stats, &q);
        let stem = file_stem(&q);
        let (hist, exc) = (format!("hist_{stem}.svg"), format!("exceed_{stem}.svg"));
        plots::histogram(
            &at.join(&hist),
            &q,
            &data::histogram(&sorted),
            sorted.len(),
            &markers,
        )?;
        // A margin (`min_…`) is read from its low tail.
        let lower = crate::montecarlo::histories::worst_is_smallest(&q);
        let curve = data::exceedance(&sorted, confidence, lower);
        plots::exceedance(&at.join(&exc), &q, &curve, confidence, &markers, lower)?;
        plots += 2;
        let (_, shown) = plots::x_span(sorted[0], sorted[sorted.len() - 1], &markers);
        let off_scale = markers
            .iter()
            .filter(|m| !shown.iter().any(|s| s.x == m.x))
            .map(|m| m.label.clone())
            .collect();
        sections.push(QoiSection {
            n: sorted.len(),
            rows: stats
                .iter()
                .filter(|r| r.quantity == q && is_distribution_row(&r.statistic))
                .cloned()
                .collect(),
            name: q,
            histogram: hist,
            exceedance: exc,
            off_scale,
        });
    }
    let varying: Vec<String> = sections.iter().map(|s| s.name.clone()).collect();
    let mut sensitivities = Vec::new();
    for q in sensitivity_qois(&stats, &varying) {
        let s = sensitivity(&info, &stats, &q, &at)?;
        plots += usize::from(s.spearman.is_some())
            + usize::from(s.sobol.is_some())
            + usize::from(s.scatter.is_some());
        sensitivities.push(s);
    }
    let probabilities: Vec<StatRow> = stats
        .iter()
        .filter(|r| {
            matches!(
                r.statistic.as_str(),
                "prob_exceed" | "prob_below" | "fraction"
            )
        })
        .cloned()
        .collect();
    let (worst, worst_notes) = if opts.worst_cases {
        let headline: Vec<String> = HEADLINE
            .iter()
            .filter(|h| varying.iter().any(|v| v == *h))
            .map(|h| h.to_string())
            .collect();
        worst::worst_cases(&info, &headline, &at, opts.progress)?
    } else {
        (
            Vec::new(),
            vec!["worst cases not re-simulated (--no-worst-cases)".into()],
        )
    };
    plots += worst.len();
    let page = html::Page {
        info: &info,
        confidence,
        sections: &sections,
        skipped: &skipped,
        sensitivities: &sensitivities,
        probabilities: &probabilities,
        worst: &worst,
        worst_notes: &worst_notes,
    };
    let index = at.join("index.html");
    std::fs::write(&index, html::render(&page)).map_err(|source| ReportError::Io {
        path: out.join("index.html"),
        source,
    })?;
    staging.publish()?;
    Ok(ReportSummary {
        out,
        plots,
        replays: worst.len(),
    })
}

/// Rows of a QoI's distribution table.
fn is_distribution_row(statistic: &str) -> bool {
    matches!(statistic, "mean" | "std" | "min" | "max")
        || statistic.starts_with("tolerance_")
        || (statistic.starts_with('p') && statistic[1..].starts_with(|c: char| c.is_ascii_digit()))
}

/// The thresholds `statistics.parquet` evaluated for `q` (MEOP, boil-off budget, zero
/// cavitation margin, every `[[statistics.thresholds]]`), as plot markers with their
/// probability.
fn thresholds(stats: &[StatRow], q: &str) -> Vec<Marker> {
    stats
        .iter()
        .filter(|r| r.quantity == q && r.threshold.is_finite())
        .filter(|r| matches!(r.statistic.as_str(), "prob_exceed" | "prob_below"))
        .enumerate()
        .map(|(i, r)| {
            let side = if r.statistic == "prob_exceed" {
                ">"
            } else {
                "<"
            };
            Marker {
                x: r.threshold,
                label: format!(
                    "P(X {side} {} {}) = {} [{}, {}]",
                    plots::fmt_tick(r.threshold),
                    data::unit_of(q),
                    fmt_p(r.value),
                    fmt_p(r.ci_low),
                    fmt_p(r.ci_high)
                ),
                colour: MARKER_COLOURS[i % MARKER_COLOURS.len()],
            }
        })
        .collect()
}

/// A probability with four decimals (or `–` for none).
pub(crate) fn fmt_p(p: f64) -> String {
    if p.is_finite() {
        format!("{p:.4}")
    } else {
        "–".into()
    }
}
