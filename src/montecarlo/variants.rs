//! `run` and `merge` of a campaign with `[[variants]]`: every variant integrates the same
//! instances (the same dispersed inputs, common random numbers) into a complete results
//! directory of its own, `DIR/variants/<name>/` (instances, statistics, run.json, manifest: what
//! `report`, `simulate --run` and `merge` read), and `DIR/differences.parquet` holds the paired
//! differences against the baseline. `DIR` is staged and published whole, like any run.

use super::differences::{self, DiffRow};
use super::statistics::Spec;
use super::{merge, run, table, RunError, RunOptions, RunReport};
use crate::campaign::Campaign;
use crate::engine::Backend;
use crate::output::atomic::write_atomic;
use crate::output::results_dir::Staging;
use crate::output::OutputError;
use std::path::{Path, PathBuf};

/// What a run or merge of variants did.
#[derive(Clone, Debug)]
pub struct VariantsReport {
    pub names: Vec<String>,
    /// Each variant's run, in order (the first is the baseline).
    pub reports: Vec<RunReport>,
    pub differences: Vec<DiffRow>,
}

impl VariantsReport {
    /// Why some variant's statistics cannot be signed (exit code 3), or `None`.
    pub fn untrusted(&self) -> Option<String> {
        let why: Vec<String> = self
            .names
            .iter()
            .zip(&self.reports)
            .filter_map(|(n, r)| r.untrusted().map(|u| format!("variant {n}: {u}")))
            .collect();
        (!why.is_empty()).then(|| why.join("; "))
    }
}

/// Where variant `name` of the results directory `dir` lives.
pub fn variant_dir(dir: &Path, name: &str) -> PathBuf {
    dir.join("variants").join(name)
}

/// Whether `dir` is the result of a run with variants.
pub fn is_variants_dir(dir: &Path) -> bool {
    dir.join("differences.parquet").is_file() && dir.join("variants").is_dir()
}

/// Remove the lock files the variants' own staging left in `DIR/variants/` (not results; a
/// run's and a report's alike).
pub fn drop_locks(dir: &Path) {
    if let Ok(entries) = std::fs::read_dir(dir.join("variants")) {
        for e in entries.filter_map(Result::ok) {
            let name = e.file_name().to_string_lossy().into_owned();
            if name.starts_with('.') && name.ends_with(".lock") {
                let _ = std::fs::remove_file(e.path());
            }
        }
    }
}

/// The differences of the variants in `dir` → `dir/differences.parquet`, with the baseline
/// campaign's thresholds and statistics plan, and `meta` (the provenance of the campaign with
/// its variants).
fn finish(
    base: &Campaign,
    dir: &Path,
    names: &[String],
    seed: u64,
    total: u64,
    mut meta: Vec<(String, String)>,
) -> Result<Vec<DiffRow>, RunError> {
    let files: Vec<PathBuf> = names
        .iter()
        .map(|n| variant_dir(dir, n).join("instances.parquet"))
        .collect();
    let spec = Spec {
        dispersions: base.dispersions.clone(),
        plan: base.statistics.clone(),
        meop_pa: base.params.meop_pa,
        boiloff_budget_kg: base.dispersions.boiloff_budget_kg,
        total,
        seed,
        phases: table::phase_names(base),
    };
    let rows = differences::compute(names, &files, &spec)?;
    meta.retain(|(k, _)| k != "cryoslosh.variants");
    meta.push(("cryoslosh.variants".into(), names.join(",")));
    differences::write(&dir.join("differences.parquet"), &rows, meta)?;
    Ok(rows)
}

/// `run.json` of the whole directory: the variants, each one's counts, and the run's identity.
fn write_run_json(dir: &Path, r: &VariantsReport, seed: u64, shard: &str) -> Result<(), RunError> {
    let variants: Vec<serde_json::Value> = r
        .names
        .iter()
        .zip(&r.reports)
        .map(|(n, v)| {
            let mut m = serde_json::json!({
                "name": n,
                "dir": format!("variants/{n}"),
                "instances": v.instances,
                "diverged": v.diverged,
                "rejected": v.rejected,
                "untrusted": v.untrusted(),
            });
            if let serde_json::Value::Object(m) = &mut m {
                m.extend(v.cost_json());
            }
            m
        })
        .collect();
    let first = &r.reports[0];
    let json = serde_json::json!({
        "variants": variants,
        "baseline": r.names[0],
        "instances": first.instances,
        "backend": first.backend,
        "device": first.device,
        "threads": first.threads,
        "seed": seed,
        "shard": shard,
        "design": first.design,
        "integrator": first.integrator,
        "untrusted": r.untrusted(),
        "version": crate::VERSION,
        "build": first.build,
    });
    // The whole run's cost: every variant's work over their wall times summed (the variants
    // run one after another).
    let mut all = first.clone();
    let sum = |f: fn(&RunReport) -> u64| r.reports.iter().map(f).sum::<u64>();
    all.instance_steps = sum(|v| v.instance_steps);
    all.resumed_steps = sum(|v| v.resumed_steps);
    all.rhs_evaluations = sum(|v| v.rhs_evaluations);
    all.resumed_rhs_evaluations = sum(|v| v.resumed_rhs_evaluations);
    all.wall_s = r.reports.iter().map(|v| v.wall_s).sum();
    let mut json = json;
    if let serde_json::Value::Object(m) = &mut json {
        m.extend(all.cost_json());
    }
    let text = serde_json::to_string_pretty(&json).map_err(|e| RunError::Input(e.to_string()))?;
    write_atomic(&dir.join("run.json"), text.as_bytes())?;
    Ok(())
}

/// Provenance of `differences.parquet`: the campaign with its variants, seed, shard, backend.
fn metadata(
    c: &Campaign,
    backend: &str,
    seed: u64,
    shard: &str,
    total: u64,
) -> Vec<(String, String)> {
    let mut m = crate::history::provenance(c, backend, shard);
    super::set_meta(&mut m, "cryoslosh.seed", seed.to_string());
    m.push(("cryoslosh.instances".into(), total.to_string()));
    m
}

/// Run every variant of `c` on the same instances into `o.out_dir`. Not with `--resume` nor a
/// precision target (`--until`): each variant is a run of the whole instance range.
pub fn run_variants(
    c: &Campaign,
    backend: &Backend,
    o: &RunOptions,
) -> Result<VariantsReport, RunError> {
    if o.resume {
        return Err(RunError::Input(
            "--resume: a campaign with [[variants]] runs again from the start (no --resume)".into(),
        ));
    }
    if o.target(c).is_some() {
        return Err(RunError::Input(format!(
            "{}: a campaign with [[variants]] runs every variant on the whole instance range: \
             not with --until or [statistics.target]",
            c.path.display()
        )));
    }
    let campaigns = c.variant_campaigns()?;
    for v in &campaigns {
        super::check_options(v, o)?;
    }
    let names: Vec<String> = c.variants.iter().map(|v| v.name.clone()).collect();
    let staging = Staging::begin(&o.out_dir, o.force, false)?;
    let dir = staging.path().to_path_buf();
    std::fs::create_dir_all(dir.join("variants")).map_err(|source| OutputError::Io {
        path: dir.join("variants"),
        source,
    })?;
    let mut reports = Vec::new();
    for (name, v) in names.iter().zip(&campaigns) {
        let sub = RunOptions {
            out_dir: variant_dir(&dir, name),
            force: false,
            resume: false,
            ..o.clone()
        };
        reports.push(run(v, backend, &sub)?);
    }
    drop_locks(&dir);
    let total = o.instances;
    let backend_name = reports[0].backend.clone();
    let shard = o.shard.to_string();
    let meta = metadata(c, &backend_name, o.seed, &shard, total);
    let differences = finish(&campaigns[0], &dir, &names, o.seed, total, meta)?;
    let report = VariantsReport {
        names,
        reports,
        differences,
    };
    write_run_json(&dir, &report, o.seed, &shard)?;
    staging.publish()?;
    Ok(report)
}

/// Merge shard directories of a run with variants: each variant's shards are merged as any
/// run's (byte-identical to the unsharded variant), then the differences recomputed.
pub fn merge_variants(
    dirs: &[PathBuf],
    out: &Path,
    force: bool,
) -> Result<VariantsReport, RunError> {
    let first = dirs
        .first()
        .ok_or_else(|| RunError::Input("merge needs at least one directory".into()))?;
    let meta_of = |d: &Path| table::read_metadata(&d.join("differences.parquet"));
    let meta = meta_of(first)?;
    let value = |m: &[(String, String)], k: &str| {
        m.iter().find(|(key, _)| key == k).map(|(_, v)| v.clone())
    };
    for d in dirs {
        if !is_variants_dir(d) {
            return Err(RunError::Input(format!(
                "{}: not the result of a run with [[variants]] (no differences.parquet), unlike {}",
                d.display(),
                first.display()
            )));
        }
        crate::output::results_dir::verify(d)
            .map_err(|e| RunError::Input(format!("{}: {e}", d.display())))?;
        let m = meta_of(d)?;
        for key in [
            "cryoslosh.campaign",
            "cryoslosh.variants",
            "cryoslosh.seed",
            "cryoslosh.instances",
        ] {
            if value(&m, key) != value(&meta, key) {
                return Err(RunError::Input(format!(
                    "{} and {} differ in {key}: they are not shards of one campaign",
                    d.display(),
                    first.display()
                )));
            }
        }
    }
    let path = value(&meta, "cryoslosh.campaign_path").unwrap_or_else(|| "campaign.toml".into());
    let text = value(&meta, "cryoslosh.campaign").unwrap_or_default();
    let c = Campaign::from_text(Path::new(&path), &text, &[])?;
    let campaigns = c.variant_campaigns()?;
    let names: Vec<String> = c.variants.iter().map(|v| v.name.clone()).collect();
    let seed: u64 = value(&meta, "cryoslosh.seed")
        .and_then(|s| s.parse().ok())
        .unwrap_or(0);
    let total: u64 = value(&meta, "cryoslosh.instances")
        .and_then(|s| s.parse().ok())
        .unwrap_or(0);
    let staging = Staging::begin(out, force, false)?;
    let dir = staging.path().to_path_buf();
    std::fs::create_dir_all(dir.join("variants")).map_err(|source| OutputError::Io {
        path: dir.join("variants"),
        source,
    })?;
    let mut reports = Vec::new();
    for name in &names {
        let shards: Vec<PathBuf> = dirs.iter().map(|d| variant_dir(d, name)).collect();
        reports.push(merge(&shards, &variant_dir(&dir, name), false)?);
    }
    drop_locks(&dir);
    let backend_name = reports[0].backend.clone();
    let shard = super::Shard::ALL.to_string();
    let meta = metadata(&c, &backend_name, seed, &shard, total);
    let differences = finish(&campaigns[0], &dir, &names, seed, total, meta)?;
    let report = VariantsReport {
        names,
        reports,
        differences,
    };
    write_run_json(&dir, &report, seed, &shard)?;
    staging.publish()?;
    Ok(report)
}

/// The run summary of a run with variants: each variant's one-line count, the side-by-side
/// table and the paired differences.
pub fn summary_text(r: &VariantsReport) -> String {
    let mut out = String::new();
    for (n, v) in r.names.iter().zip(&r.reports) {
        out += &format!(
            "variant {n}: {} instances ({} diverged, {} rejected), {} on {}\n",
            v.instances,
            v.diverged,
            v.rejected,
            v.cost_text(),
            v.device
        );
    }
    let stats: Vec<Vec<super::statistics::Row>> =
        r.reports.iter().map(|v| v.statistics.clone()).collect();
    out += &differences::side_by_side(&r.names, &stats, &r.differences);
    out
}
