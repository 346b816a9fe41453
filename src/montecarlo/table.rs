//! `instances.parquet`: one row per instance, written in fixed-size row groups so that the file's
//! bytes do not depend on how the engine blocked the work (threads, block size, shard merge).

use super::plan::InstanceRecord;
use crate::campaign::Campaign;
use crate::model::params::Fidelity;
use crate::output::{ColumnData, ColumnKind, ColumnSpec, OutputError, TableWriter};
use crate::simulate::{PhaseSummary, Summary};
use arrow_array::{Array, BooleanArray, Float64Array, UInt64Array};
use parquet::arrow::arrow_reader::ParquetRecordBatchReaderBuilder;
use parquet::arrow::ProjectionMask;
use std::path::Path;

/// Rows per row group of instances.parquet.
pub const ROW_GROUP_ROWS: usize = 65_536;

/// A QoI column: its name and how to read it from a [`Summary`].
pub type Qoi = (&'static str, fn(&Summary) -> f64);

/// f64 quantities of interest per instance, with how to read them from a [`Summary`]. Missing
/// values (no engine draw: no cavitation margin; every QoI of a rejected or diverged instance but
/// `final_time_s`) are NaN here and Arrow nulls in the file.
pub const QOI_F64: [Qoi; 22] = [
    ("peak_pressure_pa", |q| q.peak_pressure_pa),
    ("peak_pressure_time_s", |q| q.peak_pressure_time_s),
    ("min_pressure_pa", |q| q.min_pressure_pa),
    ("final_pressure_pa", |q| q.final_pressure_pa),
    ("boiloff_kg", |q| q.boiloff_kg),
    ("vented_kg", |q| q.vented_kg),
    ("vented_vapor_kg", |q| q.vented_vapor_kg),
    ("vented_helium_kg", |q| q.vented_helium_kg),
    ("tvs_vented_kg", |q| q.tvs_vented_kg),
    ("pressurant_used_kg", |q| q.pressurant_used_kg),
    ("propellant_drawn_kg", |q| q.propellant_drawn_kg),
    ("min_cavitation_margin_m", |q| {
        q.min_cavitation_margin_m.unwrap_or(f64::NAN)
    }),
    ("min_cavitation_margin_pa", |q| {
        q.min_cavitation_margin_pa.unwrap_or(f64::NAN)
    }),
    ("min_cavitation_margin_time_s", |q| {
        q.min_cavitation_margin_time_s.unwrap_or(f64::NAN)
    }),
    ("max_slosh_angle_rad", |q| q.max_slosh_angle_rad),
    ("peak_slosh_force_n", |q| q.peak_slosh_force_n),
    ("peak_slosh_moment_n_m", |q| q.peak_slosh_moment_n_m),
    ("final_stratification_k", |q| q.final_stratification_k),
    ("final_time_s", |q| q.final_time_s),
    ("pressurant_exhausted_time_s", |q| {
        q.pressurant_exhausted_time_s.unwrap_or(f64::NAN)
    }),
    ("depleted_time_s", |q| q.depleted_time_s.unwrap_or(f64::NAN)),
    ("slosh_out_of_range_fraction", |q| {
        q.slosh_out_of_range_fraction
    }),
];

/// A per-phase QoI: its name (the column is `<name>.<phase>`) and how to read it from a
/// [`PhaseSummary`].
pub type PhaseQoi = (&'static str, fn(&PhaseSummary) -> f64);

/// f64 quantities of interest per phase, as columns `<qoi>.<phase>` after [`QOI_F64`], phase by
/// phase in the campaign's order. A phase the instance never entered (it ran dry or diverged
/// before) has nulls; `min_cavitation_margin_m` is null in a phase where the engine never drew.
pub const PHASE_QOIS: [PhaseQoi; 8] = [
    ("peak_pressure_pa", |q| q.peak_pressure_pa),
    ("min_pressure_pa", |q| q.min_pressure_pa),
    ("pressure_rise_pa", PhaseSummary::pressure_rise_pa),
    ("boiloff_kg", |q| q.boiloff_kg),
    ("vented_kg", |q| q.vented_kg),
    ("tvs_vented_kg", |q| q.tvs_vented_kg),
    ("min_cavitation_margin_m", |q| {
        q.min_cavitation_margin_m.unwrap_or(f64::NAN)
    }),
    ("max_slosh_angle_rad", |q| q.max_slosh_angle_rad),
];

/// The phase names of a campaign, in order (the suffixes of its per-phase QoI columns).
pub fn phase_names(c: &Campaign) -> Vec<String> {
    c.phases.iter().map(|ph| ph.name.clone()).collect()
}

/// Every f64 QoI column of instances.parquet for phases named `phases`: [`QOI_F64`], then
/// [`PHASE_QOIS`] as `<qoi>.<phase>` for each phase in order.
pub fn qoi_names(phases: &[String]) -> Vec<String> {
    let whole = QOI_F64.iter().map(|(n, _)| (*n).to_string());
    let per_phase = phases
        .iter()
        .flat_map(|ph| PHASE_QOIS.iter().map(move |(n, _)| format!("{n}.{ph}")));
    whole.chain(per_phase).collect()
}

/// A count column: its name and how to read it from a [`Summary`].
pub type Count = (&'static str, fn(&Summary) -> u64);

/// Counts per instance after `instance`: accepted steps, the right-hand-side evaluations they
/// cost (stages, the end-of-step evaluation, probes and event location: what the instance alone
/// costs, whatever lane group it ran in), relief-valve openings and
/// thermodynamic-vent-system starts.
pub const COUNTS: [Count; 4] = [
    ("steps", |q| q.steps),
    ("rhs_evaluations", |q| q.rhs_evaluations),
    ("relief_cycles", |q| q.relief_cycles),
    ("tvs_cycles", |q| q.tvs_cycles),
];

/// The [`COUNTS`] that `statistics.parquet` describes like a QoI (distribution, and the
/// campaign's thresholds: P(relief_cycles > N) is a valve-life question). Null for a rejected or
/// diverged instance like every QoI; 0 where the campaign has no relief valve or TVS.
pub const COUNT_QOIS: [&str; 2] = ["relief_cycles", "tvs_cycles"];

/// Every quantity `statistics.parquet` describes: [`qoi_names`], then [`COUNT_QOIS`].
pub fn statistic_names(phases: &[String]) -> Vec<String> {
    let mut names = qoi_names(phases);
    names.extend(COUNT_QOIS.iter().map(|n| (*n).to_string()));
    names
}

/// Boolean flags per instance: outcomes (cavitation, overpressure, the pressurant running out,
/// the tank running dry) and validity (diverged, rejected).
pub const FLAGS: [&str; 7] = [
    "cavitation",
    "overpressure",
    "pressurant_exhausted",
    "depleted",
    "slosh_out_of_range",
    "diverged",
    "rejected",
];

/// What the rows of a campaign hold after its inputs: its phase count (the per-phase columns)
/// and its fidelity (the QoIs it does not model are nulls, see [`unmodelled`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RowShape {
    pub n_phases: usize,
    pub fidelity: Fidelity,
}

impl RowShape {
    /// The shape of `c`'s rows.
    pub fn of(c: &Campaign) -> RowShape {
        RowShape {
            n_phases: c.phases.len(),
            fidelity: c.params.fidelity,
        }
    }
}

/// Columns that `fidelity` does not model, null in every row (whole-mission QoIs, their
/// per-phase columns and the outcome flag of the same name): the `homogeneous` level has no
/// slosh analog and no stratified layer, and a zero there would read as "no slosh" or "no
/// stratification" in statistics and in differences against a variant that models them.
pub fn unmodelled(fidelity: Fidelity) -> &'static [&'static str] {
    match fidelity {
        Fidelity::Homogeneous => &[
            "max_slosh_angle_rad",
            "peak_slosh_force_n",
            "peak_slosh_moment_n_m",
            "final_stratification_k",
            "slosh_out_of_range_fraction",
            "slosh_out_of_range",
        ],
        Fidelity::Lumped | Fidelity::TwoMode | Fidelity::Layered => &[],
    }
}

/// What a row of instances.parquet holds for `r` after its inputs, in a campaign of `shape`:
/// the QoI values of [`qoi_names`] (NaN = null), the [`COUNTS`] and the [`FLAGS`]. A rejected
/// or diverged instance has no QoIs, except the time it reached, and its outcome flags are
/// null; what the fidelity does not model ([`unmodelled`]) is null in every row.
pub fn row_values(
    r: &InstanceRecord,
    shape: RowShape,
) -> (Vec<f64>, [u64; COUNTS.len()], [Option<bool>; 7]) {
    let q = &r.summary;
    let invalid = r.rejected || q.diverged;
    let missing = unmodelled(shape.fidelity);
    let mut qois: Vec<f64> = QOI_F64
        .iter()
        .map(|&(name, get)| {
            if (invalid && name != "final_time_s") || missing.contains(&name) {
                f64::NAN
            } else {
                get(q)
            }
        })
        .collect();
    for i in 0..shape.n_phases {
        let phase = q.phases.get(i).filter(|_| !invalid);
        qois.extend(PHASE_QOIS.iter().map(|(name, get)| {
            if missing.contains(name) {
                f64::NAN
            } else {
                phase.map_or(f64::NAN, get)
            }
        }));
    }
    let counts = COUNTS.map(|(_, get)| get(q));
    let outcome = |v: bool| (!invalid).then_some(v);
    let flags = [
        outcome(q.cavitation),
        outcome(q.overpressure),
        outcome(q.pressurant_exhausted),
        outcome(q.depleted),
        outcome(q.slosh_out_of_range).filter(|_| !missing.contains(&"slosh_out_of_range")),
        Some(q.diverged),
        Some(r.rejected),
    ];
    (qois, counts, flags)
}

/// Column buffer of one kind.
#[derive(Clone, Debug)]
enum Buf {
    F64(Vec<f64>),
    U64(Vec<u64>),
    /// A flag; `None` is null (an outcome flag of a rejected or diverged instance).
    Bool(Vec<Option<bool>>),
}

/// The schema: `instance`, the dispersed inputs, the f64 QoIs of [`qoi_names`] for phases named
/// `phases`, the counts, the flags.
pub fn schema(input_columns: &[String], phases: &[String]) -> Vec<ColumnSpec> {
    let mut specs = vec![ColumnSpec::new("instance", ColumnKind::U64)];
    specs.extend(
        input_columns
            .iter()
            .map(|c| ColumnSpec::new(c.clone(), ColumnKind::F64)),
    );
    specs.extend(
        qoi_names(phases)
            .into_iter()
            .map(|n| ColumnSpec::new(n, ColumnKind::F64)),
    );
    specs.extend(
        COUNTS
            .iter()
            .map(|(n, _)| ColumnSpec::new(*n, ColumnKind::U64)),
    );
    // Outcome flags are null where the instance has no outcome (rejected or diverged); the
    // validity flags themselves always have a value.
    specs.extend(FLAGS.iter().map(|n| {
        if matches!(*n, "diverged" | "rejected") {
            ColumnSpec::new(*n, ColumnKind::Bool)
        } else {
            ColumnSpec::optional(*n, ColumnKind::Bool)
        }
    }));
    specs
}

/// Buffers rows and writes them in row groups of exactly [`ROW_GROUP_ROWS`] (the last may be short).
pub struct InstanceWriter {
    writer: TableWriter,
    bufs: Vec<Buf>,
    shape: RowShape,
}

impl InstanceWriter {
    /// Create the temporary file for `path` with one column per dispersed input of `c`, the
    /// QoI columns of its phases, and `metadata` as file-level key-value metadata.
    pub fn create(
        path: &Path,
        c: &Campaign,
        metadata: Vec<(String, String)>,
    ) -> Result<Self, OutputError> {
        let d = &c.dispersions;
        let input_columns: Vec<String> = d.inputs.iter().map(|i| i.column.clone()).collect();
        let specs = schema(&input_columns, &phase_names(c));
        let bufs = specs
            .iter()
            .map(|s| match s.kind {
                ColumnKind::U64 => Buf::U64(Vec::new()),
                ColumnKind::Bool => Buf::Bool(Vec::new()),
                _ => Buf::F64(Vec::new()),
            })
            .collect();
        Ok(InstanceWriter {
            writer: TableWriter::create(path, specs, metadata)?,
            bufs,
            shape: RowShape::of(c),
        })
    }

    fn rows(&self) -> usize {
        match &self.bufs[0] {
            Buf::U64(v) => v.len(),
            _ => 0,
        }
    }

    /// Append one instance.
    pub fn push(&mut self, r: &InstanceRecord) -> Result<(), OutputError> {
        let (qois, counts, flags) = row_values(r, self.shape);
        let mut f64s = r.inputs.iter().copied().chain(qois);
        let mut flag = flags.iter();
        let mut u64s = std::iter::once(r.instance).chain(counts);
        for b in &mut self.bufs {
            match b {
                Buf::U64(v) => v.push(u64s.next().unwrap_or(0)),
                Buf::F64(v) => v.push(f64s.next().unwrap_or(f64::NAN)),
                Buf::Bool(v) => v.push(flag.next().copied().flatten()),
            }
        }
        if self.rows() >= ROW_GROUP_ROWS {
            self.flush()?;
        }
        Ok(())
    }

    /// Append rows read back from another instances file (shard merge), same schema.
    fn push_columns(&mut self, cols: &[Buf], rows: usize) -> Result<(), OutputError> {
        for start in (0..rows).step_by(ROW_GROUP_ROWS) {
            let end = (start + ROW_GROUP_ROWS).min(rows);
            for (dst, src) in self.bufs.iter_mut().zip(cols) {
                match (dst, src) {
                    (Buf::F64(d), Buf::F64(s)) => d.extend_from_slice(&s[start..end]),
                    (Buf::U64(d), Buf::U64(s)) => d.extend_from_slice(&s[start..end]),
                    (Buf::Bool(d), Buf::Bool(s)) => d.extend_from_slice(&s[start..end]),
                    _ => {}
                }
            }
            while self.rows() >= ROW_GROUP_ROWS {
                self.flush()?;
            }
        }
        Ok(())
    }

    /// Write up to one row group from the buffers.
    fn flush(&mut self) -> Result<(), OutputError> {
        let n = self.rows().min(ROW_GROUP_ROWS);
        if n == 0 {
            return Ok(());
        }
        {
            let data: Vec<ColumnData> = self
                .bufs
                .iter()
                .map(|b| match b {
                    Buf::F64(v) => ColumnData::F64(&v[..n]),
                    Buf::U64(v) => ColumnData::U64(&v[..n]),
                    Buf::Bool(v) => ColumnData::OptBool(&v[..n]),
                })
                .collect();
            self.writer.write_chunk(&data)?;
        }
        for b in &mut self.bufs {
            match b {
                Buf::F64(v) => drop(v.drain(..n)),
                Buf::U64(v) => drop(v.drain(..n)),
                Buf::Bool(v) => drop(v.drain(..n)),
            }
        }
        Ok(())
    }

    /// Add a file-level metadata entry known only at the end.
    pub fn append_metadata(&mut self, key: &str, value: &str) {
        self.writer.append_metadata(key, value);
    }

    /// Write what is buffered and rename the file into place. Returns the rows written.
    pub fn finish(mut self) -> Result<u64, OutputError> {
        while self.rows() > 0 {
            self.flush()?;
        }
        self.writer.finish()
    }
}

/// Failure to read an instances file back.
#[derive(Debug, thiserror::Error)]
pub enum ReadError {
    #[error("cannot read {path}: {message}")]
    Parquet { path: String, message: String },
    #[error("{path} has no column {column}")]
    MissingColumn { path: String, column: String },
}

fn parquet_err(path: &Path, e: impl std::fmt::Display) -> ReadError {
    ReadError::Parquet {
        path: path.display().to_string(),
        message: e.to_string(),
    }
}

/// Column names and kinds of a Parquet file, in order (kinds spelled as [`ColumnKind`]'s
/// display: f64, u64, bool, …; another Arrow type by its own name).
pub fn read_schema(path: &Path) -> Result<Vec<(String, String)>, ReadError> {
    use arrow_schema::DataType;
    let file = std::fs::File::open(path).map_err(|e| parquet_err(path, e))?;
    let builder =
        ParquetRecordBatchReaderBuilder::try_new(file).map_err(|e| parquet_err(path, e))?;
    Ok(builder
        .schema()
        .fields()
        .iter()
        .map(|f| {
            let kind = match f.data_type() {
                DataType::Float64 => ColumnKind::F64.to_string(),
                DataType::UInt64 => ColumnKind::U64.to_string(),
                DataType::Int32 => ColumnKind::I32.to_string(),
                DataType::Boolean => ColumnKind::Bool.to_string(),
                DataType::Utf8 => ColumnKind::Utf8.to_string(),
                other => other.to_string(),
            };
            (f.name().clone(), kind)
        })
        .collect())
}

/// File-level key-value metadata of an instances file.
pub fn read_metadata(path: &Path) -> Result<Vec<(String, String)>, ReadError> {
    let file = std::fs::File::open(path).map_err(|e| parquet_err(path, e))?;
    let builder =
        ParquetRecordBatchReaderBuilder::try_new(file).map_err(|e| parquet_err(path, e))?;
    Ok(builder
        .metadata()
        .file_metadata()
        .key_value_metadata()
        .map(|kv| {
            kv.iter()
                .map(|e| (e.key.clone(), e.value.clone().unwrap_or_default()))
                .collect()
        })
        .unwrap_or_default())
}

/// Convert an arrow column to a buffer, appending to `out`.
fn append_array(out: &mut Option<Buf>, col: &dyn Array) {
    let any = col.as_any();
    if let Some(a) = any.downcast_ref::<Float64Array>() {
        if let Buf::F64(v) = out.get_or_insert(Buf::F64(Vec::new())) {
            // A null (no value) reads back as NaN, which every statistic skips.
            v.extend(a.iter().map(|x| x.unwrap_or(f64::NAN)));
        }
    } else if let Some(a) = any.downcast_ref::<UInt64Array>() {
        if let Buf::U64(v) = out.get_or_insert(Buf::U64(Vec::new())) {
            v.extend_from_slice(a.values());
        }
    } else if let Some(a) = any.downcast_ref::<BooleanArray>() {
        if let Buf::Bool(v) = out.get_or_insert(Buf::Bool(Vec::new())) {
            v.extend(a.iter());
        }
    }
}

/// Read one column, converting to the buffer kind of its arrow type.
fn read_column(path: &Path, name: &str) -> Result<Buf, ReadError> {
    let file = std::fs::File::open(path).map_err(|e| parquet_err(path, e))?;
    let builder =
        ParquetRecordBatchReaderBuilder::try_new(file).map_err(|e| parquet_err(path, e))?;
    let idx = builder
        .schema()
        .fields()
        .iter()
        .position(|f| f.name() == name)
        .ok_or_else(|| ReadError::MissingColumn {
            path: path.display().to_string(),
            column: name.to_string(),
        })?;
    let mask = ProjectionMask::roots(builder.parquet_schema(), [idx]);
    let reader = builder
        .with_projection(mask)
        .build()
        .map_err(|e| parquet_err(path, e))?;
    let mut out: Option<Buf> = None;
    for batch in reader {
        let batch = batch.map_err(|e| parquet_err(path, e))?;
        append_array(&mut out, batch.column(0).as_ref());
    }
    Ok(out.unwrap_or(Buf::F64(Vec::new())))
}

/// An f64 column of an instances file.
pub fn read_f64(path: &Path, name: &str) -> Result<Vec<f64>, ReadError> {
    match read_column(path, name)? {
        Buf::F64(v) => Ok(v),
        Buf::U64(v) => Ok(v.into_iter().map(|x| x as f64).collect()),
        Buf::Bool(v) => Ok(v
            .into_iter()
            .map(|x| x.map_or(f64::NAN, |b| f64::from(u8::from(b))))
            .collect()),
    }
}

/// A bool column of an instances file.
pub fn read_bool(path: &Path, name: &str) -> Result<Vec<bool>, ReadError> {
    match read_column(path, name)? {
        Buf::Bool(v) => Ok(v.into_iter().map(|x| x.unwrap_or(false)).collect()),
        Buf::F64(v) => Ok(v.into_iter().map(|x| x != 0.0).collect()),
        Buf::U64(v) => Ok(v.into_iter().map(|x| x != 0).collect()),
    }
}

/// A flag column of an instances file with its nulls (a rejected or diverged instance's
/// outcome, or a flag the campaign's fidelity does not model).
pub fn read_flag(path: &Path, name: &str) -> Result<Vec<Option<bool>>, ReadError> {
    match read_column(path, name)? {
        Buf::Bool(v) => Ok(v),
        Buf::F64(v) => Ok(v.into_iter().map(|x| Some(x != 0.0)).collect()),
        Buf::U64(v) => Ok(v.into_iter().map(|x| Some(x != 0)).collect()),
    }
}

/// A u64 column of an instances file.
pub fn read_u64(path: &Path, name: &str) -> Result<Vec<u64>, ReadError> {
    match read_column(path, name)? {
        Buf::U64(v) => Ok(v),
        Buf::F64(v) => Ok(v.into_iter().map(|x| x as u64).collect()),
        Buf::Bool(v) => Ok(v
            .into_iter()
            .map(|x| u64::from(x.unwrap_or(false)))
            .collect()),
    }
}

/// Append every row of the instances file `src` (same schema as `w`) to `w`, one batch of
/// [`ROW_GROUP_ROWS`] at a time so memory stays bounded.
pub fn copy_rows(w: &mut InstanceWriter, src: &Path) -> Result<u64, super::RunError> {
    let file = std::fs::File::open(src).map_err(|e| parquet_err(src, e))?;
    let reader = ParquetRecordBatchReaderBuilder::try_new(file)
        .map_err(|e| parquet_err(src, e))?
        .with_batch_size(ROW_GROUP_ROWS)
        .build()
        .map_err(|e| parquet_err(src, e))?;
    let mut total = 0u64;
    for batch in reader {
        let batch = batch.map_err(|e| parquet_err(src, e))?;
        let cols: Vec<Buf> = batch
            .columns()
            .iter()
            .map(|c| {
                let mut b = None;
                append_array(&mut b, c.as_ref());
                b.unwrap_or(Buf::F64(Vec::new()))
            })
            .collect();
        w.push_columns(&cols, batch.num_rows())?;
        total += batch.num_rows() as u64;
    }
    Ok(total)
}
