//! Dispersion campaigns: `run` streams instances through an engine into `instances.parquet`,
//! then derives `statistics.parquet` and `run.json`; `merge` joins shard directories into
//! exactly what the unsharded run writes.

pub mod checkpoint;
pub mod differences;
pub mod events;
pub mod histories;
mod merge;
pub mod plan;
pub mod replay;
pub mod screen;
pub mod statistics;
mod summary;
pub mod table;
pub mod until;
pub mod variants;

use crate::campaign::{Campaign, CampaignError};
use crate::engine::Backend;
use crate::output::results_dir::{failpoint, ResultsDirError, Staging};
use crate::output::{atomic::write_atomic, OutputError};
use crate::sampling::Design;
pub use merge::merge;
use plan::Plan;
use statistics::Row;
use std::io::IsTerminal;
use std::ops::Range;
use std::path::{Path, PathBuf};
pub use summary::summary_text;
use table::{ReadError, RowShape};

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
    /// Instances whose time histories are written to DIR/histories after the run.
    pub histories: Vec<histories::Pick>,
    /// Stop early once this estimate is precise enough (`--until`; else the campaign's
    /// `[statistics.target]`); `instances` is then the cap.
    pub until: Option<crate::campaign::statistics::Target>,
    /// Replace a previous result in `out_dir` (a non-empty directory is refused otherwise).
    pub force: bool,
    /// Continue the interrupted run of the same command in `out_dir` (`run --resume`).
    pub resume: bool,
}

impl RunOptions {
    /// The precision target of the run: `--until`, else the campaign's.
    pub fn target<'a>(
        &'a self,
        c: &'a Campaign,
    ) -> Option<&'a crate::campaign::statistics::Target> {
        self.until.as_ref().or(c.statistics.target.as_ref())
    }
}

/// What a run did, as written to run.json.
#[derive(Clone, Debug)]
pub struct RunReport {
    pub instances: u64,
    pub diverged: u64,
    pub rejected: u64,
    pub instance_steps: u64,
    /// Of `instance_steps`, those a resumed run (`--resume`) loaded from the interrupted run's
    /// committed blocks instead of integrating them (0 otherwise): `wall_s` does not cover them.
    pub resumed_steps: u64,
    /// Right-hand-side evaluations of every instance (the `rhs_evaluations` column's sum).
    pub rhs_evaluations: u64,
    /// Of `rhs_evaluations`, those of the instances a resumed run loaded (as `resumed_steps`).
    pub resumed_rhs_evaluations: u64,
    /// Wall time of this invocation's integration, s: sampling, integrating and committing the
    /// instances' blocks (not the loading before it nor the statistics pass after it); a
    /// resumed run: of the part it integrated; a merge: the shards' summed.
    pub wall_s: f64,
    pub backend: String,
    pub device: String,
    /// The CPU build that ran ([`crate::lanes::isa::build_description`]; a merge: each shard's
    /// distinct build, in shard order, joined by " | ").
    pub build: String,
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
    /// A precision-driven run: the summary line and `run.json`'s record of the estimate, its
    /// interval and whether the target was reached.
    pub until: Option<(String, serde_json::Value)>,
    /// What `--histories` wrote (or why not), per instance.
    pub histories: Vec<String>,
    pub statistics: Vec<Row>,
    /// A merge: each shard's own record from its `run.json` (shard, device, build, threads,
    /// wall time and [`Self::cost_json`]), in shard order; empty for a run.
    pub shards: Vec<serde_json::Value>,
}

impl RunReport {
    /// The instance-steps this invocation integrated (a resumed run's loaded from its
    /// checkpoint left out).
    pub fn steps_integrated(&self) -> u64 {
        self.instance_steps.saturating_sub(self.resumed_steps)
    }

    /// Instance-steps per second of the work this invocation did: [`Self::steps_integrated`]
    /// over its wall time (a resumed run's steps loaded from its checkpoint took none of it);
    /// `None` when it integrated nothing (every instance came from the checkpoint). A merge:
    /// over the shards' wall times summed, the rate of one shard's worth of hardware.
    pub fn steps_per_s(&self) -> Option<f64> {
        let n = self.steps_integrated();
        (n > 0).then(|| n as f64 / self.wall_s.max(1e-9))
    }

    /// Right-hand-side evaluations per second of the work this invocation did (as
    /// [`Self::steps_per_s`]): the engine's throughput in the unit that does not depend on the
    /// integrator (an RK4 step costs four, a Dormand–Prince step seven).
    pub fn rhs_evaluations_per_s(&self) -> Option<f64> {
        let n = self
            .rhs_evaluations
            .saturating_sub(self.resumed_rhs_evaluations);
        (self.steps_integrated() > 0).then(|| n as f64 / self.wall_s.max(1e-9))
    }

    /// The cost keys of `run.json` (a run's, each variant's and each merged shard's):
    /// instance_steps, resumed_instance_steps, wall_s, instance_steps_per_s, rhs_evaluations,
    /// resumed_rhs_evaluations, rhs_evaluations_per_s (the rates null when nothing was
    /// integrated now).
    pub fn cost_json(&self) -> serde_json::Map<String, serde_json::Value> {
        let serde_json::Value::Object(m) = serde_json::json!({
            "instance_steps": self.instance_steps,
            "resumed_instance_steps": self.resumed_steps,
            "wall_s": self.wall_s,
            "instance_steps_per_s": self.steps_per_s(),
            "rhs_evaluations": self.rhs_evaluations,
            "resumed_rhs_evaluations": self.resumed_rhs_evaluations,
            "rhs_evaluations_per_s": self.rhs_evaluations_per_s(),
        }) else {
            unreachable!("json! of an object literal is an object")
        };
        m
    }

    /// The summary line's cost: "N instance-steps [(resumed …)] in W s = R instance-steps/s
    /// (E right-hand sides/s)", or that nothing was integrated now; a merge says its time is
    /// the shards' summed.
    pub fn cost_text(&self) -> String {
        let steps = if self.resumed_steps == 0 {
            format!("{} instance-steps", self.instance_steps)
        } else {
            format!(
                "{} instance-steps ({} from the checkpoint, {} integrated now)",
                self.instance_steps,
                self.resumed_steps,
                self.steps_integrated()
            )
        };
        let (time, per) = if self.shards.is_empty() {
            (format!("{:.2} s", self.wall_s), "")
        } else {
            (
                format!(
                    "{:.2} s summed over {} shards' wall times",
                    self.wall_s,
                    self.shards.len()
                ),
                " per shard",
            )
        };
        match (self.steps_per_s(), self.rhs_evaluations_per_s()) {
            (Some(steps_s), Some(rhs_s)) => format!(
                "{steps} in {time} = {steps_s:.3e} instance-steps/s{per} \
                 ({rhs_s:.3e} right-hand sides/s{per})"
            ),
            _ => format!("{steps} in {time} (none integrated now)"),
        }
    }

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
    #[error(transparent)]
    Dir(#[from] ResultsDirError),
}

impl RunError {
    /// Whether the error is the user's input (exit code 2) rather than a runtime failure.
    pub fn is_bad_input(&self) -> bool {
        match self {
            RunError::Campaign(_) | RunError::Input(_) => true,
            RunError::Dir(e) => !matches!(e, ResultsDirError::Io { .. }),
            _ => false,
        }
    }
}

/// A `[statistics]` or `--until` key naming a QoI column, or the error naming the key.
fn check_quantity(c: &Campaign, key: &str, q: &str) -> Result<(), RunError> {
    check_quantity_in(c, key, q, &table::qoi_names(&table::phase_names(c)))
}

/// [`check_quantity`] against the quantity names `names`.
fn check_quantity_in(c: &Campaign, key: &str, q: &str, names: &[String]) -> Result<(), RunError> {
    if names.iter().any(|name| name == q) {
        return Ok(());
    }
    Err(RunError::Campaign(CampaignError::Invalid {
        file: c.path.clone(),
        key: key.to_string(),
        value: format!("{q:?}"),
        allowed: format!(
            "a quantity of instances.parquet{}: {}",
            if names.iter().any(|n| n == "relief_cycles") {
                ""
            } else {
                " read as f64 (the counts relief_cycles and tvs_cycles take thresholds only)"
            },
            names.join(", ")
        ),
    }))
}

/// The quantity a target's estimate is about.
fn target_quantity(t: &crate::campaign::statistics::Target) -> &str {
    match &t.estimate {
        crate::campaign::statistics::TargetEstimate::Probability(th) => &th.quantity,
        crate::campaign::statistics::TargetEstimate::Quantile { quantity, .. } => quantity,
    }
}

/// Check that every `[statistics]` threshold and target names a QoI column.
pub fn check_statistics(c: &Campaign) -> Result<(), RunError> {
    let st = &c.statistics;
    // A threshold may also name a count (relief_cycles, tvs_cycles); a precision target reads
    // the QoIs only.
    let described = table::statistic_names(&table::phase_names(c));
    for t in &st.thresholds {
        check_quantity_in(c, &format!("{}.quantity", t.key), &t.quantity, &described)?;
    }
    if let Some(t) = &st.target {
        check_quantity(c, "statistics.target.quantity", target_quantity(t))?;
    }
    Ok(())
}

/// Check a precision target against the run: one process sees every instance in order, under
/// a design whose samples do not depend on the final count.
fn check_target(c: &Campaign, o: &RunOptions) -> Result<(), RunError> {
    let Some(t) = o.target(c) else {
        return Ok(());
    };
    if let Some(u) = &o.until {
        check_quantity(c, "--until", target_quantity(u))?;
    }
    if o.shard.count > 1 {
        return Err(RunError::Input(
            "--until (or [statistics.target]) needs every instance in one run: not with --shard"
                .into(),
        ));
    }
    if c.dispersions.design == Design::LatinHypercube {
        return Err(RunError::Input(format!(
            "{}: a precision target stops at a count not known in advance, and latin_hypercube \
             strata depend on that count: use monte_carlo or sobol (or drop the target)",
            c.path.display()
        )));
    }
    let _ = t;
    Ok(())
}

/// Tightest tolerances the GPU's error-controlled kernel accepts: its stages are f32 (machine
/// epsilon 6e-8), so a tighter relative tolerance is below its own rounding and the steps
/// collapse (rtol 1e-12 on the LOX ascent had not finished after 170 s on llvmpipe).
pub const GPU_MIN_RTOL: f64 = 1.0e-6;
/// See [`GPU_MIN_RTOL`].
pub const GPU_MIN_ATOL: f64 = 1.0e-9;

/// Most instances one campaign may hold: indices, strata and row counts stay far from overflow
/// (18446744073709551615 used to lose a row or hang).
pub const MAX_INSTANCES: u64 = 1_000_000_000_000;

/// Check run options against the campaign before anything is written.
pub fn check_options(c: &Campaign, o: &RunOptions) -> Result<(), RunError> {
    check_statistics(c)?;
    check_target(c, o)?;
    if o.instances == 0 || o.instances > MAX_INSTANCES {
        return Err(RunError::Input(format!(
            "--instances {}: expected 1 to {MAX_INSTANCES}",
            o.instances
        )));
    }
    if o.chunk_size == 0 {
        return Err(RunError::Input("--chunk-size must be at least 1".into()));
    }
    let (k, group) = (c.dispersions.inputs.len(), c.dispersions.group_size());
    if !o.instances.is_multiple_of(group) {
        return Err(RunError::Input(format!(
            "{}: the saltelli design with {k} inputs needs instances in multiples of k + 2 = {group} (got {})",
            c.path.display(),
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

/// File-level metadata of both Parquet files of a run (the instance count is added once the
/// run knows where it stopped).
fn metadata(c: &Campaign, backend: &str, o_seed: u64, shard: Shard) -> Vec<(String, String)> {
    let mut m = crate::history::provenance(c, backend, &shard.to_string());
    set_meta(&mut m, "cryoslosh.seed", o_seed.to_string());
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

/// Run shard `o.shard` of the campaign on `backend`, writing DIR/instances.parquet,
/// DIR/statistics.parquet and DIR/run.json.
pub fn run(c: &Campaign, backend: &Backend, o: &RunOptions) -> Result<RunReport, RunError> {
    check_options(c, o)?;
    let engine = backend.engine();
    if c.record_events && engine.name() != "cpu" {
        return Err(RunError::Input(
            "--events: events are located on the CPU engine's dense output; run with --backend cpu"
                .into(),
        ));
    }
    let st = &c.stepping;
    if engine.name() == "gpu"
        && st.integrator == crate::campaign::Integrator::Dopri5
        && (st.rtol < GPU_MIN_RTOL || st.atol < GPU_MIN_ATOL)
    {
        return Err(RunError::Input(format!(
            "{}: campaign.rtol = {:e}, campaign.atol = {:e}: the GPU's stages are f32 and hold \
             at best rtol {GPU_MIN_RTOL:e}, atol {GPU_MIN_ATOL:e} (the defaults); tighter \
             tolerances run on --backend cpu",
            c.path.display(),
            st.rtol,
            st.atol
        )));
    }
    let mut staging = Staging::begin(&o.out_dir, o.force, o.resume)?;
    staging.keep_on_failure();
    let dir = staging.path().to_path_buf();
    let work = staging.work().to_path_buf();
    let plan = Plan {
        campaign: c,
        seed: o.seed,
        total: o.instances,
    };
    let range = o.shard.range(o.instances);
    histories::check(&o.histories, c, &range)?;
    let group = c.dispersions.group_size();
    let mut stopper = o.target(c).and_then(|t| {
        let phases = table::phase_names(c);
        let qois = table::qoi_names(&phases);
        let at = (range.start, group);
        until::Stopper::new(
            t.clone(),
            c.statistics.confidence,
            at,
            &qois,
            RowShape::of(c),
        )
    });
    let mut meta = metadata(c, engine.name(), o.seed, o.shard);
    // What makes a run this run: a resumed run must be the same one.
    let identity = serde_json::json!({
        "campaign": c.text,
        "seed": o.seed,
        "instances": o.instances,
        "shard": o.shard.to_string(),
        "backend": engine.name(),
        "target": o.target(c).map(|t| format!("{t:?}")),
        "events": c.record_events,
    });
    let mut counts = checkpoint::Counts::default();
    let mut part_records = Vec::new();
    let mut at = range.start;
    if o.resume {
        let (done, records, parts) = checkpoint::load(&work, &identity, range.start)?;
        part_records = records;
        // Replay the committed rows through the stopping rule, part by part: parts end at its
        // check points, so it reaches the state it had.
        // (`load` checked each part's rows: its record says how many.)
        for (part, record) in parts.iter().zip(&part_records) {
            let n = record["rows"].as_u64().unwrap_or(0);
            if let Some(s) = &mut stopper {
                s.observe_column(&table::read_f64(part, s.quantity())?);
            }
            at += n;
            if stopper.as_mut().is_some_and(|s| s.check(at)) {
                break;
            }
        }
        counts = done;
    }
    let (resumed_steps, resumed_rhs_evaluations) = (counts.steps, counts.rhs_evaluations);
    let mut stop_at = match &stopper {
        Some(s) if s.last.as_ref().is_some_and(|p| p.met) => at,
        _ => range.end,
    };

    let bar = progress_bar_of(o.progress, range.end - range.start, "instances");
    bar.inc(at - range.start);
    let start = std::time::Instant::now();
    // Double buffering: a writer thread commits block k as a part file while the engine
    // integrates block k + 1 (one block in flight bounds memory at two blocks).
    type Message = (Vec<plan::InstanceRecord>, checkpoint::Counts);
    let (tx, rx) = std::sync::mpsc::sync_channel::<Message>(1);
    let outcome = std::thread::scope(|scope| -> Result<(), RunError> {
        let (work, identity, records) = (&work, &identity, &mut part_records);
        let writing = scope.spawn(move || -> Result<(), RunError> {
            for (k, (block, counts)) in rx.into_iter().enumerate() {
                checkpoint::commit(work, c, identity, &block, &counts, records)?;
                failpoint(&format!("after-part-{k}")).map_err(|source| OutputError::Io {
                    path: work.to_path_buf(),
                    source,
                })?;
            }
            Ok(())
        });
        let mut integrated = Ok(());
        while at < stop_at {
            let mut end = (at + o.chunk_size).min(stop_at);
            if let Some(s) = &stopper {
                end = end.min(s.next_check());
            }
            let block = match engine.run_block(&plan, at..end) {
                Ok(b) => b,
                Err(e) => {
                    integrated = Err(RunError::Engine(e));
                    break;
                }
            };
            counts.add(&block);
            if let Some(s) = &mut stopper {
                s.observe(&block);
            }
            if tx.send((block, counts.clone())).is_err() {
                break; // the writer failed; its error is reported below
            }
            bar.inc(end - at);
            at = end;
            if stopper.as_mut().is_some_and(|s| s.check(at)) {
                stop_at = at;
            }
        }
        drop(tx);
        let written = writing
            .join()
            .expect("the Parquet writer thread does not panic");
        integrated.and(written)
    });
    outcome?; // the staging directory stays for `run --resume`
    bar.finish_and_clear();
    let wall_s = start.elapsed().as_secs_f64();
    let checkpoint::Counts {
        steps,
        rhs_evaluations,
        diverged,
        rejected,
        rejected_by,
        ..
    } = counts;

    let full = o.shard.count == 1;
    // A precision-driven run holds the instances up to where it stopped.
    let total = match &mut stopper {
        Some(s) => {
            if s.last
                .as_ref()
                .is_none_or(|p| p.instances != stop_at - range.start)
            {
                s.last = Some(s.progress());
            }
            stop_at
        }
        None => o.instances,
    };
    meta.push(("cryoslosh.instances".into(), total.to_string()));
    let inst_path = checkpoint::assemble(&work, &dir, c, meta.clone())?;
    failpoint("after-instances").map_err(|source| OutputError::Io {
        path: dir.clone(),
        source,
    })?;
    let rows = finish_statistics(c, &dir, total, o.seed, full, meta)?;
    failpoint("after-statistics").map_err(|source| OutputError::Io {
        path: dir.clone(),
        source,
    })?;
    let mut history_notes = Vec::new();
    if !o.histories.is_empty() {
        let (chosen, select_notes) = histories::select(&o.histories, &inst_path)?;
        let written = histories::write(&plan, &dir, &chosen)?;
        // Paths as they will be once the directory is published.
        let published: Vec<(u64, Option<PathBuf>)> = written
            .into_iter()
            .map(|(i, f)| (i, f.map(|_| histories::history_path(&o.out_dir, i))))
            .collect();
        history_notes = histories::outcome(&o.histories, &chosen, &published);
        history_notes.extend(select_notes);
    }
    let report = RunReport {
        instances: stop_at - range.start,
        diverged,
        rejected,
        instance_steps: steps,
        resumed_steps,
        rhs_evaluations,
        resumed_rhs_evaluations,
        wall_s,
        backend: engine.name().into(),
        device: engine.device(),
        build: crate::lanes::isa::build_description(),
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
        until: stopper.as_ref().map(|s| (s.describe(), s.to_json())),
        histories: history_notes,
        statistics: rows,
        shards: Vec::new(),
    };
    write_run_json(&dir, &report, total)?;
    staging.publish()?;
    Ok(report)
}

/// Statistics of DIR/instances.parquet → DIR/statistics.parquet. Sobol indices need every row
/// of a Saltelli design, so shards report them only once merged.
fn finish_statistics(
    c: &Campaign,
    dir: &Path,
    total: u64,
    seed: u64,
    full: bool,
    meta: Vec<(String, String)>,
) -> Result<Vec<Row>, RunError> {
    let mut d = c.dispersions.clone();
    if !full && d.design == Design::Saltelli {
        d.design = Design::Sobol;
    }
    let spec = statistics::Spec {
        dispersions: d,
        plan: c.statistics.clone(),
        meop_pa: c.params.meop_pa,
        boiloff_budget_kg: c.dispersions.boiloff_budget_kg,
        total,
        seed,
        phases: table::phase_names(c),
    };
    let rows = statistics::compute(&dir.join("instances.parquet"), &spec)?;
    statistics::write(&dir.join("statistics.parquet"), &rows, meta)?;
    Ok(rows)
}

/// A progress bar on stderr over `len` items called `what` (hidden when `enabled` is false or
/// stderr is not a terminal).
pub fn progress_bar_of(enabled: bool, len: u64, what: &str) -> indicatif::ProgressBar {
    if !enabled || !std::io::stderr().is_terminal() {
        return indicatif::ProgressBar::hidden();
    }
    let bar = indicatif::ProgressBar::new(len);
    let template = format!("{{bar:40}} {{pos}}/{{len}} {what}  {{per_sec}}  ETA {{eta}}");
    if let Ok(style) = indicatif::ProgressStyle::with_template(&template) {
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
        "backend": r.backend,
        "device": r.device,
        "threads": r.threads,
        "seed": r.seed,
        "shard": r.shard,
        "design": r.design,
        "integrator": r.integrator,
        "rejected_by": r.rejected_by.iter().map(|(k, n)| (k.clone(), serde_json::json!(n))).collect::<serde_json::Map<_, _>>(),
        "untrusted": r.untrusted(),
        "until": r.until.as_ref().map(|(_, json)| json),
        "histories": r.histories,
        "version": crate::VERSION,
        "build": r.build,
    });
    let mut json = json;
    if let serde_json::Value::Object(m) = &mut json {
        m.extend(r.cost_json());
        if !r.shards.is_empty() {
            m.insert("shards".into(), r.shards.clone().into());
        }
    }
    let text = serde_json::to_string_pretty(&json).map_err(|e| RunError::Input(e.to_string()))?;
    write_atomic(&dir.join("run.json"), text.as_bytes())?;
    Ok(())
}
