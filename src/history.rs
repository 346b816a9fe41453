//! Time history of one instance → Parquet (`cryoslosh simulate`), with provenance metadata.

use crate::campaign::Campaign;
use crate::output::{ColumnData, ColumnKind, ColumnSpec, OutputError, TableWriter};
use crate::simulate::{History, HISTORY_COLUMNS};
use std::path::Path;

/// File-level key-value metadata every output carries (DESIGN.md): campaign text, seed, shard,
/// backend, version, fidelity.
pub fn provenance(c: &Campaign, backend: &str, shard: &str) -> Vec<(String, String)> {
    vec![
        ("cryoslosh.campaign".into(), c.text.clone()),
        (
            "cryoslosh.campaign_path".into(),
            c.path.display().to_string(),
        ),
        ("cryoslosh.seed".into(), c.seed.to_string()),
        ("cryoslosh.shard".into(), shard.to_string()),
        ("cryoslosh.backend".into(), backend.to_string()),
        ("cryoslosh.version".into(), crate::VERSION.to_string()),
        // The CPU build (lane width, instruction-set extensions): what the speed depends on.
        (
            "cryoslosh.build".into(),
            crate::lanes::isa::build_description(),
        ),
        (
            "cryoslosh.fidelity".into(),
            c.params.fidelity.name().to_string(),
        ),
        (
            "cryoslosh.integrator".into(),
            crate::montecarlo::integrator_text(c),
        ),
    ]
}

/// Write `h` to `path` atomically: the f64 columns of [`HISTORY_COLUMNS`], then `phase` (utf8)
/// and `valve_open` (bool). `instance` is recorded in the metadata, and `cryoslosh.diverged` is
/// `false` or `true: <reason>`.
pub fn write_history(
    path: &Path,
    c: &Campaign,
    h: &History,
    instance: &str,
    diverged: Option<&str>,
) -> Result<u64, OutputError> {
    let mut specs: Vec<ColumnSpec> = HISTORY_COLUMNS
        .iter()
        .map(|n| ColumnSpec::new(*n, ColumnKind::F64))
        .collect();
    specs.push(ColumnSpec::new("phase", ColumnKind::Utf8));
    specs.push(ColumnSpec::new("valve_open", ColumnKind::Bool));
    let mut meta = provenance(c, "cpu", "0/1");
    meta.push(("cryoslosh.instance".into(), instance.to_string()));
    // A diverged instance's history stops where the model left its validity: say so and why.
    meta.push((
        "cryoslosh.diverged".into(),
        diverged.map_or_else(|| "false".to_string(), |why| format!("true: {why}")),
    ));
    let mut w = TableWriter::create(path, specs, meta)?;
    let mut data: Vec<ColumnData> = h.columns.iter().map(|c| ColumnData::F64(c)).collect();
    data.push(ColumnData::Utf8(&h.phase));
    data.push(ColumnData::Bool(&h.valve_open));
    w.write_chunk(&data)?;
    w.finish()
}
