//! The `cryoslosh` command line: parses arguments, calls the library, maps errors to exit codes
//! (0 success, 2 bad input, 3 a finished run with too many rejected or diverged instances,
//! 1 anything else).

use anyhow::Context;
use clap::{Parser, Subcommand};
use cryoslosh::campaign::{Campaign, CampaignError};
use cryoslosh::gpu::context;
use cryoslosh::montecarlo::{self, RunError};
use cryoslosh::report::{self, ReportError, ReportOptions};
use cryoslosh::runner::{self, RunnerError};
use cryoslosh::simulate::{self, History};
use std::path::PathBuf;
use std::process::ExitCode;

/// `print!` that returns an error instead of panicking when stdout fails (a full disk: exit 1;
/// a closed pipe: exit 0, see [`stdout_result`]).
macro_rules! out {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        stdout_result(write!(std::io::stdout().lock(), $($arg)*))?
    }};
}

/// `println!` with the error handling of [`out!`].
macro_rules! outln {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        stdout_result(writeln!(std::io::stdout().lock(), $($arg)*))?
    }};
}

/// A closed pipe (`cryoslosh check … | head`) ends the process quietly with exit 0, as `cat`
/// does (Rust ignores SIGPIPE, so the write fails instead); any other failure is an error.
fn stdout_result(r: std::io::Result<()>) -> anyhow::Result<()> {
    match r {
        Err(e) if e.kind() == std::io::ErrorKind::BrokenPipe => std::process::exit(0),
        r => r.context("cannot write to standard output"),
    }
}

/// `--version`: the version and the CPU build ([`cryoslosh::lanes::isa::build_description`]),
/// so that a user can tell which build ran (`-V` prints the version alone).
fn long_version() -> &'static str {
    static TEXT: std::sync::LazyLock<String> = std::sync::LazyLock::new(|| {
        format!(
            "{}\nbuild: {}",
            cryoslosh::VERSION,
            cryoslosh::lanes::isa::build_description()
        )
    });
    TEXT.as_str()
}

#[derive(Parser)]
#[command(
    name = "cryoslosh",
    version,
    long_version = long_version(),
    about = "Monte Carlo dispersion engine for cryogenic propellant tanks"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Validate a campaign and print the resolved nominal inputs and trajectory.
    Check {
        /// Campaign TOML file.
        campaign: PathBuf,
        /// Override a scalar by its dotted key path, e.g. tank.heat_leak_w=40 or phases.1.duration_s=300.
        #[arg(long = "set", value_name = "KEY=VALUE")]
        set: Vec<String>,
    },
    /// Simulate one instance (the nominal) and write its full time history to Parquet.
    Simulate {
        /// Campaign TOML file (not with --run).
        #[arg(required_unless_present = "run")]
        campaign: Option<PathBuf>,
        /// Output Parquet file.
        #[arg(long)]
        out: PathBuf,
        /// Simulate instance I of the dispersion campaign (its sampled inputs) instead of the nominal.
        #[arg(long, required_if_eq_any = [("run", "*")])]
        instance: Option<u64>,
        /// Replay instance I of the finished run in DIR (campaign text, seed, instance count and
        /// design from its metadata) and compare it with its row of DIR/instances.parquet.
        #[arg(long, value_name = "DIR", conflicts_with_all = ["campaign", "set"], requires = "instance")]
        run: Option<PathBuf>,
        /// Override a scalar by its dotted key path (repeatable).
        #[arg(long = "set", value_name = "KEY=VALUE")]
        set: Vec<String>,
    },
    /// Run a dispersion campaign: DIR/instances.parquet, DIR/statistics.parquet, DIR/run.json.
    Run {
        /// Campaign TOML file (its [dispersions] section says what varies).
        campaign: PathBuf,
        /// Output directory (created if missing).
        #[arg(long)]
        out: PathBuf,
        /// Instances in the whole campaign (default: campaign.instances).
        #[arg(long)]
        instances: Option<u64>,
        /// Random seed (default: campaign.seed).
        #[arg(long)]
        seed: Option<u64>,
        /// Backend: cpu, gpu (any Vulkan adapter, Mesa's software lavapipe included) or auto
        /// (a hardware GPU when there is one, else the CPU).
        #[arg(long, default_value = "auto")]
        backend: String,
        /// Worker threads (0: one per core).
        #[arg(long, default_value_t = 0)]
        threads: usize,
        /// Run only shard I of N (contiguous instance slices), e.g. 0/4.
        #[arg(long, value_name = "I/N")]
        shard: Option<String>,
        /// Instances handed to the engine at a time (memory bound; results do not depend on it).
        /// Default: 16384 on the CPU, 262144 on a GPU.
        #[arg(long)]
        chunk_size: Option<u64>,
        /// Override a scalar by its dotted key path (repeatable).
        #[arg(long = "set", value_name = "KEY=VALUE")]
        set: Vec<String>,
        /// Write into a non-empty --out directory (its result files are replaced).
        #[arg(long)]
        force: bool,
        /// After the run, write the time histories of chosen instances to DIR/histories/:
        /// `worst:QOI:N` (the N worst of a QoI: smallest for min_*, else largest) and
        /// `instance:I`, comma-separated, e.g. worst:peak_pressure_pa:5,instance:17.
        #[arg(long, value_name = "LIST")]
        histories: Option<String>,
        /// Integrate until an estimate is precise enough, checking every 100 instances, with
        /// --instances as the cap: QOI>X:H or QOI<X:H (the probability of being above/below X to
        /// ±H), QOI@pNN:H (the NN % quantile to ±H in the QoI's unit), e.g.
        /// peak_pressure_pa>350000:0.002. Default: the campaign's [statistics.target].
        #[arg(long, value_name = "SPEC")]
        until: Option<String>,
        /// Continue the interrupted run of this same command in --out from its committed
        /// blocks; the result equals the uninterrupted run byte for byte.
        #[arg(long)]
        resume: bool,
        /// Also write DIR/events.parquet: every instance's located events (relief valve
        /// openings and closings, thermodynamic vent system starts and stops, pressurant
        /// exhausted, bulk merged, tank dry, cavitation onset and end, phase ends) with time,
        /// phase and ullage pressure. CPU backend.
        #[arg(long)]
        events: bool,
        /// After the run, write its HTML report to DIR/report (as `cryoslosh report DIR`).
        #[arg(long)]
        report: bool,
    },
    /// Write a commented template campaign to start from (refuses to overwrite without --force).
    Init {
        /// Where to write it.
        #[arg(default_value = "campaign.toml")]
        path: PathBuf,
        /// Overwrite an existing file.
        #[arg(long)]
        force: bool,
    },
    /// List the GPU adapters the WGSL backend can use (name, backend, type, limits).
    Devices,
    /// Write an HTML report with SVG plots of a results directory (a run or a merge).
    Report {
        /// Results directory (instances.parquet, statistics.parquet, run.json).
        dir: PathBuf,
        /// Report directory (default: DIR/report); a previous report there is replaced.
        #[arg(long)]
        out: Option<PathBuf>,
        /// Skip re-simulating the worst instance of each headline QoI.
        #[arg(long)]
        no_worst_cases: bool,
    },
    /// Join shard directories of one campaign into DIR, equal to the unsharded run.
    Merge {
        /// Shard output directories.
        #[arg(required = true)]
        dirs: Vec<PathBuf>,
        /// Output directory.
        #[arg(long)]
        out: PathBuf,
        /// Write into a non-empty --out directory (its result files are replaced).
        #[arg(long)]
        force: bool,
    },
}

fn main() -> ExitCode {
    let missing = cryoslosh::lanes::isa::missing_features();
    if !missing.is_empty() {
        cryoslosh::eprintln_lossy!(
            "error: this cryoslosh was built for CPU extensions this CPU lacks ({}); rebuild \
             it with {}",
            missing.join(", "),
            cryoslosh::lanes::isa::rebuild_hint(&missing)
        );
        return ExitCode::from(1);
    }
    quiet_process_defaults();
    let cli = Cli::parse();
    match run(cli) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            cryoslosh::eprintln_lossy!("error: {}", cryoslosh::error_text(e.as_ref()));
            let bad_input = e.downcast_ref::<CampaignError>().is_some()
                || e.downcast_ref::<BadInput>().is_some()
                || e.downcast_ref::<RunError>()
                    .is_some_and(RunError::is_bad_input)
                || e.downcast_ref::<RunnerError>()
                    .is_some_and(RunnerError::is_bad_input)
                || e.downcast_ref::<ReportError>()
                    .is_some_and(ReportError::is_bad_input);
            if bad_input {
                ExitCode::from(2)
            } else if e.downcast_ref::<Untrusted>().is_some() {
                ExitCode::from(3)
            } else {
                ExitCode::from(1)
            }
        }
    }
}

/// Process-wide settings made before any thread starts: a runtime directory for Mesa, whose window-system code prints "XDG_RUNTIME_DIR
/// is invalid" when probing adapters on a machine without one (compute needs none).
fn quiet_process_defaults() {
    let valid =
        std::env::var_os("XDG_RUNTIME_DIR").is_some_and(|d| std::path::Path::new(&d).is_dir());
    if !valid {
        // Single-threaded here, so setting the environment is sound.
        std::env::set_var("XDG_RUNTIME_DIR", std::env::temp_dir());
    }
}

/// The run finished and wrote its outputs, but too many instances were rejected or diverged for
/// its statistics to be signed (exit code 3).
#[derive(Debug, thiserror::Error)]
#[error("{0}: the statistics exclude them; see run.json and statistics.parquet")]
struct Untrusted(String);

/// Exit 3 when a finished run is not to be trusted.
fn trust(untrusted: Option<String>) -> anyhow::Result<()> {
    match untrusted {
        Some(why) => Err(Untrusted(why).into()),
        None => Ok(()),
    }
}

/// A command-line value outside its allowed range (exit code 2).
#[derive(Debug, thiserror::Error)]
#[error("{0}")]
struct BadInput(String);

fn run(cli: Cli) -> anyhow::Result<()> {
    match cli.command {
        Command::Check { campaign, set } => {
            let checked = runner::check(&campaign, &set)?;
            out!("{}", checked.text);
            if let Some(e) = checked.error {
                return Err(e.into());
            }
            match checked.nominal_diverged {
                // A campaign whose nominal instance cannot be integrated fails the check, with
                // `simulate`'s exit code 1.
                Some(why) => Err(anyhow::anyhow!("the nominal instance diverged: {why}")),
                None => Ok(()),
            }
        }
        Command::Simulate {
            run: Some(dir),
            out,
            instance,
            ..
        } => replay(&dir, instance.unwrap_or(0), &out),
        Command::Simulate {
            campaign,
            out,
            instance,
            set,
            run: None,
        } => {
            let Some(campaign) = campaign else {
                return Err(BadInput("simulate needs a campaign file or --run DIR".into()).into());
            };
            let nominal = Campaign::load(&campaign, &set)?;
            check_history_out(&out, &nominal.input_files())?;
            let (c, label) = match instance {
                None => (nominal, "nominal".to_string()),
                Some(i) => {
                    let values = runner::instance_inputs(&nominal, &set, i)?;
                    outln!(
                        "instance {i} of campaign.instances = {}, seed {} (to replay a run made \
                         with other --instances or --seed: simulate --run DIR --instance {i})",
                        nominal.instances,
                        nominal.seed
                    );
                    for (input, v) in nominal.dispersions.inputs.iter().zip(&values) {
                        outln!("{} = {v}", input.key);
                    }
                    (runner::instance_campaign(&nominal, &values)?, i.to_string())
                }
            };
            let mut h = History::default();
            let start = std::time::Instant::now();
            let mut c = c;
            c.record_events = true;
            let q = simulate::simulate(&c, &c.params, Some(&mut h));
            let wall = start.elapsed().as_secs_f64();
            // The error names the file and its cause (`OutputError`).
            let rows = cryoslosh::history::write_history(&out, &c, &h, &label, q.divergence())?;
            outln!("{}", simulate::describe_summary(&q));
            outln!(
                "{} steps in {:.2} s ({:.0} steps/s); {} rows → {}",
                q.steps,
                wall,
                q.steps as f64 / wall.max(1e-9),
                rows,
                out.display()
            );
            if q.diverged {
                anyhow::bail!(
                    "instance diverged: {}",
                    q.diverged_reason.unwrap_or_default()
                );
            }
            Ok(())
        }
        Command::Run {
            campaign,
            out,
            instances,
            seed,
            backend,
            threads,
            shard,
            chunk_size,
            set,
            force,
            histories,
            until,
            resume,
            events,
            report: with_report,
        } => {
            let args = runner::RunArgs {
                campaign,
                out,
                instances,
                seed,
                backend,
                threads,
                shard,
                chunk_size,
                set,
                force,
                histories,
                until,
                resume,
                events,
                progress: true,
            };
            let prepared = runner::prepare(&args)?;
            if !prepared.campaign.variants.is_empty() {
                let runner::FinishedVariants {
                    options: opts,
                    report,
                    ..
                } = runner::execute_variants(prepared)?;
                out!("{}", montecarlo::variants::summary_text(&report));
                outln!(
                    "wrote {d}/variants/{{{}}}/ and {d}/differences.parquet, run.json",
                    report.names.join(","),
                    d = opts.out_dir.display()
                );
                if with_report {
                    write_report(&opts.out_dir, None, true)?;
                }
                return trust(report.untrusted());
            }
            let runner::Finished {
                campaign: c,
                options: opts,
                report,
            } = runner::execute(prepared)?;
            out!("{}", montecarlo::summary_text(&report));
            outln!(
                "wrote {}/{{instances,statistics{}}}.parquet and run.json{}",
                opts.out_dir.display(),
                if c.record_events { ",events" } else { "" },
                if opts.out_dir.join("histories").is_dir() {
                    format!(", time histories in {}/histories", opts.out_dir.display())
                } else {
                    String::new()
                }
            );
            if with_report {
                write_report(&opts.out_dir, None, true)?;
            }
            trust(report.untrusted())
        }
        Command::Init { path, force } => {
            if path.is_dir() {
                return Err(BadInput(format!(
                    "{}: is a directory; name the campaign file to write",
                    path.display()
                ))
                .into());
            }
            match cryoslosh::campaign::template::write_template(&path, force) {
                Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => Err(BadInput(format!(
                    "{}: the file exists; pass --force to overwrite it",
                    path.display()
                ))
                .into()),
                Err(e) => Err(anyhow::Error::new(e).context(format!("writing {}", path.display()))),
                Ok(()) => {
                    let p = path.display();
                    let stem = path
                        .file_stem()
                        .map_or_else(|| "campaign".into(), |s| s.to_string_lossy().into_owned());
                    outln!("wrote the template campaign {p} (a small LN2 tank: pad hold, burn with a gust, three dispersions)");
                    outln!("next: edit it, then");
                    outln!("  cryoslosh check {p}");
                    outln!("  cryoslosh run {p} --out {stem}-run --instances 100");
                    Ok(())
                }
            }
        }
        Command::Devices => {
            out!("{}", context::describe_adapters(&context::adapters()));
            Ok(())
        }
        Command::Report {
            dir,
            out,
            no_worst_cases,
        } => write_report(&dir, out, !no_worst_cases),
        Command::Merge { dirs, out, force } => {
            if dirs
                .first()
                .is_some_and(|d| montecarlo::variants::is_variants_dir(d))
            {
                let report = montecarlo::variants::merge_variants(&dirs, &out, force)?;
                out!("{}", montecarlo::variants::summary_text(&report));
                outln!("merged {} shards into {}", dirs.len(), out.display());
                return trust(report.untrusted());
            }
            let report = montecarlo::merge(&dirs, &out, force)?;
            out!("{}", montecarlo::summary_text(&report));
            outln!("merged {} shards into {}", dirs.len(), out.display());
            trust(report.untrusted())
        }
    }
}

/// `report DIR` and `run --report`: write the report and say where it went.
fn write_report(
    dir: &std::path::Path,
    out: Option<PathBuf>,
    worst_cases: bool,
) -> anyhow::Result<()> {
    let start = std::time::Instant::now();
    let opts = ReportOptions {
        out,
        worst_cases,
        progress: true,
    };
    let r = report::report(dir, &opts)?;
    outln!(
        "wrote {}/index.html: {} plots, {} worst cases re-simulated, in {:.2} s",
        r.out.display(),
        r.plots,
        r.replays,
        start.elapsed().as_secs_f64()
    );
    Ok(())
}

/// A history `--out` may not be one of the command's inputs (the campaign, an excitation table),
/// nor anything but a regular file (a FIFO, device or symlink there would be replaced).
fn check_history_out(out: &std::path::Path, inputs: &[PathBuf]) -> anyhow::Result<()> {
    // Never into a published results directory (its manifest would no longer hold).
    if let Some(parent) = out.parent() {
        let parent = if parent.as_os_str().is_empty() {
            std::path::Path::new(".")
        } else {
            parent
        };
        if parent
            .join(cryoslosh::output::results_dir::MANIFEST)
            .is_file()
        {
            return Err(BadInput(format!(
                "--out {}: inside a results directory ({}); write the history elsewhere",
                out.display(),
                parent.display()
            ))
            .into());
        }
    }
    if let Ok(m) = std::fs::symlink_metadata(out) {
        if !m.is_file() {
            return Err(BadInput(format!(
                "--out {}: exists and is not a regular file (a directory, link, FIFO or device)",
                out.display()
            ))
            .into());
        }
        let same = |p: &PathBuf| std::fs::canonicalize(p).ok() == std::fs::canonicalize(out).ok();
        if let Some(input) = inputs.iter().find(|p| same(p)) {
            return Err(BadInput(format!(
                "--out {}: it is an input of this command ({}); write the history elsewhere",
                out.display(),
                input.display()
            ))
            .into());
        }
    }
    Ok(())
}

/// `simulate --run DIR --instance I`: replay the instance, write its history, compare its row.
fn replay(dir: &std::path::Path, i: u64, out: &std::path::Path) -> anyhow::Result<()> {
    let files = ["instances.parquet", "statistics.parquet", "run.json"].map(|f| dir.join(f));
    check_history_out(out, &files)?;
    let mut h = History::default();
    let (run, record) = montecarlo::replay::replay(dir, i, Some(&mut h))?;
    let c = &run.campaign;
    // Compared first: an instance the file does not hold (another shard's) writes nothing.
    let diffs = montecarlo::replay::compare_row(dir, c, &record)?;
    for (input, v) in c.dispersions.inputs.iter().zip(&record.inputs) {
        outln!("{} = {v}", input.key);
    }
    if record.rejected {
        outln!(
            "instance {i} is rejected: {}",
            record.summary.diverged_reason.as_deref().unwrap_or("")
        );
    } else {
        let q = &record.summary;
        let rows = cryoslosh::history::write_history(out, c, &h, &i.to_string(), q.divergence())?;
        outln!("{}", simulate::describe_summary(q));
        outln!("{} steps; {rows} rows → {}", q.steps, out.display());
    }
    let row = format!("row {i} of {}", dir.join("instances.parquet").display());
    if diffs.is_empty() {
        outln!("replay equals {row} bit for bit");
        return Ok(());
    }
    let list: Vec<String> = diffs
        .iter()
        .map(|(n, file, got)| format!("{n}: file {file}, replay {got}"))
        .collect();
    if run.backend == "cpu" {
        anyhow::bail!("replay differs from {row}: {}", list.join("; "));
    }
    outln!(
        "the run integrated on {} (f32); the CPU replay differs from {row} in: {}",
        run.backend,
        list.join("; ")
    );
    Ok(())
}
