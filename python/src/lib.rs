//! `cryoslosh._native`: the engine behind the `cryoslosh` Python package. Each call does what the
//! CLI command of the same name does, through the same library functions
//! ([`cryoslosh::runner`]), with the GIL released while the engine integrates; tables come back
//! as pyarrow tables through the Arrow C data interface.

mod errors;
mod scratch;
mod tables;

use cryoslosh::campaign::Campaign;
use cryoslosh::montecarlo;
use cryoslosh::runner::{self, Ran, RunArgs, RunnerError};
use cryoslosh::simulate::History;
use pyo3::prelude::*;
use std::path::{Path, PathBuf};

/// What `run` and `merge` hand back: instances and statistics tables (`None` for a campaign with
/// `[[variants]]`), run.json's text, why the statistics cannot be signed (CLI exit code 3) or
/// `None`, and for a campaign with variants each variant's (name, instances, statistics,
/// run.json) and the differences table.
type Results<'py> = (
    Option<Bound<'py, PyAny>>,
    Option<Bound<'py, PyAny>>,
    String,
    Option<String>,
    Vec<Variant<'py>>,
    Option<Bound<'py, PyAny>>,
);

/// One variant of a run with `[[variants]]`: its name, instances, statistics and run.json.
type Variant<'py> = (String, Bound<'py, PyAny>, Bound<'py, PyAny>, String);

/// What `simulate` hands back: the history, the sampled inputs and the summary text.
type Simulated<'py> = (Bound<'py, PyAny>, Vec<(String, f64)>, String);

/// What `replay` hands back: the history (none for a rejected instance) and the differing
/// columns as (name, file value, replayed value).
type Replayed<'py> = (Option<Bound<'py, PyAny>>, Vec<(String, f64, f64)>);

/// The three files of a results directory, decoded without the GIL.
struct Read {
    instances: tables::Decoded,
    statistics: tables::Decoded,
    run_json: String,
}

fn read_dir(dir: &Path) -> Result<Read, String> {
    Ok(Read {
        instances: tables::read(&dir.join("instances.parquet"))?,
        statistics: tables::read(&dir.join("statistics.parquet"))?,
        run_json: read_text(&dir.join("run.json"))?,
    })
}

fn read_text(path: &Path) -> Result<String, String> {
    std::fs::read_to_string(path).map_err(|e| format!("{}: {e}", path.display()))
}

/// A results directory as the CLI wrote it: one run, or one run per variant and the
/// differences.
enum Written {
    Plain(Read),
    Variants {
        run_json: String,
        variants: Vec<(String, Read)>,
        differences: tables::Decoded,
    },
}

/// Read what a run or merge wrote into `dir` (`names`: its variants, if it had any).
fn read_written(dir: &Path, names: Option<&[String]>) -> Result<Written, String> {
    let Some(names) = names else {
        return read_dir(dir).map(Written::Plain);
    };
    let variants = names
        .iter()
        .map(|n| {
            Ok((
                n.clone(),
                read_dir(&montecarlo::variants::variant_dir(dir, n))?,
            ))
        })
        .collect::<Result<_, String>>()?;
    Ok(Written::Variants {
        run_json: read_text(&dir.join("run.json"))?,
        variants,
        differences: tables::read(&dir.join("differences.parquet"))?,
    })
}

/// Failures of a call made without the GIL, turned into exceptions once it is held again.
enum Failure {
    Runner(Box<RunnerError>),
    Io(String),
}

impl From<RunnerError> for Failure {
    fn from(e: RunnerError) -> Failure {
        Failure::Runner(Box::new(e))
    }
}

impl Failure {
    fn into_py(self, py: Python<'_>) -> PyErr {
        match self {
            Failure::Runner(e) => errors::to_py(py, &e),
            Failure::Io(m) => errors::failed(py, m),
        }
    }
}

fn results<'py>(py: Python<'py>, w: Written, untrusted: Option<String>) -> PyResult<Results<'py>> {
    match w {
        Written::Plain(r) => Ok((
            Some(r.instances.into_py(py)?),
            Some(r.statistics.into_py(py)?),
            r.run_json,
            untrusted,
            Vec::new(),
            None,
        )),
        Written::Variants {
            run_json,
            variants,
            differences,
        } => {
            let variants = variants
                .into_iter()
                .map(|(name, r)| {
                    let (i, s) = (r.instances.into_py(py)?, r.statistics.into_py(py)?);
                    Ok((name, i, s, r.run_json))
                })
                .collect::<PyResult<_>>()?;
            let differences = Some(differences.into_py(py)?);
            Ok((None, None, run_json, untrusted, variants, differences))
        }
    }
}

/// `cryoslosh run`: run the campaign (or one shard of it) into `out` (a scratch directory,
/// removed afterwards, when `None`) and return its tables — of every variant and their
/// differences for a campaign with `[[variants]]`.
#[pyfunction]
#[pyo3(signature = (campaign, out=None, instances=None, seed=None, sets=Vec::new(), backend="cpu".to_string(), threads=0, shard=None, chunk_size=None, force=false))]
#[expect(
    clippy::too_many_arguments,
    reason = "mirrors the CLI's options, passed by keyword from Python"
)]
fn run<'py>(
    py: Python<'py>,
    campaign: PathBuf,
    out: Option<PathBuf>,
    instances: Option<u64>,
    seed: Option<u64>,
    sets: Vec<String>,
    backend: String,
    threads: usize,
    shard: Option<String>,
    chunk_size: Option<u64>,
    force: bool,
) -> PyResult<Results<'py>> {
    let scratch = match out {
        Some(dir) => scratch::Scratch::keep(dir),
        None => scratch::Scratch::new().map_err(|m| errors::failed(py, m))?,
    };
    let args = RunArgs {
        campaign,
        out: scratch.path().to_path_buf(),
        instances,
        seed,
        backend,
        threads,
        shard,
        chunk_size,
        set: sets,
        force,
        progress: false,
        ..RunArgs::default()
    };
    let done = py.detach(|| -> Result<(Written, Option<String>), Failure> {
        let (names, untrusted) = match runner::run(&args).map_err(Failure::from)? {
            Ran::Plain(f) => (None, f.report.untrusted()),
            Ran::Variants(f) => (Some(f.report.names.clone()), f.report.untrusted()),
        };
        let read = read_written(&args.out, names.as_deref()).map_err(Failure::Io)?;
        Ok((read, untrusted))
    });
    drop(scratch);
    let (read, untrusted) = done.map_err(|f| f.into_py(py))?;
    results(py, read, untrusted)
}

/// `cryoslosh merge`: join shard directories (of a run with or without variants) into `out` and
/// return its tables.
#[pyfunction]
#[pyo3(signature = (dirs, out, force=false))]
fn merge<'py>(
    py: Python<'py>,
    dirs: Vec<PathBuf>,
    out: PathBuf,
    force: bool,
) -> PyResult<Results<'py>> {
    let done = py.detach(|| -> Result<(Written, Option<String>), Failure> {
        let failed = |e| Failure::from(RunnerError::Run(e));
        let variants = dirs
            .first()
            .is_some_and(|d| montecarlo::variants::is_variants_dir(d));
        let (names, untrusted) = if variants {
            let r = montecarlo::variants::merge_variants(&dirs, &out, force).map_err(failed)?;
            (Some(r.names.clone()), r.untrusted())
        } else {
            let r = montecarlo::merge(&dirs, &out, force).map_err(failed)?;
            (None, r.untrusted())
        };
        let read = read_written(&out, names.as_deref()).map_err(Failure::Io)?;
        Ok((read, untrusted))
    });
    let (read, untrusted) = done.map_err(|f| f.into_py(py))?;
    results(py, read, untrusted)
}

/// `cryoslosh check`: the text the CLI prints; raises what it exits with.
#[pyfunction]
#[pyo3(signature = (campaign, sets=Vec::new()))]
fn check(py: Python<'_>, campaign: PathBuf, sets: Vec<String>) -> PyResult<String> {
    let checked = py
        .detach(|| runner::check(&campaign, &sets).map_err(Failure::from))
        .map_err(|f| f.into_py(py))?;
    match checked.error {
        Some(e) => Err(errors::to_py(py, &e)),
        None => Ok(checked.text),
    }
}

/// `cryoslosh simulate`: the time history of the nominal (or of instance `instance` of the
/// dispersion campaign), its sampled inputs and the summary the CLI prints.
#[pyfunction]
#[pyo3(signature = (campaign, instance=None, sets=Vec::new()))]
fn simulate<'py>(
    py: Python<'py>,
    campaign: PathBuf,
    instance: Option<u64>,
    sets: Vec<String>,
) -> PyResult<Simulated<'py>> {
    let done = py.detach(|| -> Result<_, Failure> {
        let nominal = Campaign::load(&campaign, &sets)
            .map_err(|e| Failure::from(RunnerError::Campaign(e)))?;
        let (mut c, label, inputs) = match instance {
            None => (nominal, "nominal".to_string(), Vec::new()),
            Some(i) => {
                let values = runner::instance_inputs(&nominal, &sets, i).map_err(Failure::from)?;
                let keys = nominal.dispersions.inputs.iter().map(|d| d.key.clone());
                let inputs: Vec<(String, f64)> = keys.zip(values.iter().copied()).collect();
                let c = runner::instance_campaign(&nominal, &values).map_err(Failure::from)?;
                (c, i.to_string(), inputs)
            }
        };
        c.record_events = true;
        let mut h = History::default();
        let q = cryoslosh::simulate::simulate(&c, &c.params, Some(&mut h));
        let table = history_table(&c, &h, &label, q.divergence())?;
        Ok((table, inputs, cryoslosh::simulate::describe_summary(&q)))
    });
    let (table, inputs, summary) = done.map_err(|f| f.into_py(py))?;
    Ok((table.into_py(py)?, inputs, summary))
}

/// `cryoslosh simulate --run DIR --instance I`: the instance's history (`None` for a rejected
/// instance) and the columns where its row of `DIR/instances.parquet` differs from the replay.
#[pyfunction]
fn replay<'py>(py: Python<'py>, dir: PathBuf, instance: u64) -> PyResult<Replayed<'py>> {
    let done = py.detach(|| -> Result<_, Failure> {
        let mut h = History::default();
        let (run, record) = montecarlo::replay::replay(&dir, instance, Some(&mut h))
            .map_err(|e| Failure::from(RunnerError::Run(e)))?;
        let c = &run.campaign;
        let diffs = montecarlo::replay::compare_row(&dir, c, &record)
            .map_err(|e| Failure::from(RunnerError::Run(e)))?;
        let table = if record.rejected {
            None
        } else {
            let q = &record.summary;
            Some(history_table(c, &h, &instance.to_string(), q.divergence())?)
        };
        Ok((table, diffs))
    });
    let (table, diffs) = done.map_err(|f| f.into_py(py))?;
    Ok((table.map(|t| t.into_py(py)).transpose()?, diffs))
}

/// A history as the CLI writes it (same columns and metadata), decoded back.
fn history_table(
    c: &Campaign,
    h: &History,
    label: &str,
    diverged: Option<&str>,
) -> Result<tables::Decoded, Failure> {
    let dir = scratch::Scratch::new().map_err(Failure::Io)?;
    std::fs::create_dir_all(dir.path()).map_err(|e| Failure::Io(e.to_string()))?;
    let path = dir.path().join("history.parquet");
    cryoslosh::history::write_history(&path, c, h, label, diverged)
        .map_err(|e| Failure::Io(errors::message(&e)))?;
    tables::read(&path).map_err(Failure::Io)
}

/// The package's engine module.
#[pymodule]
fn _native(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("__version__", cryoslosh::VERSION)?;
    m.add_function(wrap_pyfunction!(run, m)?)?;
    m.add_function(wrap_pyfunction!(merge, m)?)?;
    m.add_function(wrap_pyfunction!(check, m)?)?;
    m.add_function(wrap_pyfunction!(simulate, m)?)?;
    m.add_function(wrap_pyfunction!(replay, m)?)?;
    Ok(())
}
