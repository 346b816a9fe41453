//! Resumable runs: every block the engine integrates is committed as a part file
//! (`parts/part-<first instance>.parquet`) followed by `progress.json` (what the run is, how far
//! it got, its running counts and every part's row range and SHA-256), in the run's working
//! directory (`.DIR.partial`, removed once the result is published). A killed run leaves them;
//! `run --resume` checks that it is the same run, re-reads the parts and continues. At the end
//! the parts are joined into `instances.parquet` exactly as `merge` joins shards, so the result
//! is byte-identical to an uninterrupted run.

use super::events::EventWriter;
use super::plan::InstanceRecord;
use super::table::{self, InstanceWriter};
use super::RunError;
use crate::campaign::Campaign;
use crate::output::atomic::write_atomic;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// Running counts of a run, as of its last committed part.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Counts {
    /// Instances committed, from the shard's first.
    pub completed: u64,
    pub steps: u64,
    /// Right-hand-side evaluations of those instances (the `rhs_evaluations` column).
    pub rhs_evaluations: u64,
    pub diverged: u64,
    pub rejected: u64,
    pub rejected_by: BTreeMap<String, u64>,
}

impl Counts {
    /// Add a block's records.
    pub fn add(&mut self, block: &[InstanceRecord]) {
        for r in block {
            self.steps += r.summary.steps;
            self.rhs_evaluations += r.summary.rhs_evaluations;
            self.diverged += u64::from(r.summary.diverged);
            self.rejected += u64::from(r.rejected);
            if let Some(key) = &r.rejected_by {
                *self.rejected_by.entry(key.clone()).or_default() += 1;
            }
        }
        self.completed += block.len() as u64;
    }
}

const PROGRESS: &str = "progress.json";

fn parts_dir(dir: &Path) -> PathBuf {
    dir.join("parts")
}

/// Where a run with `--events` keeps each block's events (`events-<first instance>.parquet`).
fn events_dir(dir: &Path) -> PathBuf {
    dir.join("events")
}

/// The file and its size and SHA-256, as a part record holds them.
fn digest(path: &Path) -> Result<(u64, String), RunError> {
    crate::output::results_dir::digest(path).map_err(|source| {
        RunError::Output(crate::output::OutputError::Io {
            path: path.to_path_buf(),
            source,
        })
    })
}

/// Write a block as its part file, then the progress after it (the part first: progress never
/// names a part that is not whole).
pub fn commit(
    dir: &Path,
    c: &Campaign,
    identity: &serde_json::Value,
    block: &[InstanceRecord],
    counts: &Counts,
    parts_so_far: &mut Vec<serde_json::Value>,
) -> Result<(), RunError> {
    let Some(first) = block.first() else {
        return Ok(());
    };
    let parts = parts_dir(dir);
    std::fs::create_dir_all(&parts).map_err(|source| crate::output::OutputError::Io {
        path: parts.clone(),
        source,
    })?;
    let name = format!("part-{:012}.parquet", first.instance);
    let path = parts.join(&name);
    let phases = table::phase_names(c);
    // The block's events first: a part record names only whole files.
    let events = if c.record_events {
        let dir = events_dir(dir);
        std::fs::create_dir_all(&dir).map_err(|source| crate::output::OutputError::Io {
            path: dir.clone(),
            source,
        })?;
        let file = format!("events-{:012}.parquet", first.instance);
        let mut w = EventWriter::create(&dir.join(&file), &phases, Vec::new())?;
        for r in block {
            w.push(r)?;
        }
        w.finish()?;
        let (bytes, sha) = digest(&dir.join(&file))?;
        serde_json::json!({"file": file, "bytes": bytes, "sha256": sha})
    } else {
        serde_json::Value::Null
    };
    let mut w = InstanceWriter::create(&path, c, Vec::new())?;
    for r in block {
        w.push(r)?;
    }
    w.finish()?;
    let (bytes, sha) = crate::output::results_dir::digest(&path).map_err(|source| {
        crate::output::OutputError::Io {
            path: path.clone(),
            source,
        }
    })?;
    parts_so_far.push(serde_json::json!({
        "file": name,
        "first": first.instance,
        "rows": block.len(),
        "bytes": bytes,
        "sha256": sha,
        "events": events,
    }));
    let json = serde_json::json!({
        "parts": parts_so_far,
        "identity": identity,
        "completed": counts.completed,
        "steps": counts.steps,
        "rhs_evaluations": counts.rhs_evaluations,
        "diverged": counts.diverged,
        "rejected": counts.rejected,
        "rejected_by": counts.rejected_by,
    });
    write_atomic(&dir.join(PROGRESS), json.to_string().as_bytes())?;
    Ok(())
}

/// An interrupted run's state: its counts, its part records and the part files in instance
/// order. Every part the progress lists must be whole (its SHA-256) and hold exactly its rows,
/// contiguous from `first_instance`; a part written after the last progress is dropped.
pub fn load(
    dir: &Path,
    identity: &serde_json::Value,
    first_instance: u64,
) -> Result<(Counts, Vec<serde_json::Value>, Vec<PathBuf>), RunError> {
    let bad = |why: String| RunError::Input(format!("--resume: {why}"));
    let text = std::fs::read_to_string(dir.join(PROGRESS))
        .map_err(|_| bad("the interrupted run committed nothing yet: run it again".into()))?;
    let p: serde_json::Value =
        serde_json::from_str(&text).map_err(|e| bad(format!("progress.json: {e}")))?;
    if &p["identity"] != identity {
        return Err(bad(
            "the interrupted run in that directory is another run (campaign, seed, instances, \
             shard, backend or target differ): give the same command, or run without --resume"
                .into(),
        ));
    }
    let u = |k: &str| p[k].as_u64().unwrap_or(0);
    let counts = Counts {
        completed: u("completed"),
        steps: u("steps"),
        rhs_evaluations: u("rhs_evaluations"),
        diverged: u("diverged"),
        rejected: u("rejected"),
        rejected_by: p["rejected_by"]
            .as_object()
            .map(|m| {
                m.iter()
                    .map(|(k, v)| (k.clone(), v.as_u64().unwrap_or(0)))
                    .collect()
            })
            .unwrap_or_default(),
    };
    let records: Vec<serde_json::Value> = p["parts"].as_array().cloned().unwrap_or_default();
    let mut files = Vec::new();
    let mut event_files = Vec::new();
    let mut next = first_instance;
    for r in &records {
        let name = r["file"].as_str().unwrap_or_default();
        let path = parts_dir(dir).join(name);
        let (bytes, sha) = crate::output::results_dir::digest(&path)
            .map_err(|e| bad(format!("part {name}: {e}: run without --resume")))?;
        if r["bytes"].as_u64() != Some(bytes) || r["sha256"].as_str() != Some(sha.as_str()) {
            return Err(bad(format!(
                "part {name} changed after it was committed: run without --resume"
            )));
        }
        let ids = table::read_u64(&path, "instance")?;
        let rows = r["rows"].as_u64().unwrap_or(0);
        if r["first"].as_u64() != Some(next)
            || ids.len() as u64 != rows
            || ids.iter().zip(next..).any(|(&a, b)| a != b)
        {
            return Err(bad(format!(
                "part {name} does not hold instances {next} to {}: run without --resume",
                next + rows.saturating_sub(1)
            )));
        }
        if let Some(ev) = r["events"].as_object() {
            let file = ev["file"].as_str().unwrap_or_default();
            let (bytes, sha) = digest(&events_dir(dir).join(file))
                .map_err(|e| bad(format!("events part {file}: {e}: run without --resume")))?;
            if ev["bytes"].as_u64() != Some(bytes) || ev["sha256"].as_str() != Some(sha.as_str()) {
                return Err(bad(format!(
                    "events part {file} changed after it was committed: run without --resume"
                )));
            }
            event_files.push(events_dir(dir).join(file));
        }
        next += rows;
        files.push(path);
    }
    if next - first_instance != counts.completed {
        return Err(bad(format!(
            "the parts hold {} instances, the progress says {}: run without --resume",
            next - first_instance,
            counts.completed
        )));
    }
    // Parts written after the last progress (a kill between the two) are not part of the run.
    for f in parts(dir).into_iter().chain(listing(&events_dir(dir))) {
        if !files.contains(&f) && !event_files.contains(&f) {
            let _ = std::fs::remove_file(f);
        }
    }
    Ok((counts, records, files))
}

/// The part files of `dir` in instance order.
pub fn parts(dir: &Path) -> Vec<PathBuf> {
    listing(&parts_dir(dir))
}

/// The files in `dir`, sorted by name (empty when it does not exist).
fn listing(dir: &Path) -> Vec<PathBuf> {
    let mut files: Vec<PathBuf> = std::fs::read_dir(dir)
        .map(|it| it.filter_map(Result::ok).map(|e| e.path()).collect())
        .unwrap_or_default();
    files.sort();
    files
}

/// Join the parts of the working directory `work` into `out/instances.parquet` with `meta`.
/// The parts stay until the result is published (a kill before that can still be resumed).
pub fn assemble(
    work: &Path,
    out: &Path,
    c: &Campaign,
    meta: Vec<(String, String)>,
) -> Result<PathBuf, RunError> {
    let path = out.join("instances.parquet");
    let mut w = InstanceWriter::create(&path, c, meta.clone())?;
    for part in parts(work) {
        table::copy_rows(&mut w, &part)?;
    }
    w.finish()?;
    if c.record_events {
        let phases = table::phase_names(c);
        let mut events = EventWriter::create(&out.join("events.parquet"), &phases, meta)?;
        for part in listing(&events_dir(work)) {
            events.copy_rows(&part)?;
        }
        events.finish()?;
    }
    Ok(path)
}
