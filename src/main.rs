//! The `cryoslosh` command line: parses arguments, calls the library, maps errors to exit codes
//! (0 success, 2 bad input, 1 anything else).

use anyhow::Context;
use clap::{Parser, Subcommand};
use cryoslosh::campaign::{Campaign, CampaignError};
use cryoslosh::simulate::{self, History};
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(Parser)]
#[command(
    name = "cryoslosh",
    version,
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
        /// Campaign TOML file.
        campaign: PathBuf,
        /// Output Parquet file.
        #[arg(long)]
        out: PathBuf,
        /// Override a scalar by its dotted key path (repeatable).
        #[arg(long = "set", value_name = "KEY=VALUE")]
        set: Vec<String>,
    },
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    match run(cli) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e:#}");
            if e.downcast_ref::<CampaignError>().is_some() {
                ExitCode::from(2)
            } else {
                ExitCode::from(1)
            }
        }
    }
}

fn run(cli: Cli) -> anyhow::Result<()> {
    match cli.command {
        Command::Check { campaign, set } => {
            let c = Campaign::load(&campaign, &set)?;
            print!("{}", cryoslosh::campaign::describe(&c));
            Ok(())
        }
        Command::Simulate { campaign, out, set } => {
            let c = Campaign::load(&campaign, &set)?;
            let mut h = History::default();
            let start = std::time::Instant::now();
            let q = simulate::simulate(&c, &c.params, Some(&mut h));
            let wall = start.elapsed().as_secs_f64();
            let rows = cryoslosh::history::write_history(&out, &c, &h, "nominal")
                .with_context(|| format!("writing {}", out.display()))?;
            println!("{}", simulate::describe_summary(&q));
            println!(
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
    }
}
