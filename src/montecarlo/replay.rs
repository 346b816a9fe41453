//! Exact replay: instance I of a finished run, rebuilt from the run's own metadata (campaign text
//! with its overrides, seed, instance count, design) and integrated again on the CPU, with its
//! row of `instances.parquet` to compare against.

use super::plan::{InstanceRecord, Plan};
use super::table::{self, COUNTS, FLAGS};
use super::RunError;
use crate::campaign::Campaign;
use crate::simulate::{simulate, History};
use std::path::Path;

/// A run's campaign as its metadata recorded it.
#[derive(Clone, Debug)]
pub struct RunCampaign {
    pub campaign: Campaign,
    pub seed: u64,
    /// Instances in the whole campaign (all shards).
    pub total: u64,
    /// The backend that integrated the run (`cpu`, or a GPU's description).
    pub backend: String,
}

/// Read the campaign of the run in `dir` from its `instances.parquet` metadata.
pub fn run_campaign(dir: &Path) -> Result<RunCampaign, RunError> {
    let path = dir.join("instances.parquet");
    if !path.is_file() {
        // A run with [[variants]] keeps each variant's run in its own directory: say which.
        if super::variants::is_variants_dir(dir) {
            let names: Vec<String> = std::fs::read_dir(dir.join("variants"))
                .map(|entries| {
                    let mut n: Vec<String> = entries
                        .filter_map(Result::ok)
                        .filter(|e| e.path().join("instances.parquet").is_file())
                        .map(|e| e.file_name().to_string_lossy().into_owned())
                        .collect();
                    n.sort();
                    n
                })
                .unwrap_or_default();
            return Err(RunError::Input(format!(
                "--run {}: a run with variants; replay one variant's run: --run {} (variants: {})",
                dir.display(),
                super::variants::variant_dir(dir, "<name>").display(),
                names.join(", ")
            )));
        }
        return Err(RunError::Input(format!(
            "--run {}: not a results directory (no instances.parquet)",
            dir.display()
        )));
    }
    let meta = table::read_metadata(&path)?;
    let get = |key: &str| {
        meta.iter()
            .find(|(k, _)| k == key)
            .map(|(_, v)| v.as_str())
            .ok_or_else(|| {
                RunError::Input(format!(
                    "{}: no {key} in the file metadata: not a cryoslosh run",
                    path.display()
                ))
            })
    };
    let number = |key: &str| -> Result<u64, RunError> {
        get(key)?
            .parse()
            .map_err(|_| RunError::Input(format!("{}: {key} is not an integer", path.display())))
    };
    let campaign_path = get("cryoslosh.campaign_path")?;
    let campaign = Campaign::from_text(Path::new(campaign_path), get("cryoslosh.campaign")?, &[])?;
    Ok(RunCampaign {
        campaign,
        seed: number("cryoslosh.seed")?,
        total: number("cryoslosh.instances")?,
        backend: get("cryoslosh.backend")?.to_string(),
    })
}

/// Instance `i` of the run in `dir`, integrated again on the CPU with its time history.
pub fn replay(
    dir: &Path,
    i: u64,
    history: Option<&mut History>,
) -> Result<(RunCampaign, InstanceRecord), RunError> {
    let mut run = run_campaign(dir)?;
    // A replay is for inspection: it locates the instance's events (no QoI depends on it).
    run.campaign.record_events = true;
    if i >= run.total {
        return Err(RunError::Input(format!(
            "--instance {i}: the run in {} has {} instances",
            dir.display(),
            run.total
        )));
    }
    let plan = Plan {
        campaign: &run.campaign,
        seed: run.seed,
        total: run.total,
    };
    let (inputs, resolved) = plan.resolve(i);
    let record = match resolved {
        Ok(ci) => {
            let ci = ci.as_ref().unwrap_or(&run.campaign);
            InstanceRecord {
                instance: i,
                inputs,
                summary: simulate(ci, &ci.params, history),
                rejected: false,
                rejected_by: None,
            }
        }
        Err(e) => plan.record(i, inputs, Err(e)),
    };
    Ok((run, record))
}

/// Compare `record` with its row in `dir/instances.parquet`, value by value (bit patterns; a null
/// equals NaN). Returns the columns that differ as (name, file value, replayed value); `Err` when
/// the file has no row for the instance (another shard's).
pub fn compare_row(
    dir: &Path,
    c: &Campaign,
    record: &InstanceRecord,
) -> Result<Vec<(String, f64, f64)>, RunError> {
    let d = &c.dispersions;
    let phases = table::phase_names(c);
    let qoi_names = table::qoi_names(&phases);
    let path = dir.join("instances.parquet");
    let ids = table::read_u64(&path, "instance")?;
    let row = ids
        .iter()
        .position(|&x| x == record.instance)
        .ok_or_else(|| {
            RunError::Input(format!(
                "{} has no row for instance {} (a shard holds only its own slice)",
                path.display(),
                record.instance
            ))
        })?;
    let (qois, counts, flags) = table::row_values(record, table::RowShape::of(c));
    let replayed = d
        .inputs
        .iter()
        .map(|i| i.column.as_str())
        .zip(record.inputs.iter().copied())
        .chain(qoi_names.iter().map(String::as_str).zip(qois))
        .chain(COUNTS.iter().map(|(n, _)| *n).zip(counts.map(|c| c as f64)))
        .chain(
            FLAGS
                .iter()
                .copied()
                .zip(flags.map(|f| f.map_or(f64::NAN, |b| f64::from(u8::from(b))))),
        );
    let mut diffs = Vec::new();
    for (name, value) in replayed {
        let file = table::read_f64(&path, name)?[row];
        let same = file.to_bits() == value.to_bits() || (file.is_nan() && value.is_nan());
        if !same {
            diffs.push((name.to_string(), file, value));
        }
    }
    Ok(diffs)
}
