//! What a report reads from a results directory: the run's header (`run.json` and the Parquet
//! file metadata), the rows of `statistics.parquet`, and instance columns one at a time, so that
//! memory stays bounded by one column (and its sorted copy) even for ten million instances.

use super::ReportError;
use crate::montecarlo::replay::{self, RunCampaign};
use crate::montecarlo::table;
use arrow_array::{Array, Float64Array, StringArray, UInt64Array};
use parquet::arrow::arrow_reader::ParquetRecordBatchReaderBuilder;
use std::path::{Path, PathBuf};

/// The header of a run or merge: who made it, with what, and what came out.
#[derive(Debug)]
pub struct RunInfo {
    /// The results directory.
    pub dir: PathBuf,
    /// The run's campaign as its metadata recorded it (text with overrides, seed, count).
    pub run: RunCampaign,
    /// Sampling design (`monte_carlo`, `latin_hypercube`, `sobol`, `saltelli`).
    pub design: String,
    /// Instances in the file (a shard's slice, or the whole campaign).
    pub instances: u64,
    pub diverged: Option<u64>,
    pub rejected: Option<u64>,
    /// Valid instances whose tank ran dry (from the `depleted` column).
    pub depleted: Option<u64>,
    pub version: String,
    /// Where the run integrated (`cpu: 2 threads`, a GPU's name).
    pub device: String,
    pub integrator: String,
    pub fidelity: String,
    pub shard: String,
    /// Wall time of the run, s (`run.json`; absent for a directory without it; a merge: the
    /// shards' summed).
    pub wall_s: Option<f64>,
    /// Shards a merge joined (0 for a run).
    pub merged_shards: usize,
    /// Dispersed-input columns of `instances.parquet`, with their campaign key paths.
    pub inputs: Vec<(String, String)>,
    /// Every column of `instances.parquet` with its kind (`f64`, `u64`, `bool`).
    pub columns: Vec<(String, String)>,
}

impl RunInfo {
    /// `instances.parquet` of the directory.
    pub fn instances_file(&self) -> PathBuf {
        self.dir.join("instances.parquet")
    }

    /// The quantity-of-interest columns, in file order: every f64 column that is not a
    /// dispersed input. Per-phase columns (`peak_pressure_pa.burn`) come along by themselves.
    pub fn qoi_columns(&self) -> Vec<String> {
        self.columns
            .iter()
            .filter(|(name, kind)| {
                kind == "f64" && name != "instance" && !self.inputs.iter().any(|(c, _)| c == name)
            })
            .map(|(name, _)| name.clone())
            .collect()
    }
}

/// Read the header of the results directory `dir`; a directory that is not one is bad input.
pub fn run_info(dir: &Path) -> Result<RunInfo, ReportError> {
    if !dir.is_dir() {
        return Err(ReportError::Input(format!(
            "{}: not a directory (give a results directory written by `cryoslosh run` or `merge`)",
            dir.display()
        )));
    }
    for f in ["instances.parquet", "statistics.parquet"] {
        if !dir.join(f).is_file() {
            return Err(ReportError::Input(format!(
                "{}: not a results directory (no {f})",
                dir.display()
            )));
        }
    }
    let run = replay::run_campaign(dir).map_err(|e| ReportError::Input(e.to_string()))?;
    let path = dir.join("instances.parquet");
    let meta = table::read_metadata(&path).map_err(|e| ReportError::Input(e.to_string()))?;
    let get = |key: &str| {
        meta.iter()
            .find(|(k, _)| k == key)
            .map(|(_, v)| v.clone())
            .unwrap_or_default()
    };
    let inputs = get("cryoslosh.inputs")
        .split(',')
        .filter_map(|pair| pair.split_once('='))
        .map(|(c, k)| (c.to_string(), k.to_string()))
        .collect();
    let columns = table::read_schema(&path).map_err(|e| ReportError::Input(e.to_string()))?;
    // run.json is optional: its absence (a hand-copied directory) only blanks header fields;
    // one that is there but not JSON is bad input (the header would silently go blank).
    let run_json = dir.join("run.json");
    let json: serde_json::Value = match std::fs::read_to_string(&run_json) {
        Err(_) => serde_json::Value::Null,
        Ok(t) => serde_json::from_str(&t).map_err(|e| {
            ReportError::Input(format!(
                "{}: not a run's JSON record: {e}",
                run_json.display()
            ))
        })?,
    };
    let text =
        |key: &str, fallback: String| json[key].as_str().map(str::to_string).unwrap_or(fallback);
    let rows = parquet_rows(&path)?;
    let depleted = if columns.iter().any(|(c, _)| c == "depleted") {
        Some(count_true(&path, "depleted")?)
    } else {
        None
    };
    Ok(RunInfo {
        dir: dir.to_path_buf(),
        design: text("design", get("cryoslosh.design")),
        instances: json["instances"].as_u64().unwrap_or(rows),
        diverged: json["diverged"].as_u64(),
        rejected: json["rejected"].as_u64(),
        depleted,
        version: text("version", get("cryoslosh.version")),
        device: text("device", run.backend.clone()),
        integrator: text("integrator", get("cryoslosh.integrator")),
        fidelity: get("cryoslosh.fidelity"),
        shard: text("shard", get("cryoslosh.shard")),
        wall_s: json["wall_s"].as_f64(),
        merged_shards: json["shards"].as_array().map_or(0, Vec::len),
        inputs,
        columns,
        run,
    })
}

/// Rows of a Parquet file, from its footer.
fn parquet_rows(path: &Path) -> Result<u64, ReportError> {
    let file = std::fs::File::open(path).map_err(|e| ReportError::read(path, e))?;
    let b =
        ParquetRecordBatchReaderBuilder::try_new(file).map_err(|e| ReportError::read(path, e))?;
    Ok(b.metadata().file_metadata().num_rows().max(0) as u64)
}

/// How many values of a bool column are true (nulls are not).
fn count_true(path: &Path, column: &str) -> Result<u64, ReportError> {
    let v = table::read_bool(path, column).map_err(|e| ReportError::read(path, e))?;
    Ok(v.iter().filter(|&&b| b).count() as u64)
}

/// One row of `statistics.parquet` (nulls as NaN / `None`).
#[derive(Clone, Debug)]
pub struct StatRow {
    pub quantity: String,
    pub statistic: String,
    pub input: Option<String>,
    pub threshold: f64,
    pub probability: f64,
    pub confidence: f64,
    pub value: f64,
    pub ci_low: f64,
    pub ci_high: f64,
    pub n: u64,
}

/// Every row of `statistics.parquet` (a few per QoI and input: small even for a large run).
pub fn statistics(dir: &Path) -> Result<Vec<StatRow>, ReportError> {
    let path = dir.join("statistics.parquet");
    let file = std::fs::File::open(&path).map_err(|e| ReportError::read(&path, e))?;
    let reader = ParquetRecordBatchReaderBuilder::try_new(file)
        .and_then(|b| b.build())
        .map_err(|e| ReportError::read(&path, e))?;
    let mut rows = Vec::new();
    for batch in reader {
        let batch = batch.map_err(|e| ReportError::read(&path, e))?;
        let col = |name: &str| {
            batch.column_by_name(name).ok_or_else(|| {
                ReportError::Input(format!(
                    "{}: no column {name}: not a cryoslosh statistics file",
                    path.display()
                ))
            })
        };
        let strings = |name: &str| -> Result<StringArray, ReportError> {
            col(name)?
                .as_any()
                .downcast_ref::<StringArray>()
                .cloned()
                .ok_or_else(|| {
                    ReportError::Input(format!("{}: {name} is not text", path.display()))
                })
        };
        let floats = |name: &str| -> Result<Vec<f64>, ReportError> {
            let a = col(name)?;
            let a = a.as_any().downcast_ref::<Float64Array>().ok_or_else(|| {
                ReportError::Input(format!("{}: {name} is not f64", path.display()))
            })?;
            Ok(a.iter().map(|v| v.unwrap_or(f64::NAN)).collect())
        };
        let (quantity, statistic, input) = (
            strings("quantity")?,
            strings("statistic")?,
            strings("input")?,
        );
        let [threshold, probability, confidence, value, lo, hi] = [
            "threshold",
            "probability",
            "confidence",
            "value",
            "ci_low",
            "ci_high",
        ]
        .map(floats);
        let (threshold, probability, confidence, value, lo, hi) =
            (threshold?, probability?, confidence?, value?, lo?, hi?);
        let n = col("n")?;
        let n = n.as_any().downcast_ref::<UInt64Array>();
        for r in 0..batch.num_rows() {
            rows.push(StatRow {
                quantity: quantity.value(r).to_string(),
                statistic: statistic.value(r).to_string(),
                input: (!input.is_null(r)).then(|| input.value(r).to_string()),
                threshold: threshold[r],
                probability: probability[r],
                confidence: confidence[r],
                value: value[r],
                ci_low: lo[r],
                ci_high: hi[r],
                n: n.map_or(0, |a| a.value(r)),
            });
        }
    }
    Ok(rows)
}

/// The finite values of one instances column, sorted ascending (nulls, i.e. diverged or
/// rejected instances and QoIs that did not occur, are left out). The only full-length buffer a
/// report holds at a time.
pub fn sorted_column(info: &RunInfo, column: &str) -> Result<Vec<f64>, ReportError> {
    let path = info.instances_file();
    let mut v = table::read_f64(&path, column).map_err(|e| ReportError::read(&path, e))?;
    v.retain(|x| x.is_finite());
    v.sort_unstable_by(f64::total_cmp);
    Ok(v)
}

/// At most `max` rows of one column, taken at an even stride in instance order (rows with a
/// null included, as NaN), so two columns subsampled alike stay paired.
pub fn strided_column(info: &RunInfo, column: &str, max: usize) -> Result<Vec<f64>, ReportError> {
    let path = info.instances_file();
    let v = table::read_f64(&path, column).map_err(|e| ReportError::read(&path, e))?;
    let stride = v.len().div_ceil(max.max(1)).max(1);
    Ok(v.into_iter().step_by(stride).collect())
}

/// Equal-width histogram of sorted values: bin edges and counts.
#[derive(Clone, Debug)]
pub struct Histogram {
    pub lo: f64,
    pub width: f64,
    pub counts: Vec<u64>,
}

/// Bins by the Freedman–Diaconis rule (2 IQR n^(−1/3)), clamped to 10…60 so the bars stay
/// readable at 100 % zoom; `sorted` must be ascending, finite and not constant.
pub fn histogram(sorted: &[f64]) -> Histogram {
    let n = sorted.len();
    let (lo, hi) = (sorted[0], sorted[n - 1]);
    let q = |p: f64| crate::stats::percentile(sorted, p);
    let iqr = q(0.75) - q(0.25);
    let fd = if iqr > 0.0 {
        ((hi - lo) / (2.0 * iqr * (n as f64).powf(-1.0 / 3.0))).ceil()
    } else {
        (n as f64).sqrt().ceil()
    };
    let bins = (fd as usize).clamp(10, 60);
    let width = (hi - lo) / bins as f64;
    let mut counts = vec![0u64; bins];
    for &x in sorted {
        let b = (((x - lo) / width) as usize).min(bins - 1);
        counts[b] += 1;
    }
    Histogram { lo, width, counts }
}

/// One point of the empirical exceedance curve: the fraction of values at or above `x`, with
/// its pointwise Clopper–Pearson interval.
#[derive(Clone, Copy, Debug)]
pub struct ExceedancePoint {
    pub x: f64,
    pub p: f64,
    pub lo: f64,
    pub hi: f64,
}

/// The exceedance curve P(X ≥ x) at the order statistics — or, for a margin (`lower`), the
/// non-exceedance P(X ≤ x), whose low tail is the one that matters — at every one of the 200
/// most extreme values and a geometric selection of the rest (about 600 points whatever n),
/// each with the pointwise Clopper–Pearson interval at `level` (exact for k of n values at or
/// beyond x). Points ascend in x.
pub fn exceedance(sorted: &[f64], level: f64, lower: bool) -> Vec<ExceedancePoint> {
    let n = sorted.len();
    let mut ks: Vec<usize> = (1..=n.min(200)).collect();
    if n > 200 {
        let steps = 400;
        let ratio = (n as f64 / 200.0).powf(1.0 / steps as f64);
        let mut k = 200.0;
        for _ in 0..steps {
            k *= ratio;
            ks.push((k.round() as usize).min(n));
        }
        ks.push(n);
        ks.dedup();
    }
    let point = |k: usize| {
        let (lo, hi) = crate::stats::clopper_pearson(k as u64, n as u64, level);
        ExceedancePoint {
            x: if lower { sorted[k - 1] } else { sorted[n - k] },
            p: k as f64 / n as f64,
            lo,
            hi,
        }
    };
    if lower {
        ks.iter().map(|&k| point(k)).collect()
    } else {
        ks.iter().rev().map(|&k| point(k)).collect()
    }
}

/// The SI unit of a column, from the suffix of its name (`peak_pressure_pa` → Pa; a per-phase
/// column `boiloff_kg.burn` by its part before the dot); "1" for a dimensionless one.
pub fn unit_of(column: &str) -> &'static str {
    let base = column.split('.').next().unwrap_or(column);
    const SUFFIXES: [(&str, &str); 16] = [
        ("_kg_per_m2", "kg/m²"),
        ("_w_per_m2_k", "W/(m²·K)"),
        ("_j_per_kg_k", "J/(kg·K)"),
        ("_m_s2", "m/s²"),
        ("_rad_s", "rad/s"),
        ("_kg_s", "kg/s"),
        ("_m_s", "m/s"),
        ("_n_m", "N·m"),
        ("_pa", "Pa"),
        ("_kg", "kg"),
        ("_rad", "rad"),
        ("_hz", "Hz"),
        ("_w", "W"),
        ("_k", "K"),
        ("_s", "s"),
        ("_n", "N"),
    ];
    if let Some((_, u)) = SUFFIXES.iter().find(|(s, _)| base.ends_with(s)) {
        return u;
    }
    if base.ends_with("_m") {
        "m"
    } else {
        "1"
    }
}

/// Axis label of a column: its name and unit, e.g. `peak_pressure_pa (Pa)`.
pub fn label(column: &str) -> String {
    format!("{column} ({})", unit_of(column))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn exceedance_points_count_values_at_or_beyond_x() {
        let sorted = [1.0, 2.0, 3.0, 4.0];
        let up = exceedance(&sorted, 0.95, false);
        let xs: Vec<(f64, f64)> = up.iter().map(|p| (p.x, p.p)).collect();
        assert_eq!(xs, vec![(1.0, 1.0), (2.0, 0.75), (3.0, 0.5), (4.0, 0.25)]);
        let down = exceedance(&sorted, 0.95, true);
        let xs: Vec<(f64, f64)> = down.iter().map(|p| (p.x, p.p)).collect();
        assert_eq!(xs, vec![(1.0, 0.25), (2.0, 0.5), (3.0, 0.75), (4.0, 1.0)]);
        // k = n: the interval reaches 1; every point's interval holds its estimate.
        assert_eq!(up[0].hi, 1.0);
        assert!(up.iter().all(|p| p.lo <= p.p && p.p <= p.hi));
        // A large sample keeps about 600 points, the extreme one included.
        let big: Vec<f64> = (0..1_000_000).map(f64::from).collect();
        let pts = exceedance(&big, 0.95, false);
        assert!(pts.len() < 700, "{}", pts.len());
        assert_eq!(pts.last().map(|p| p.x), Some(999_999.0));
    }

    #[test]
    fn units_come_from_the_column_suffix() {
        assert_eq!(unit_of("peak_pressure_pa"), "Pa");
        assert_eq!(unit_of("peak_pressure_pa.burn"), "Pa");
        assert_eq!(unit_of("peak_slosh_moment_n_m"), "N·m");
        assert_eq!(unit_of("min_cavitation_margin_m"), "m");
        assert_eq!(unit_of("tank_wall_areal_mass_kg_per_m2"), "kg/m²");
        assert_eq!(unit_of("slosh_out_of_range_fraction"), "1");
        assert_eq!(label("boiloff_kg"), "boiloff_kg (kg)");
    }
}
