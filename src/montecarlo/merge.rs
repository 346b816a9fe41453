//! `merge`: shard directories of one campaign → exactly what the unsharded run writes, after
//! checking that the shards are of one campaign, cover it once, and hold what they declare.

use super::table::{self, InstanceWriter};
use super::{
    finish_statistics, integrator_text, set_meta, tally, write_run_json, RunError, RunReport, Shard,
};
use crate::campaign::Campaign;
use crate::output::results_dir::{failpoint, Staging};
use crate::output::OutputError;
use std::path::{Path, PathBuf};

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
    if !dir.join("instances.parquet").is_file() {
        return Err(bad("not a results directory (no instances.parquet)".into()));
    }
    crate::output::results_dir::verify(dir).map_err(bad)?;
    let listed = std::fs::read_to_string(dir.join(crate::output::results_dir::MANIFEST))
        .ok()
        .and_then(|t| serde_json::from_str::<serde_json::Value>(&t).ok())
        .unwrap_or_default();
    for f in ["instances.parquet", "statistics.parquet", "run.json"] {
        if listed["files"].get(f).is_none() {
            return Err(bad(format!("manifest.json does not list {f}")));
        }
    }
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

/// Every shard `0/N … N−1/N` exactly once; otherwise name the directories at fault and the
/// shards missing.
fn check_cover(shards: &[ShardDir], count: u64) -> Result<(), RunError> {
    let mut problems = Vec::new();
    for s in shards.iter().filter(|s| s.shard.count != count) {
        problems.push(format!(
            "{} is shard {} of a {}-way split, the others of a {count}-way one",
            s.dir.display(),
            s.shard,
            s.shard.count
        ));
    }
    for i in 0..count {
        let dirs: Vec<String> = shards
            .iter()
            .filter(|s| s.shard.count == count && s.shard.index == i)
            .map(|s| s.dir.display().to_string())
            .collect();
        match dirs.len() {
            0 => problems.push(format!("shard {i}/{count} is missing")),
            1 => {}
            _ => problems.push(format!(
                "shard {i}/{count} is given twice: {}",
                dirs.join(" and ")
            )),
        }
    }
    if problems.is_empty() {
        Ok(())
    } else {
        Err(RunError::Input(format!(
            "the shards do not cover the campaign exactly once: {}",
            problems.join("; ")
        )))
    }
}

/// Join shard directories (any order) into `out`: rows in instance order, statistics recomputed,
/// metadata as the unsharded run writes it. Checks that the shards are of one campaign and
/// cover it exactly once.
pub fn merge(dirs: &[PathBuf], out: &Path, force: bool) -> Result<RunReport, RunError> {
    refuse_output_among_inputs(dirs, out)?;
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
            let odd: Vec<String> = shards
                .iter()
                .filter(|s| meta_value(&s.meta, key) != meta_value(&first.meta, key))
                .map(|s| format!("shard {} ({})", s.shard, s.dir.display()))
                .collect();
            return Err(RunError::Input(format!(
                "the shards differ in {key}: {} differ{} from shard {} ({}); they are not one \
                 campaign",
                odd.join(", "),
                if odd.len() == 1 { "s" } else { "" },
                first.shard,
                first.dir.display()
            )));
        }
    }
    check_cover(&shards, count)?;
    let path = meta_value(&first.meta, "cryoslosh.campaign_path").unwrap_or("campaign.toml");
    let text = meta_value(&first.meta, "cryoslosh.campaign").unwrap_or_default();
    let c = Campaign::from_text(Path::new(path), text, &[])?;
    let total: u64 = meta_value(&first.meta, "cryoslosh.instances")
        .and_then(|v| v.parse().ok())
        .unwrap_or(0);

    let staging = Staging::begin(out, force, false)?;
    let dir = staging.path().to_path_buf();
    let mut meta = first.meta.clone();
    set_meta(&mut meta, "cryoslosh.shard", Shard::ALL.to_string());
    // Shards run by different CPU builds (an AVX2 and an AVX-512 machine) give the same bits;
    // the merged files name every build that ran, in shard order.
    let mut builds: Vec<&str> = Vec::new();
    for b in shards
        .iter()
        .filter_map(|s| meta_value(&s.meta, "cryoslosh.build"))
    {
        if !builds.contains(&b) {
            builds.push(b);
        }
    }
    let build = builds.join(" | ");
    if builds.len() > 1 {
        set_meta(&mut meta, "cryoslosh.build", build.clone());
    }
    let inst_path = dir.join("instances.parquet");
    let mut writer = InstanceWriter::create(&inst_path, &c, meta.clone())?;
    let (mut rows, mut diverged, mut rejected) = (0, 0, 0);
    for s in &shards {
        let file = s.dir.join("instances.parquet");
        let (d, r) = verify_shard(&c, s, &file, total)?;
        diverged += d;
        rejected += r;
        rows += table::copy_rows(&mut writer, &file)?;
    }
    writer.finish()?;
    // Events (`run --events`): every shard has them or none does.
    let with_events: Vec<bool> = shards
        .iter()
        .map(|s| s.dir.join("events.parquet").is_file())
        .collect();
    if with_events.iter().any(|&e| e != with_events[0]) {
        let odd: Vec<String> = shards
            .iter()
            .zip(&with_events)
            .filter(|(_, &e)| e != with_events[0])
            .map(|(s, _)| format!("shard {} ({})", s.shard, s.dir.display()))
            .collect();
        return Err(RunError::Input(format!(
            "{} {} events.parquet and shard {} ({}) {}: run every shard with --events, or none",
            odd.join(", "),
            if with_events[0] { "lack" } else { "have" },
            first.shard,
            first.dir.display(),
            if with_events[0] { "has it" } else { "does not" },
        )));
    }
    if with_events[0] {
        let path = dir.join("events.parquet");
        let phases = table::phase_names(&c);
        let mut events = super::events::EventWriter::create(&path, &phases, meta.clone())?;
        for s in &shards {
            events.copy_rows(&s.dir.join("events.parquet"))?;
        }
        events.finish()?;
    }
    // The shards' histories come along (their file names are instance numbers: no clashes).
    for s in &shards {
        let from = s.dir.join("histories");
        let Ok(entries) = std::fs::read_dir(&from) else {
            continue;
        };
        let to = dir.join("histories");
        std::fs::create_dir_all(&to).map_err(|source| OutputError::Io {
            path: to.clone(),
            source,
        })?;
        for e in entries.filter_map(Result::ok) {
            std::fs::copy(e.path(), to.join(e.file_name())).map_err(|source| OutputError::Io {
                path: to.join(e.file_name()),
                source,
            })?;
        }
    }
    failpoint("merge-after-instances").map_err(|source| OutputError::Io {
        path: dir.clone(),
        source,
    })?;
    if rows != total {
        return Err(RunError::Input(format!(
            "the shards hold {rows} instances, the campaign {total}"
        )));
    }
    let seed = meta_value(&first.meta, "cryoslosh.seed")
        .and_then(|v| v.parse().ok())
        .unwrap_or(c.seed);
    let stats = finish_statistics(&c, &dir, total, seed, true, meta)?;
    // Counts from the rows (each shard's checked against its run.json), never copied.
    let report = RunReport {
        instances: rows,
        diverged,
        rejected,
        instance_steps: table::read_u64(&inst_path, "steps")?.iter().sum(),
        resumed_steps: shards
            .iter()
            .map(|s| s.run["resumed_instance_steps"].as_u64().unwrap_or(0))
            .sum(),
        rhs_evaluations: table::read_u64(&inst_path, "rhs_evaluations")?.iter().sum(),
        resumed_rhs_evaluations: shards
            .iter()
            .map(|s| s.run["resumed_rhs_evaluations"].as_u64().unwrap_or(0))
            .sum(),
        wall_s: shards
            .iter()
            .map(|s| s.run["wall_s"].as_f64().unwrap_or(0.0))
            .sum(),
        backend: first.run["backend"].as_str().unwrap_or("cpu").into(),
        device: format!("{count} shards (merged)"),
        build,
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
        until: None,
        histories: Vec::new(),
        statistics: stats,
        shards: shards.iter().map(shard_record).collect(),
    };
    write_run_json(&dir, &report, total)?;
    staging.publish()?;
    Ok(report)
}

/// What a merged `run.json` keeps of one shard's own: where and how it ran and what it cost
/// (the merge's own wall time and rates are over the shards' summed, which says nothing of
/// whether they ran side by side).
fn shard_record(s: &ShardDir) -> serde_json::Value {
    const KEYS: [&str; 11] = [
        "shard",
        "device",
        "build",
        "threads",
        "wall_s",
        "instance_steps",
        "resumed_instance_steps",
        "instance_steps_per_s",
        "rhs_evaluations",
        "resumed_rhs_evaluations",
        "rhs_evaluations_per_s",
    ];
    let mut m = serde_json::Map::new();
    for k in KEYS {
        m.insert(k.into(), s.run.get(k).cloned().unwrap_or_default());
    }
    m.into()
}

/// `merge … --out` may not be (or contain, or lie inside) one of its shard directories.
fn refuse_output_among_inputs(dirs: &[PathBuf], out: &Path) -> Result<(), RunError> {
    let canon = |p: &Path| std::fs::canonicalize(p).unwrap_or_else(|_| p.to_path_buf());
    let out_c = match std::fs::canonicalize(out) {
        Ok(p) => p,
        // A missing --out: compare its would-be location through its parent.
        Err(_) => match (out.parent(), out.file_name()) {
            (Some(parent), Some(name)) if !parent.as_os_str().is_empty() => {
                canon(parent).join(name)
            }
            _ => canon(Path::new(".")).join(out),
        },
    };
    for d in dirs {
        let d_c = canon(d);
        if out_c.starts_with(&d_c) || d_c.starts_with(&out_c) {
            return Err(RunError::Input(format!(
                "--out {}: it is (or overlaps) the shard directory {}: merge into a new directory",
                out.display(),
                d.display()
            )));
        }
    }
    Ok(())
}

/// A shard's file must have the merged schema (names and types, in order) and hold exactly the
/// instance ids of its declared range, in order.
/// Returns the shard's diverged and rejected counts, read from its rows.
fn verify_shard(
    c: &Campaign,
    s: &ShardDir,
    file: &Path,
    total: u64,
) -> Result<(u64, u64), RunError> {
    let bad =
        |why: String| RunError::Input(format!("shard {} ({}): {why}", s.shard, s.dir.display()));
    let input_columns: Vec<String> = c
        .dispersions
        .inputs
        .iter()
        .map(|i| i.column.clone())
        .collect();
    let expected = table::schema(&input_columns, &table::phase_names(c));
    let found = table::read_schema(file)?;
    let want: Vec<(String, String)> = expected
        .iter()
        .map(|spec| (spec.name.clone(), spec.kind.to_string()))
        .collect();
    if found != want {
        let first_diff = want
            .iter()
            .zip(&found)
            .position(|(a, b)| a != b)
            .unwrap_or(want.len().min(found.len()));
        let show = |v: &[(String, String)]| {
            v.get(first_diff)
                .map_or_else(|| "(none)".to_string(), |(n, k)| format!("{n} ({k})"))
        };
        return Err(bad(format!(
            "instances.parquet has other columns than the campaign: column {} is {}, expected {}",
            first_diff + 1,
            show(&found),
            show(&want)
        )));
    }
    // run.json says what the rows say.
    let rows_true = |name: &str| -> Result<u64, RunError> {
        Ok(table::read_bool(file, name)?
            .into_iter()
            .filter(|&x| x)
            .count() as u64)
    };
    let (diverged, rejected) = (rows_true("diverged")?, rows_true("rejected")?);
    for (key, declared, actual) in [
        ("diverged", s.run["diverged"].as_u64(), diverged),
        ("rejected", s.run["rejected"].as_u64(), rejected),
    ] {
        if declared != Some(actual) {
            return Err(bad(format!(
                "run.json says {key} {}, its rows {actual}",
                declared.map_or_else(|| "nothing".to_string(), |d| d.to_string())
            )));
        }
    }
    if s.run["shard"].as_str() != Some(s.shard.to_string().as_str())
        || s.run["campaign_instances"].as_u64() != Some(total)
    {
        return Err(bad(
            "run.json names another shard or instance count than its instances.parquet".into(),
        ));
    }
    let ids = table::read_u64(file, "instance")?;
    let range = s.shard.range(total);
    if ids.len() as u64 != range.end - range.start
        || ids.iter().zip(range.clone()).any(|(&a, b)| a != b)
    {
        let wrong = ids
            .iter()
            .zip(range.clone())
            .find(|(&a, b)| a != *b)
            .map_or_else(String::new, |(a, b)| {
                format!("; row {} holds instance {a}", b - range.start)
            });
        return Err(bad(format!(
            "holds {} rows, but shard {} of {total} instances is {}..{}{wrong}",
            ids.len(),
            s.shard,
            range.start,
            range.end
        )));
    }
    Ok((diverged, rejected))
}
