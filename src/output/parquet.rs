//! Streaming, atomic Parquet writer for flat tables. A missing value is an Arrow null: NaN in an
//! f64 column, an empty string in a column declared [`ColumnSpec::optional`].

use std::collections::HashSet;
use std::fmt;
use std::fs::{self, File};
use std::path::{Path, PathBuf};
use std::sync::Arc;

use ::parquet::arrow::ArrowWriter;
use ::parquet::basic::Compression;
use ::parquet::file::metadata::KeyValue;
use ::parquet::file::properties::WriterProperties;
use arrow_array::{
    ArrayRef, BooleanArray, Float64Array, Int32Array, RecordBatch, StringArray, UInt64Array,
};
use arrow_schema::{DataType, Field, Schema, SchemaRef};

use super::atomic::{commit, io_error, temp_path};
use super::OutputError;

/// Physical type of one output column.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ColumnKind {
    /// 64-bit IEEE float (Parquet `DOUBLE`).
    F64,
    /// Unsigned 64-bit integer (Parquet `INT64` annotated `UINT_64`).
    U64,
    /// Signed 32-bit integer (Parquet `INT32`).
    I32,
    /// Boolean (Parquet `BOOLEAN`).
    Bool,
    /// UTF-8 string (Parquet `BYTE_ARRAY` annotated `STRING`).
    Utf8,
}

impl ColumnKind {
    /// Arrow data type used for this kind.
    fn data_type(self) -> DataType {
        match self {
            ColumnKind::F64 => DataType::Float64,
            ColumnKind::U64 => DataType::UInt64,
            ColumnKind::I32 => DataType::Int32,
            ColumnKind::Bool => DataType::Boolean,
            ColumnKind::Utf8 => DataType::Utf8,
        }
    }
}

impl fmt::Display for ColumnKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            ColumnKind::F64 => "f64",
            ColumnKind::U64 => "u64",
            ColumnKind::I32 => "i32",
            ColumnKind::Bool => "bool",
            ColumnKind::Utf8 => "utf8",
        })
    }
}

/// Name and kind of one output column.
#[derive(Clone, Debug)]
pub struct ColumnSpec {
    /// Column name, SI-suffixed by convention (e.g. `ullage_pressure_pa`).
    pub name: String,
    /// Physical type of the column.
    pub kind: ColumnKind,
    /// Whether the column holds nulls. F64 columns always do (NaN is written as null, so
    /// DuckDB, polars and pandas skip it alike); a UTF-8 column does when declared
    /// [`ColumnSpec::optional`] (an empty string is written as null).
    pub nullable: bool,
}

impl ColumnSpec {
    /// Creates a column spec; an F64 column is nullable (NaN → null), others are not.
    pub fn new(name: impl Into<String>, kind: ColumnKind) -> Self {
        ColumnSpec {
            name: name.into(),
            kind,
            nullable: kind == ColumnKind::F64,
        }
    }

    /// A nullable column: NaN (F64), an empty string (UTF-8) or `None` ([`ColumnData::OptBool`])
    /// is written as null.
    pub fn optional(name: impl Into<String>, kind: ColumnKind) -> Self {
        ColumnSpec {
            nullable: true,
            ..ColumnSpec::new(name, kind)
        }
    }
}

/// One chunk's column data, borrowed.
#[derive(Clone, Copy, Debug)]
pub enum ColumnData<'a> {
    /// Values of an [`ColumnKind::F64`] column.
    F64(&'a [f64]),
    /// Values of an [`ColumnKind::U64`] column.
    U64(&'a [u64]),
    /// Values of an [`ColumnKind::I32`] column.
    I32(&'a [i32]),
    /// Values of an [`ColumnKind::Bool`] column.
    Bool(&'a [bool]),
    /// Values of a nullable [`ColumnKind::Bool`] column (`None` is null).
    OptBool(&'a [Option<bool>]),
    /// Values of an [`ColumnKind::Utf8`] column.
    Utf8(&'a [String]),
}

impl ColumnData<'_> {
    /// Kind of this data.
    pub fn kind(&self) -> ColumnKind {
        match self {
            ColumnData::F64(_) => ColumnKind::F64,
            ColumnData::U64(_) => ColumnKind::U64,
            ColumnData::I32(_) => ColumnKind::I32,
            ColumnData::Bool(_) | ColumnData::OptBool(_) => ColumnKind::Bool,
            ColumnData::Utf8(_) => ColumnKind::Utf8,
        }
    }

    /// Number of values (rows).
    pub fn len(&self) -> usize {
        match self {
            ColumnData::F64(v) => v.len(),
            ColumnData::U64(v) => v.len(),
            ColumnData::I32(v) => v.len(),
            ColumnData::Bool(v) => v.len(),
            ColumnData::OptBool(v) => v.len(),
            ColumnData::Utf8(v) => v.len(),
        }
    }

    /// Whether there are no values.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Copies the values into an Arrow array; in a `nullable` column NaN and "" become null.
    fn to_array(self, nullable: bool) -> ArrayRef {
        match self {
            ColumnData::F64(v) if nullable => Arc::new(
                v.iter()
                    .map(|&x| (!x.is_nan()).then_some(x))
                    .collect::<Float64Array>(),
            ),
            ColumnData::Utf8(v) if nullable => Arc::new(
                v.iter()
                    .map(|x| (!x.is_empty()).then_some(x.as_str()))
                    .collect::<StringArray>(),
            ),
            ColumnData::F64(v) => Arc::new(Float64Array::from(v.to_vec())),
            ColumnData::U64(v) => Arc::new(UInt64Array::from(v.to_vec())),
            ColumnData::I32(v) => Arc::new(Int32Array::from(v.to_vec())),
            ColumnData::Bool(v) => Arc::new(BooleanArray::from(v.to_vec())),
            ColumnData::OptBool(v) => Arc::new(BooleanArray::from(v.to_vec())),
            ColumnData::Utf8(v) => Arc::new(StringArray::from_iter_values(v)),
        }
    }
}

/// Streaming, atomic Parquet writer for a flat table.
///
/// Data goes to `<path>.tmp-<pid>` in the same directory; [`finish`](Self::finish)
/// fsyncs it and renames it over `path`. If the writer is dropped without
/// `finish` (error, panic, early return) the temporary file is removed and
/// any existing file at `path` is left untouched.
///
/// Each [`write_chunk`](Self::write_chunk) becomes exactly one row group, so
/// memory is bounded by the chunk size no matter how many rows are written.
///
/// The temporary name depends only on `path` and the process id, so one
/// process must not have two writers for the same `path` open at once.
pub struct TableWriter {
    /// Final output path.
    path: PathBuf,
    /// Temporary file being written.
    tmp: PathBuf,
    /// Column specs, in file order.
    columns: Vec<ColumnSpec>,
    /// Arrow schema built from `columns`.
    schema: SchemaRef,
    /// Encoder; `None` once taken by `finish`.
    writer: Option<ArrowWriter<File>>,
    /// Rows written so far.
    rows: u64,
    /// Set when an encoder or I/O error may have left the file inconsistent.
    poisoned: bool,
    /// Set once the temporary file has been renamed to `path`.
    committed: bool,
}

impl TableWriter {
    /// Opens `<path>.tmp-<pid>` (same directory) for writing.
    ///
    /// `metadata` becomes Parquet file-level key-value metadata (readable by
    /// pyarrow, polars and DuckDB), next to the `ARROW:schema` entry the
    /// Arrow writer adds itself. Columns are Snappy compressed; nullable as
    /// their [`ColumnSpec::nullable`] says. Fails if `columns` is empty or has duplicate names, or if
    /// the temporary file cannot be created (e.g. missing directory).
    pub fn create(
        path: &Path,
        columns: Vec<ColumnSpec>,
        metadata: Vec<(String, String)>,
    ) -> Result<TableWriter, OutputError> {
        if columns.is_empty() {
            return Err(OutputError::NoColumns {
                path: path.to_path_buf(),
            });
        }
        let mut seen = HashSet::new();
        for spec in &columns {
            if !seen.insert(spec.name.as_str()) {
                return Err(OutputError::DuplicateColumn {
                    path: path.to_path_buf(),
                    column: spec.name.clone(),
                });
            }
        }
        let schema: SchemaRef = Arc::new(Schema::new(
            columns
                .iter()
                .map(|spec| Field::new(spec.name.as_str(), spec.kind.data_type(), spec.nullable))
                .collect::<Vec<_>>(),
        ));
        let key_values = metadata
            .into_iter()
            .map(|(key, value)| KeyValue::new(key, value))
            .collect::<Vec<_>>();
        let props = WriterProperties::builder()
            .set_compression(Compression::SNAPPY)
            // Row groups are cut only by the explicit flush after each chunk.
            .set_max_row_group_row_count(None)
            .set_max_row_group_bytes(None)
            .set_key_value_metadata(Some(key_values))
            .build();

        let tmp = temp_path(path)?;
        let file = File::create(&tmp).map_err(|source| io_error(path, source))?;
        let writer = match ArrowWriter::try_new(file, Arc::clone(&schema), Some(props)) {
            Ok(writer) => writer,
            Err(source) => {
                let _ = fs::remove_file(&tmp);
                return Err(OutputError::Parquet {
                    path: path.to_path_buf(),
                    source,
                });
            }
        };
        Ok(TableWriter {
            path: path.to_path_buf(),
            tmp,
            columns,
            schema,
            writer: Some(writer),
            rows: 0,
            poisoned: false,
            committed: false,
        })
    }

    /// Writes one chunk as one row group.
    ///
    /// `columns` must hold one entry per [`ColumnSpec`], in spec order, with
    /// matching kinds and equal lengths. Validation happens before anything is
    /// written, so a rejected chunk ([`OutputError::ColumnCount`],
    /// [`OutputError::ColumnKind`], [`OutputError::RowCount`]) leaves the
    /// writer usable. A chunk of zero rows is validated and then skipped
    /// (Parquet row groups are never empty). An encoder or I/O error poisons
    /// the writer: later calls fail and the file is never committed.
    pub fn write_chunk(&mut self, columns: &[ColumnData<'_>]) -> Result<(), OutputError> {
        if self.poisoned {
            return Err(self.poisoned_error());
        }
        if columns.len() != self.columns.len() {
            return Err(OutputError::ColumnCount {
                path: self.path.clone(),
                expected: self.columns.len(),
                got: columns.len(),
            });
        }
        let rows = columns.first().map_or(0, ColumnData::len);
        for (spec, data) in self.columns.iter().zip(columns) {
            if data.kind() != spec.kind {
                return Err(OutputError::ColumnKind {
                    path: self.path.clone(),
                    column: spec.name.clone(),
                    expected: spec.kind,
                    got: data.kind(),
                });
            }
            if data.len() != rows {
                return Err(OutputError::RowCount {
                    path: self.path.clone(),
                    column: spec.name.clone(),
                    expected: rows,
                    got: data.len(),
                });
            }
            if let ColumnData::Utf8(values) = data {
                // Arrow `Utf8` arrays use i32 offsets; larger chunks would panic.
                let bytes = values
                    .iter()
                    .map(String::len)
                    .fold(0usize, usize::saturating_add);
                if i32::try_from(bytes).is_err() {
                    return Err(OutputError::Utf8Overflow {
                        path: self.path.clone(),
                        column: spec.name.clone(),
                        bytes,
                    });
                }
            }
        }
        if rows == 0 {
            return Ok(());
        }

        let arrays = columns
            .iter()
            .zip(&self.columns)
            .map(|(data, spec)| data.to_array(spec.nullable))
            .collect();
        let batch = RecordBatch::try_new(Arc::clone(&self.schema), arrays).map_err(|source| {
            OutputError::Arrow {
                path: self.path.clone(),
                source,
            }
        })?;
        let Some(writer) = self.writer.as_mut() else {
            return Err(self.poisoned_error());
        };
        if let Err(source) = writer.write(&batch).and_then(|()| writer.flush()) {
            self.poisoned = true;
            return Err(OutputError::Parquet {
                path: self.path.clone(),
                source,
            });
        }
        self.rows += rows as u64;
        Ok(())
    }

    /// Add a file-level key-value entry known only at the end (e.g. the instance count of a
    /// precision-driven run); written into the footer by [`finish`](Self::finish).
    pub fn append_metadata(&mut self, key: &str, value: &str) {
        if let Some(w) = self.writer.as_mut() {
            w.append_key_value_metadata(KeyValue::new(key.to_string(), value.to_string()));
        }
    }

    /// Rows written so far (across all chunks).
    pub fn rows_written(&self) -> u64 {
        self.rows
    }

    /// Final output path.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Writes the footer, fsyncs, and renames the temporary file over the
    /// final path (atomic replace). Returns the number of rows written.
    ///
    /// On error the temporary file is removed and any previous file at the
    /// final path is left untouched.
    pub fn finish(mut self) -> Result<u64, OutputError> {
        if self.poisoned {
            return Err(self.poisoned_error());
        }
        let Some(writer) = self.writer.take() else {
            return Err(self.poisoned_error());
        };
        let file = writer.into_inner().map_err(|source| OutputError::Parquet {
            path: self.path.clone(),
            source,
        })?;
        file.sync_all()
            .map_err(|source| io_error(&self.path, source))?;
        drop(file);
        commit(&self.tmp, &self.path)?;
        self.committed = true;
        Ok(self.rows)
    }

    /// Error returned once the writer can no longer produce a valid file.
    fn poisoned_error(&self) -> OutputError {
        OutputError::Poisoned {
            path: self.path.clone(),
        }
    }
}

impl fmt::Debug for TableWriter {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("TableWriter")
            .field("path", &self.path)
            .field("tmp", &self.tmp)
            .field("columns", &self.columns)
            .field("rows", &self.rows)
            .field("poisoned", &self.poisoned)
            .field("committed", &self.committed)
            .finish_non_exhaustive()
    }
}

impl Drop for TableWriter {
    /// Removes the temporary file unless [`TableWriter::finish`] committed it,
    /// so a half-written file never appears at the final path.
    fn drop(&mut self) {
        if !self.committed {
            // Close the file handle before removing it (required on Windows).
            drop(self.writer.take());
            let _ = fs::remove_file(&self.tmp);
        }
    }
}
