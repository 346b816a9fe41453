//! Dispersion campaigns: `run` streams instances through an engine into `instances.parquet`,
//! then derives `statistics.parquet` and `run.json`; `merge` joins shard directories into
//! exactly what the unsharded run writes.

pub mod plan;
pub mod screen;
pub mod statistics;
pub mod table;

use crate::campaign::{Campaign, CampaignError};
use crate::engine::Backend;
use crate::output::{atomic::write_atomic, OutputError};
use crate::sampling::Design;
use plan::Plan;
use statistics::{Row, Thresholds};
use std::io::IsTerminal;
use std::ops::Range;
use std::path::{Path, PathBuf};
use table::{InstanceWriter, ReadError};

/// A contiguous slice of the instance range: shard `index` of `count`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Shard {
    pub index: u64,
    pub count: u64,
}

impl Shard {
    /// The whole campaign.
    pub const ALL: Shard = Shard { index: 0, count: 1 };

    /// Parse `I/N` with 0 ≤ I < N.
    pub fn parse(s: &str) -> Option<Shard> {
        let (i, n) = s.split_once('/')?;
        let (index, count) = (i.trim().parse().ok()?, n.trim().parse().ok()?);
        (count > 0 && index < count).then_some(Shard { index, count })
    }

    /// Instances of this shard out of `total`: [I·total/N, (I+1)·total/N).
    pub fn range(self, total: u64) -> Range<u64> {
        let at = |k: u64| ((u128::from(k) * u128::from(total)) / u128::from(self.count)) as u64;
        at(self.index)..at(self.index + 1)
    }
}

impl std::fmt::Display for Shard {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}/{}", self.index, self.count)
    }
}

/// How to run a campaign.
#[derive(Clone, Debug)]
pub struct RunOptions {
    pub out_dir: PathBuf,
    /// Instances in the whole campaign (all shards).
    pub instances: u64,
    pub seed: u64,
    pub shard: Shard,
    /// Instances handed to the engine at a time (bounds memory; results do not depend on it).
    pub chunk_size: u64,
    /// Draw a progress bar on stderr when it is a terminal.
    pub progress: bool,
}

/// What a run did, as written to run.json.
#[derive(Clone, Debug)]
pub struct RunReport {
    pub instances: u64,
    pub diverged: u64,
    pub rejected: u64,
    pub instance_steps: u64,
    pub wall_s: f64,
    pub backend: String,
    pub device: String,
    pub threads: usize,
    pub seed: u64,
    pub shard: String,
    pub design: String,
    /// The integrator and, when adaptive, its tolerances.
    pub integrator: String,
    /// Rejected instances per key path whose rule rejected them, most first.
    pub rejected_by: Vec<(String, u64)>,
    /// Whether the campaign disperses anything (a run of identical instances says so).
    pub dispersed: bool,
    /// The shares above which the run is not trusted (exit code 3).
    pub max_rejected_fraction: f64,
    pub max_diverged_fraction: f64,
    pub statistics: Vec<Row>,
}

impl RunReport {
    /// Why the run's statistics cannot be signed (too many rejected or diverged instances), or
    /// `None`. The outputs are written either way; the command exits with code 3.
    pub fn untrusted(&self) -> Option<String> {
        let n = self.instances.max(1) as f64;
        let mut why = Vec::new();
        let (rej, div) = (self.rejected as f64 / n, self.diverged as f64 / n);
        if rej > self.max_rejected_fraction {
            why.push(format!(
                "{} of {} instances rejected ({:.2} % > statistics.max_rejected_fraction {} %)",
                self.rejected,
                self.instances,
                100.0 * rej,
                100.0 * self.max_rejected_fraction
            ));
        }
        if div > self.max_diverged_fraction {
            why.push(format!(
                "{} of {} instances diverged ({:.2} % > statistics.max_diverged_fraction {} %)",
                self.diverged,
                self.instances,
                100.0 * div,
                100.0 * self.max_diverged_fraction
            ));
        }
        (!why.is_empty()).then(|| why.join("; "))
    }
}

/// Count rejections per key path, most first (ties by name).
fn tally(counts: std::collections::BTreeMap<String, u64>) -> Vec<(String, u64)> {
    let mut v: Vec<(String, u64)> = counts.into_iter().collect();
    v.sort_by(|a, b| b.1.cmp(&a.1).then_with(|| a.0.cmp(&b.0)));
    v
}

/// The integrator as `run.json` and the Parquet metadata record it: `rk4`, or `dopri5` with
/// its tolerances.
pub fn integrator_text(c: &Campaign) -> String {
    let st = &c.stepping;
    match st.integrator {
        crate::campaign::Integrator::Rk4 => "rk4".into(),
        crate::campaign::Integrator::Dopri5 => {
            format!("dopri5 (rtol {:e}, atol {:e})", st.rtol, st.atol)
        }
    }
}

/// Why a run or merge failed.
#[derive(Debug, thiserror::Error)]
pub enum RunError {
    #[error(transparent)]
    Campaign(#[from] CampaignError),
    #[error(transparent)]
    Output(#[from] OutputError),
    #[error(transparent)]
    Read(#[from] ReadError),
    #[error("{0}")]
    Input(String),
    #[error("backend failed: {0}")]
    Engine(String),
}

/// Check run options against the campaign before anything is written.
pub fn check_options(c: &Campaign, o: &RunOptions) -> Result<(), RunError> {
    if o.instances == 0 {
        return Err(RunError::Input("--instances must be at least 1".into()));
    }
    if o.chunk_size == 0 {
        return Err(RunError::Input("--chunk-size must be at least 1".into()));
    }
    let k = c.dispersions.inputs.len() as u64;
    if c.dispersions.design == Design::Saltelli && !o.instances.is_multiple_of(k + 2) {
        return Err(RunError::Input(format!(
            "{}: the saltelli design with {k} inputs needs instances in multiples of k + 2 = {} (got {})",
            c.path.display(),
            k + 2,
            o.instances
        )));
    }
    if matches!(c.dispersions.design, Design::Sobol | Design::Saltelli)
        && o.instances > u64::from(u32::MAX)
    {
        return Err(RunError::Input(format!(
            "Sobol designs support at most {} instances",
            u32::MAX
        )));
    }
    Ok(())
}

/// File-level metadata of both Parquet files of a run.
fn metadata(
    c: &Campaign,
    backend: &str,
    o_seed: u64,
    instances: u64,
    shard: Shard,
) -> Vec<(String, String)> {
    let mut m = crate::history::provenance(c, backend, &shard.to_string());
    set_meta(&mut m, "cryoslosh.seed", o_seed.to_string());
    m.push(("cryoslosh.instances".into(), instances.to_string()));
    m.push((
        "cryoslosh.design".into(),
        c.dispersions.design.name().into(),
    ));
    let inputs: Vec<String> = c
        .dispersions
        .inputs
        .iter()
        .map(|i| format!("{}={}", i.column, i.key))
        .collect();
    m.push(("cryoslosh.inputs".into(), inputs.join(",")));
    m
}

/// Replace the value of `key` in key-value metadata.
fn set_meta(meta: &mut [(String, String)], key: &str, value: String) {
    if let Some((_, v)) = meta.iter_mut().find(|(k, _)| k == key) {
        *v = value;
    }
}

fn thresholds(c: &Campaign) -> Thresholds {
    Thresholds {
        meop_pa: c.params.meop_pa,
        boiloff_budget_kg: c.dispersions.boiloff_budget_kg,
    }
}

/// Run shard `o.shard` of the campaign on `backend`, writing DIR/instances.parquet,
/// DIR/statistics.parquet and DIR/run.json.
pub fn run(c: &Campaign, backend: &Backend, o: &RunOptions) -> Result<RunReport, RunError> {
    check_options(c, o)?;
    let engine = backend.engine();
    std::fs::create_dir_all(&o.out_dir).map_err(|source| OutputError::Io {
        path: o.out_dir.clone(),
        source,
    })?;
    let plan = Plan {
        campaign: c,
        seed: o.seed,
        total: o.instances,
    };
    let range = o.shard.range(o.instances);
    let meta = metadata(c, engine.name(), o.seed, o.instances, o.shard);
    let inst_path = o.out_dir.join("instances.parquet");
    let writer = InstanceWriter::create(&inst_path, &c.dispersions, meta.clone())?;

    let bar = progress_bar(o.progress, range.end - range.start);
    let start = std::time::Instant::now();
    let (mut steps, mut diverged, mut rejected) = (0u64, 0u64, 0u64);
    let mut rejected_by = std::collections::BTreeMap::<String, u64>::new();
    // Double buffering: a writer thread encodes chunk k to Parquet while the engine integrates
    // chunk k + 1 (one chunk in flight bounds memory at two chunks).
    // `None` marks the end: only then is the file renamed into place.
    let (tx, rx) = std::sync::mpsc::sync_channel::<Option<Vec<plan::InstanceRecord>>>(1);
    let outcome = std::thread::scope(|scope| -> Result<(), RunError> {
        let mut writer = writer;
        let writing = scope.spawn(move || -> Result<(), RunError> {
            for block in rx {
                let Some(block) = block else {
                    writer.finish()?;
                    return Ok(());
                };
                for r in &block {
                    writer.push(r)?;
                }
            }
            Ok(()) // abandoned: the integration failed
        });
        let mut at = range.start;
        let mut integrated = Ok(());
        while at < range.end {
            let end = (at + o.chunk_size).min(range.end);
            let block = match engine.run_block(&plan, at..end) {
                Ok(b) => b,
                Err(e) => {
                    integrated = Err(RunError::Engine(e));
                    break;
                }
            };
            for r in &block {
                steps += r.summary.steps;
                diverged += u64::from(r.summary.diverged);
                rejected += u64::from(r.rejected);
                if let Some(key) = &r.rejected_by {
                    *rejected_by.entry(key.clone()).or_default() += 1;
                }
            }
            if tx.send(Some(block)).is_err() {
                break; // the writer failed; its error is reported below
            }
            bar.inc(end - at);
            at = end;
        }
        if integrated.is_ok() {
            let _ = tx.send(None);
        }
        drop(tx);
        let written = writing
            .join()
            .expect("the Parquet writer thread does not panic");
        integrated.and(written)
    });
    if outcome.is_err() {
        if let Ok(tmp) = crate::output::atomic::temp_path(&inst_path) {
            let _ = std::fs::remove_file(tmp);
        }
    }
    outcome?;
    bar.finish_and_clear();
    let wall_s = start.elapsed().as_secs_f64();

    let full = o.shard.count == 1;
    let rows = finish_statistics(c, &o.out_dir, o.instances, full, meta)?;
    let report = RunReport {
        instances: range.end - range.start,
        diverged,
        rejected,
        instance_steps: steps,
        wall_s,
        backend: engine.name().into(),
        device: engine.device(),
        threads: match backend {
            Backend::Cpu(e) => e.threads(),
            Backend::Gpu(_) => rayon::current_num_threads(),
        },
        seed: o.seed,
        shard: o.shard.to_string(),
        design: c.dispersions.design.name().into(),
        integrator: integrator_text(c),
        rejected_by: tally(rejected_by),
        dispersed: !c.dispersions.inputs.is_empty(),
        max_rejected_fraction: c.statistics.max_rejected_fraction,
        max_diverged_fraction: c.statistics.max_diverged_fraction,
        statistics: rows,
    };
    write_run_json(&o.out_dir, &report, o.instances)?;
    Ok(report)
}

/// Statistics of DIR/instances.parquet → DIR/statistics.parquet. Sobol indices need every row
/// of a Saltelli design, so shards report them only once merged.
fn finish_statistics(
    c: &Campaign,
    dir: &Path,
    total: u64,
    full: bool,
    meta: Vec<(String, String)>,
) -> Result<Vec<Row>, RunError> {
    let mut d = c.dispersions.clone();
    if !full && d.design == Design::Saltelli {
        d.design = Design::Sobol;
    }
    let rows = statistics::compute(&dir.join("instances.parquet"), &d, thresholds(c), total)?;
    statistics::write(&dir.join("statistics.parquet"), &rows, meta)?;
    Ok(rows)
}

fn progress_bar(enabled: bool, len: u64) -> indicatif::ProgressBar {
    if !enabled || !std::io::stderr().is_terminal() {
        return indicatif::ProgressBar::hidden();
    }
    let bar = indicatif::ProgressBar::new(len);
    if let Ok(style) = indicatif::ProgressStyle::with_template(
        "{bar:40} {pos}/{len} instances  {per_sec}  ETA {eta}",
    ) {
        bar.set_style(style);
    }
    bar
}

fn write_run_json(dir: &Path, r: &RunReport, total: u64) -> Result<(), RunError> {
    let json = serde_json::json!({
        "instances": r.instances,
        "campaign_instances": total,
        "diverged": r.diverged,
        "rejected": r.rejected,
        "instance_steps": r.instance_steps,
        "wall_s": r.wall_s,
        "instance_steps_per_s": r.instance_steps as f64 / r.wall_s.max(1e-9),
        "backend": r.backend,
        "device": r.device,
        "threads": r.threads,
        "seed": r.seed,
        "shard": r.shard,
        "design": r.design,
        "integrator": r.integrator,
        "rejected_by": r.rejected_by.iter().map(|(k, n)| (k.clone(), serde_json::json!(n))).collect::<serde_json::Map<_, _>>(),
        "untrusted": r.untrusted(),
        "version": crate::VERSION,
    });
    let text = serde_json::to_string_pretty(&json).map_err(|e| RunError::Input(e.to_string()))?;
    write_atomic(&dir.join("run.json"), text.as_bytes())?;
    Ok(())
}

/// One shard directory as read back for a merge.
struct ShardDir {
    dir: PathBuf,
    shard: Shard,
    meta: Vec<(String, String)>,
    run: serde_json::Value,
}

fn meta_value<'a>(meta: &'a [(String, String)], key: &str) -> Option<&'a str> {
    meta.iter().find(|(k, _)| k == key).map(|(_, v)| v.as_str())
}

fn read_shard(dir: &Path) -> Result<ShardDir, RunError> {
    let bad = |why: String| RunError::Input(format!("{}: {why}", dir.display()));
    let meta = table::read_metadata(&dir.join("instances.parquet"))?;
    let shard = meta_value(&meta, "cryoslosh.shard")
        .and_then(Shard::parse)
        .ok_or_else(|| bad("instances.parquet has no valid cryoslosh.shard metadata".into()))?;
    let text = std::fs::read_to_string(dir.join("run.json"))
        .map_err(|e| bad(format!("cannot read run.json: {e}")))?;
    let run = serde_json::from_str(&text).map_err(|e| bad(format!("run.json: {e}")))?;
    Ok(ShardDir {
        dir: dir.to_path_buf(),
        shard,
        meta,
        run,
    })
}

/// Join shard directories (any order) into `out`: rows in instance order, statistics recomputed,
/// metadata as the unsharded run writes it. Checks that the shards are of one campaign and
/// cover it exactly once.
pub fn merge(dirs: &[PathBuf], out: &Path) -> Result<RunReport, RunError> {
    let mut shards: Vec<ShardDir> = dirs
        .iter()
        .map(|d| read_shard(d))
        .collect::<Result<_, _>>()?;
    shards.sort_by_key(|s| s.shard.index);
    let first = shards
        .first()
        .ok_or_else(|| RunError::Input("merge needs at least one directory".into()))?;
    let count = first.shard.count;
    let same = |key: &str| {
        shards
            .iter()
            .all(|s| meta_value(&s.meta, key) == meta_value(&first.meta, key))
    };
    for key in [
        "cryoslosh.campaign",
        "cryoslosh.seed",
        "cryoslosh.instances",
        "cryoslosh.backend",
        "cryoslosh.version",
    ] {
        if !same(key) {
            return Err(RunError::Input(format!(
                "the shards differ in {key}: they are not one campaign"
            )));
        }
    }
    let indices: Vec<u64> = shards.iter().map(|s| s.shard.index).collect();
    if shards.iter().any(|s| s.shard.count != count) || indices != (0..count).collect::<Vec<_>>() {
        return Err(RunError::Input(format!(
            "shards {:?} do not cover 0..{count} exactly once",
            shards
                .iter()
                .map(|s| s.shard.to_string())
                .collect::<Vec<_>>()
        )));
    }
    let path = meta_value(&first.meta, "cryoslosh.campaign_path").unwrap_or("campaign.toml");
    let text = meta_value(&first.meta, "cryoslosh.campaign").unwrap_or_default();
    let c = Campaign::from_text(Path::new(path), text, &[])?;
    let total: u64 = meta_value(&first.meta, "cryoslosh.instances")
        .and_then(|v| v.parse().ok())
        .unwrap_or(0);

    std::fs::create_dir_all(out).map_err(|source| OutputError::Io {
        path: out.to_path_buf(),
        source,
    })?;
    let mut meta = first.meta.clone();
    set_meta(&mut meta, "cryoslosh.shard", Shard::ALL.to_string());
    let mut writer =
        InstanceWriter::create(&out.join("instances.parquet"), &c.dispersions, meta.clone())?;
    let mut rows = 0;
    for s in &shards {
        rows += table::copy_rows(&mut writer, &s.dir.join("instances.parquet"))?;
    }
    writer.finish()?;
    if rows != total {
        return Err(RunError::Input(format!(
            "the shards hold {rows} instances, the campaign {total}"
        )));
    }
    let stats = finish_statistics(&c, out, total, true, meta)?;
    let sum = |key: &str| {
        shards
            .iter()
            .map(|s| s.run[key].as_u64().unwrap_or(0))
            .sum::<u64>()
    };
    let report = RunReport {
        instances: rows,
        diverged: sum("diverged"),
        rejected: sum("rejected"),
        instance_steps: sum("instance_steps"),
        wall_s: shards
            .iter()
            .map(|s| s.run["wall_s"].as_f64().unwrap_or(0.0))
            .sum(),
        backend: first.run["backend"].as_str().unwrap_or("cpu").into(),
        device: format!("merged from {count} shards"),
        threads: shards
            .iter()
            .map(|s| s.run["threads"].as_u64().unwrap_or(0) as usize)
            .sum(),
        seed: first.run["seed"].as_u64().unwrap_or(0),
        shard: Shard::ALL.to_string(),
        design: c.dispersions.design.name().into(),
        integrator: integrator_text(&c),
        rejected_by: tally(
            shards
                .iter()
                .filter_map(|s| s.run["rejected_by"].as_object())
                .flat_map(|m| m.iter())
                .fold(std::collections::BTreeMap::new(), |mut acc, (k, v)| {
                    *acc.entry(k.clone()).or_default() += v.as_u64().unwrap_or(0);
                    acc
                }),
        ),
        dispersed: !c.dispersions.inputs.is_empty(),
        max_rejected_fraction: c.statistics.max_rejected_fraction,
        max_diverged_fraction: c.statistics.max_diverged_fraction,
        statistics: stats,
    };
    write_run_json(out, &report, total)?;
    Ok(report)
}

/// The terminal summary: margins, tail probabilities, top drivers.
pub fn summary_text(r: &RunReport) -> String {
    use statistics::find;
    let s = &r.statistics;
    let mut out = format!(
        "{} instances ({} diverged, {} rejected), {} instance-steps in {:.2} s = {:.3e} instance-steps/s on {}\n",
        r.instances,
        r.diverged,
        r.rejected,
        r.instance_steps,
        r.wall_s,
        r.instance_steps as f64 / r.wall_s.max(1e-9),
        r.device
    );
    if !r.dispersed {
        out += "note: the campaign has no [dispersions]: every instance is the nominal\n";
    }
    if !r.rejected_by.is_empty() {
        let list: Vec<String> = r
            .rejected_by
            .iter()
            .map(|(k, n)| format!("{k} {n}"))
            .collect();
        out += &format!("rejected by        {}\n", list.join(", "));
    }
    let stat = |q: &str, st: &str| find(s, q, st).map(|x| x.value).unwrap_or(f64::NAN);
    let prob = |q: &str, st: &str| {
        find(s, q, st).map_or_else(String::new, |x| {
            format!(
                "P = {:.4} [{:.4}, {:.4}] at {}",
                x.value, x.ci_low, x.ci_high, x.threshold
            )
        })
    };
    out += &format!(
        "peak pressure      p50 {:.0} Pa  p99 {:.0} Pa  max {:.0} Pa; above MEOP: {}\n",
        stat("peak_pressure_pa", "p50"),
        stat("peak_pressure_pa", "p99"),
        stat("peak_pressure_pa", "max"),
        prob("peak_pressure_pa", "prob_exceed")
    );
    if find(s, "min_cavitation_margin_m", "p01").is_some_and(|x| x.n > 0) {
        out += &format!(
            "cavitation margin  p01 {:.3} m  p50 {:.3} m  min {:.3} m; below 0: {}\n",
            stat("min_cavitation_margin_m", "p01"),
            stat("min_cavitation_margin_m", "p50"),
            stat("min_cavitation_margin_m", "min"),
            prob("min_cavitation_margin_m", "prob_below")
        );
    }
    out += &format!(
        "boil-off           p50 {:.4} kg  p99 {:.4} kg{}\n",
        stat("boiloff_kg", "p50"),
        stat("boiloff_kg", "p99"),
        find(s, "boiloff_kg", "prob_exceed").map_or_else(String::new, |_| format!(
            "; over budget: {}",
            prob("boiloff_kg", "prob_exceed")
        ))
    );
    out += &format!(
        "vented             p50 {:.4} kg  p99 {:.4} kg;  max slosh angle p99 {:.4} rad\n",
        stat("vented_kg", "p50"),
        stat("vented_kg", "p99"),
        stat("max_slosh_angle_rad", "p99")
    );
    for (name, what) in [
        ("depleted", "ran dry (depleted)"),
        ("pressurant_exhausted", "pressurant exhausted"),
    ] {
        if let Some(x) = find(s, name, "fraction").filter(|x| x.value > 0.0) {
            out += &format!(
                "{what:18} P = {:.4} [{:.4}, {:.4}] of {} valid instances\n",
                x.value, x.ci_low, x.ci_high, x.n
            );
        }
    }
    for q in statistics::SENSITIVITY_QOIS {
        let mut drivers: Vec<&Row> = s
            .iter()
            .filter(|x| {
                x.stat.quantity == q && x.stat.statistic == "spearman" && x.stat.value.is_finite()
            })
            .collect();
        drivers.sort_by(|a, b| b.stat.value.abs().total_cmp(&a.stat.value.abs()));
        if !drivers.is_empty() {
            let top: Vec<String> = drivers
                .iter()
                .take(3)
                .map(|d| format!("{} {:+.2}", d.input, d.stat.value))
                .collect();
            out += &format!("drivers of {q:24} (Spearman) {}\n", top.join(", "));
        }
    }
    out
}
