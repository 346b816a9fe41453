//! The `run` and `check` commands as library calls, shared by the CLI (`src/main.rs`) and the
//! Python package (`python/`): the same options, the same backend choice, the same errors, so a
//! run from Python writes the bytes `cryoslosh run` writes.

use crate::campaign::{Campaign, CampaignError};
use crate::engine::{Backend, CpuEngine};
use crate::gpu::context::{self, GpuError};
use crate::gpu::engine::GpuEngine;
use crate::montecarlo::variants::VariantsReport;
use crate::montecarlo::{self, RunError, RunOptions, RunReport, Shard};
use std::path::PathBuf;

/// Most worker threads `--threads` accepts (100000 used to spawn ~16000 threads and stall the
/// machine).
pub const MAX_THREADS: usize = 1024;

/// Why a command failed, in the classes the CLI maps to exit codes.
#[derive(Debug, thiserror::Error)]
pub enum RunnerError {
    /// The campaign file or a `--set` (exit code 2).
    #[error(transparent)]
    Campaign(#[from] CampaignError),
    /// The run or merge itself: bad options (exit 2) or a runtime failure (exit 1).
    #[error(transparent)]
    Run(#[from] RunError),
    /// A command-line value outside its allowed range (exit code 2).
    #[error("{0}")]
    BadInput(String),
    /// The GPU failed to open or run (exit code 1).
    #[error(transparent)]
    Gpu(#[from] GpuError),
    /// The CPU worker pool could not start (exit code 1).
    #[error(transparent)]
    Pool(#[from] rayon::ThreadPoolBuildError),
}

impl RunnerError {
    /// Whether the error is the user's input (exit code 2) rather than a runtime failure.
    pub fn is_bad_input(&self) -> bool {
        match self {
            RunnerError::Campaign(_) | RunnerError::BadInput(_) => true,
            RunnerError::Run(e) => e.is_bad_input(),
            RunnerError::Gpu(_) | RunnerError::Pool(_) => false,
        }
    }

    /// The campaign error behind this one, when there is one: it names file, key, value and
    /// allowed range.
    pub fn campaign_error(&self) -> Option<&CampaignError> {
        match self {
            RunnerError::Campaign(e) | RunnerError::Run(RunError::Campaign(e)) => Some(e),
            _ => None,
        }
    }
}

/// Everything `cryoslosh run` takes, as written on the command line (unparsed where the CLI
/// parses, so both front ends give the same messages).
#[derive(Clone, Debug, Default)]
pub struct RunArgs {
    /// Campaign TOML file.
    pub campaign: PathBuf,
    /// Output directory.
    pub out: PathBuf,
    /// Instances in the whole campaign (default: `campaign.instances`, or the target's cap).
    pub instances: Option<u64>,
    /// Random seed (default: `campaign.seed`).
    pub seed: Option<u64>,
    /// `cpu`, `gpu` or `auto`.
    pub backend: String,
    /// Worker threads (0: one per core).
    pub threads: usize,
    /// `I/N`.
    pub shard: Option<String>,
    /// Instances handed to the engine at a time (default: 16384 on the CPU, 262144 on a GPU).
    pub chunk_size: Option<u64>,
    /// `KEY=VALUE` overrides.
    pub set: Vec<String>,
    /// Replace a previous result in `out`.
    pub force: bool,
    /// `--histories LIST`.
    pub histories: Option<String>,
    /// `--until SPEC`.
    pub until: Option<String>,
    /// Continue an interrupted run.
    pub resume: bool,
    /// Write `events.parquet`.
    pub events: bool,
    /// Draw a progress bar on a terminal.
    pub progress: bool,
}

/// A finished run: the campaign as run, its options and what run.json records.
pub struct Finished {
    pub campaign: Campaign,
    pub options: RunOptions,
    pub report: RunReport,
}

/// A finished run of a campaign with `[[variants]]`: one results directory per variant under
/// `DIR/variants/` and `DIR/differences.parquet`.
pub struct FinishedVariants {
    pub campaign: Campaign,
    pub options: RunOptions,
    pub report: VariantsReport,
}

/// What [`run`] finished.
pub enum Ran {
    /// A campaign without variants (boxed, as the other: each holds a whole campaign).
    Plain(Box<Finished>),
    /// A campaign with `[[variants]]`.
    Variants(Box<FinishedVariants>),
}

/// A campaign ready to run: loaded with its overrides, options checked, backend open.
pub struct Prepared {
    pub campaign: Campaign,
    pub backend: Backend,
    pub options: RunOptions,
}

/// `cryoslosh run`: load the campaign, check the options, pick the backend and run it — a
/// campaign with `[[variants]]` every variant on the same instances, as the CLI does.
pub fn run(a: &RunArgs) -> Result<Ran, RunnerError> {
    let prepared = prepare(a)?;
    if prepared.campaign.variants.is_empty() {
        execute(prepared).map(|f| Ran::Plain(Box::new(f)))
    } else {
        execute_variants(prepared).map(|f| Ran::Variants(Box::new(f)))
    }
}

/// Run a prepared campaign without variants.
pub fn execute(p: Prepared) -> Result<Finished, RunnerError> {
    let report = montecarlo::run(&p.campaign, &p.backend, &p.options)?;
    Ok(Finished {
        campaign: p.campaign,
        options: p.options,
        report,
    })
}

/// Run every variant of a prepared campaign with `[[variants]]`
/// ([`montecarlo::variants::run_variants`]).
pub fn execute_variants(p: Prepared) -> Result<FinishedVariants, RunnerError> {
    let report = montecarlo::variants::run_variants(&p.campaign, &p.backend, &p.options)?;
    Ok(FinishedVariants {
        campaign: p.campaign,
        options: p.options,
        report,
    })
}

/// Load the campaign of `a`, check its options and open the backend, without running.
pub fn prepare(a: &RunArgs) -> Result<Prepared, RunnerError> {
    let mut c = Campaign::load(&a.campaign, &a.set)?;
    c.record_events = a.events;
    let histories = match &a.histories {
        None => Vec::new(),
        Some(spec) => montecarlo::histories::parse(spec).map_err(RunnerError::BadInput)?,
    };
    c.check_overrides_not_dispersed(&a.set)?;
    let shard = match &a.shard {
        None => Shard::ALL,
        Some(s) => Shard::parse(s).ok_or_else(|| {
            RunnerError::BadInput(format!(
                "--shard {s}: expected I/N with 0 ≤ I < N, e.g. 0/4"
            ))
        })?,
    };
    let backend = select_backend(&a.backend, a.threads)?;
    let until = match &a.until {
        None => None,
        Some(spec) => {
            Some(crate::campaign::statistics::parse_until(spec).map_err(RunnerError::BadInput)?)
        }
    };
    let target_cap = c.statistics.target.as_ref().and_then(|t| t.max_instances);
    let options = RunOptions {
        out_dir: a.out.clone(),
        instances: a
            .instances
            .or(if until.is_none() { target_cap } else { None })
            .unwrap_or(c.instances),
        seed: a.seed.unwrap_or(c.seed),
        shard,
        chunk_size: a.chunk_size.unwrap_or(match backend {
            Backend::Cpu(_) => 16_384,
            Backend::Gpu(_) => 262_144,
        }),
        progress: a.progress,
        histories,
        until,
        force: a.force,
        resume: a.resume,
    };
    Ok(Prepared {
        campaign: c,
        backend,
        options,
    })
}

/// What `cryoslosh check` prints, and the error it exits with after printing it (dispersions
/// centred outside a field's allowed range), and why the nominal instance diverged (`check`
/// then exits 1, as `simulate` does on it).
pub struct Checked {
    pub text: String,
    pub error: Option<RunnerError>,
    pub nominal_diverged: Option<String>,
}

/// `cryoslosh check`: validate the campaign and describe its resolved nominal, statistics, step
/// plan and a screen of its first instances.
pub fn check(campaign: &std::path::Path, set: &[String]) -> Result<Checked, RunnerError> {
    let c = Campaign::load(campaign, set)?;
    montecarlo::check_statistics(&c)?;
    let mut text = String::new();
    if let Err(e) = c.check_overrides_not_dispersed(set) {
        text.push_str(&format!(
            "note: the nominal below uses the override, but `run` refuses it: {e}\n"
        ));
    }
    text.push_str(&crate::campaign::describe(&c));
    text.push_str(&crate::campaign::statistics::describe(
        &c.statistics,
        c.dispersions.group_size(),
    ));
    let (plan, nominal_diverged) = crate::simulate::plan::describe_step_plan(&c);
    text.push_str(&plan);
    for (k, v) in c.variants.iter().enumerate() {
        let role = if k == 0 { " (baseline)" } else { "" };
        text.push_str(&format!("variant {}{role}: {}\n", v.name, v.describe()));
    }
    let screen = montecarlo::screen::screen(&c, c.seed, c.instances);
    text.push_str(&montecarlo::screen::describe(
        &screen,
        c.statistics.max_rejected_fraction,
    ));
    let mut median_rejected = screen
        .median_rejected
        .map(|(key, why)| (String::new(), key, why));
    // Each variant draws the same samples into its own campaign: a variant's overrides can move
    // a key's allowed range under them (a lower pump heat rejecting more mixers).
    for (k, v) in c.variants.iter().enumerate() {
        let vc = c.variant(k)?;
        let s = montecarlo::screen::screen(&vc, c.seed, c.instances);
        for line in montecarlo::screen::describe(&s, c.statistics.max_rejected_fraction).lines() {
            text.push_str(&format!("variant {}: {line}\n", v.name));
        }
        if median_rejected.is_none() {
            median_rejected = s
                .median_rejected
                .map(|(key, why)| (format!(" (variant {})", v.name), key, why));
        }
    }
    let error = median_rejected.map(|(variant, key, why)| {
        RunnerError::BadInput(format!(
            "{}{variant}: the dispersions are centred outside the allowed range of {key}: {why}",
            campaign.display()
        ))
    });
    Ok(Checked {
        text,
        error,
        nominal_diverged,
    })
}

/// The sampled inputs of instance `i` of the dispersion campaign (`simulate --instance I`), in
/// the order of `[dispersions]`; refuses an instance beyond `campaign.instances` and a `--set`
/// on a dispersed key.
pub fn instance_inputs(
    nominal: &Campaign,
    set: &[String],
    i: u64,
) -> Result<Vec<f64>, RunnerError> {
    if i >= nominal.instances {
        return Err(RunnerError::BadInput(format!(
            "--instance {i}: the campaign has {} instances (campaign.instances)",
            nominal.instances
        )));
    }
    nominal.check_overrides_not_dispersed(set)?;
    let d = &nominal.dispersions;
    Ok(montecarlo::plan::sample_inputs(
        d,
        nominal.seed,
        nominal.instances,
        i,
    ))
}

/// The campaign of an instance with the sampled `values`, keeping the nominal's text (the
/// history's provenance).
pub fn instance_campaign(nominal: &Campaign, values: &[f64]) -> Result<Campaign, RunnerError> {
    let mut c = nominal.instance(values)?;
    c.text = nominal.text.clone();
    Ok(c)
}

/// The engine for `--backend`: `gpu` opens any adapter (software included) or fails as bad
/// input; `auto` takes a hardware GPU when one opens, else the CPU. Both integrate with either
/// integrator.
pub fn select_backend(name: &str, threads: usize) -> Result<Backend, RunnerError> {
    if threads > MAX_THREADS {
        return Err(RunnerError::BadInput(format!(
            "--threads {threads}: at most {MAX_THREADS} (0 takes one per core)"
        )));
    }
    let gpu = |hardware_only: bool| context::open(hardware_only).and_then(GpuEngine::new);
    match name {
        "cpu" => Ok(Backend::Cpu(CpuEngine::new(threads)?)),
        "gpu" => match gpu(false) {
            Ok(e) => Ok(Backend::Gpu(Box::new(e))),
            Err(e @ GpuError::NoAdapter) => {
                Err(RunnerError::BadInput(format!("--backend gpu: {e}")))
            }
            Err(e) => Err(e.into()),
        },
        "auto" => match gpu(true) {
            Ok(e) => Ok(Backend::Gpu(Box::new(e))),
            Err(_) => Ok(Backend::Cpu(CpuEngine::new(threads)?)),
        },
        other => Err(RunnerError::BadInput(format!(
            "--backend {other}: expected cpu, gpu or auto"
        ))),
    }
}
