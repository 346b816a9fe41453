//! Results files → pyarrow tables through the Arrow C data interface: the Parquet a run wrote
//! is decoded once, in Rust, and its buffers are handed to pyarrow without another copy.

use arrow_array::RecordBatch;
use arrow_pyarrow::{IntoPyArrow, Table};
use arrow_schema::Schema;
use parquet::arrow::arrow_reader::ParquetRecordBatchReaderBuilder;
use pyo3::exceptions::PyOSError;
use pyo3::prelude::*;
use std::path::Path;
use std::sync::Arc;

/// A decoded Parquet file: its batches, with the file-level key-value metadata (the
/// `cryoslosh.*` provenance) on the schema, as `pyarrow.parquet.read_table` puts it.
pub struct Decoded {
    batches: Vec<RecordBatch>,
    schema: Arc<Schema>,
}

/// Read every row group of `path` (no Python involved: callable without the GIL).
pub fn read(path: &Path) -> Result<Decoded, String> {
    let file = std::fs::File::open(path).map_err(|e| format!("{}: {e}", path.display()))?;
    let builder = ParquetRecordBatchReaderBuilder::try_new(file)
        .map_err(|e| format!("{}: {e}", path.display()))?;
    let mut meta = builder.schema().metadata().clone();
    if let Some(kv) = builder.metadata().file_metadata().key_value_metadata() {
        for entry in kv.iter().filter(|e| e.key != "ARROW:schema") {
            meta.insert(entry.key.clone(), entry.value.clone().unwrap_or_default());
        }
    }
    let schema = Arc::new(builder.schema().as_ref().clone().with_metadata(meta));
    let reader = builder
        .build()
        .map_err(|e| format!("{}: {e}", path.display()))?;
    let batches = reader
        .collect::<Result<Vec<_>, _>>()
        .map_err(|e| format!("{}: {e}", path.display()))?;
    let batches = batches
        .into_iter()
        .map(|b| b.with_schema(Arc::clone(&schema)))
        .collect::<Result<Vec<_>, _>>()
        .map_err(|e| format!("{}: {e}", path.display()))?;
    Ok(Decoded { batches, schema })
}

impl Decoded {
    /// Hand the batches to pyarrow as one `pyarrow.Table`.
    pub fn into_py(self, py: Python<'_>) -> PyResult<Bound<'_, PyAny>> {
        let table = Table::try_new(self.batches, self.schema)
            .map_err(|e| PyOSError::new_err(e.to_string()))?;
        table.into_pyarrow(py)
    }
}
