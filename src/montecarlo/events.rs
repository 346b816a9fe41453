//! `events.parquet` (`run --events`): one row per located event of every instance
//! (`simulate::events`), in instance then time order, written in fixed-size row groups so that
//! the file's bytes do not depend on threads, chunking or shards (like `instances.parquet`).
//!
//! Columns: `instance` (u64), `time_s` (mission time, s), `phase` (the phase's name), `kind`
//! (`relief_open`, `relief_close`, `pressurant_exhausted`, `bulk_merged`, `depleted`,
//! `cavitation_onset`, `cavitation_end`, `phase_end`, `truncated`), `pressure_pa` (ullage
//! pressure at the event) and `value` (kg: the liquid left for `depleted` and `bulk_merged`,
//! the pressurant used for `pressurant_exhausted`; null otherwise).

use super::plan::InstanceRecord;
use super::table::ROW_GROUP_ROWS;
use super::RunError;
use crate::output::{ColumnData, ColumnKind, ColumnSpec, OutputError, TableWriter};
use arrow_array::{Array, Float64Array, StringArray, UInt64Array};
use parquet::arrow::arrow_reader::ParquetRecordBatchReaderBuilder;
use std::path::Path;

/// The schema of `events.parquet`.
pub fn schema() -> Vec<ColumnSpec> {
    vec![
        ColumnSpec::new("instance", ColumnKind::U64),
        ColumnSpec::new("time_s", ColumnKind::F64),
        ColumnSpec::new("phase", ColumnKind::Utf8),
        ColumnSpec::new("kind", ColumnKind::Utf8),
        ColumnSpec::new("pressure_pa", ColumnKind::F64),
        ColumnSpec::optional("value", ColumnKind::F64),
    ]
}

/// Buffered rows of events.
#[derive(Default)]
struct Rows {
    instance: Vec<u64>,
    time_s: Vec<f64>,
    phase: Vec<String>,
    kind: Vec<String>,
    pressure_pa: Vec<f64>,
    value: Vec<f64>,
}

impl Rows {
    fn len(&self) -> usize {
        self.instance.len()
    }

    fn drain(&mut self, n: usize) {
        drop(self.instance.drain(..n));
        drop(self.time_s.drain(..n));
        drop(self.phase.drain(..n));
        drop(self.kind.drain(..n));
        drop(self.pressure_pa.drain(..n));
        drop(self.value.drain(..n));
    }
}

/// Writes `events.parquet` in row groups of exactly [`ROW_GROUP_ROWS`] rows (the last may be
/// short).
pub struct EventWriter {
    writer: TableWriter,
    phases: Vec<String>,
    rows: Rows,
}

impl EventWriter {
    /// Create the temporary file for `path` for a campaign whose phases are named `phases`,
    /// with `metadata` as file-level key-value metadata.
    pub fn create(
        path: &Path,
        phases: &[String],
        metadata: Vec<(String, String)>,
    ) -> Result<Self, OutputError> {
        Ok(EventWriter {
            writer: TableWriter::create(path, schema(), metadata)?,
            phases: phases.to_vec(),
            rows: Rows::default(),
        })
    }

    /// Append the events of one instance.
    pub fn push(&mut self, r: &InstanceRecord) -> Result<(), OutputError> {
        for e in &r.summary.events {
            let rows = &mut self.rows;
            rows.instance.push(r.instance);
            rows.time_s.push(e.time_s);
            let phase = self.phases.get(e.phase).map_or("?", String::as_str);
            rows.phase.push(phase.to_string());
            rows.kind.push(e.kind.name().to_string());
            rows.pressure_pa.push(e.pressure_pa);
            rows.value.push(e.value);
            if rows.len() >= ROW_GROUP_ROWS {
                self.flush()?;
            }
        }
        Ok(())
    }

    /// Append every row of the events file `src` (same schema), one batch at a time.
    pub fn copy_rows(&mut self, src: &Path) -> Result<u64, RunError> {
        let err = |e: &dyn std::fmt::Display| {
            RunError::Input(format!("cannot read {}: {e}", src.display()))
        };
        let file = std::fs::File::open(src).map_err(|e| err(&e))?;
        let reader = ParquetRecordBatchReaderBuilder::try_new(file)
            .map_err(|e| err(&e))?
            .with_batch_size(ROW_GROUP_ROWS)
            .build()
            .map_err(|e| err(&e))?;
        let mut total = 0u64;
        for batch in reader {
            let batch = batch.map_err(|e| err(&e))?;
            let col = |i: usize| batch.column(i).as_any();
            let (Some(inst), Some(time), Some(phase), Some(kind), Some(press), Some(value)) = (
                col(0).downcast_ref::<UInt64Array>(),
                col(1).downcast_ref::<Float64Array>(),
                col(2).downcast_ref::<StringArray>(),
                col(3).downcast_ref::<StringArray>(),
                col(4).downcast_ref::<Float64Array>(),
                col(5).downcast_ref::<Float64Array>(),
            ) else {
                return Err(err(&"not an events file (columns differ)"));
            };
            for k in 0..batch.num_rows() {
                let rows = &mut self.rows;
                rows.instance.push(inst.value(k));
                rows.time_s.push(time.value(k));
                rows.phase.push(phase.value(k).to_string());
                rows.kind.push(kind.value(k).to_string());
                rows.pressure_pa.push(press.value(k));
                rows.value.push(if value.is_null(k) {
                    f64::NAN
                } else {
                    value.value(k)
                });
                if rows.len() >= ROW_GROUP_ROWS {
                    self.flush()?;
                }
            }
            total += batch.num_rows() as u64;
        }
        Ok(total)
    }

    /// Write up to one row group from the buffers.
    fn flush(&mut self) -> Result<(), OutputError> {
        let n = self.rows.len().min(ROW_GROUP_ROWS);
        if n == 0 {
            return Ok(());
        }
        let r = &self.rows;
        self.writer.write_chunk(&[
            ColumnData::U64(&r.instance[..n]),
            ColumnData::F64(&r.time_s[..n]),
            ColumnData::Utf8(&r.phase[..n]),
            ColumnData::Utf8(&r.kind[..n]),
            ColumnData::F64(&r.pressure_pa[..n]),
            ColumnData::F64(&r.value[..n]),
        ])?;
        self.rows.drain(n);
        Ok(())
    }

    /// Write what is buffered and rename the file into place. Returns the rows written.
    pub fn finish(mut self) -> Result<u64, OutputError> {
        while self.rows.len() > 0 {
            self.flush()?;
        }
        self.writer.finish()
    }
}
