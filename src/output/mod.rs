//! Parquet output: flat SI-named columns, file-level provenance metadata, atomic writes.
//!
//! Every file this module produces is written to a temporary sibling
//! (`<path>.tmp-<pid>`), fsynced and then renamed over the final path, so a
//! reader never sees a half-written file and an interrupted run never replaces
//! a previous good result. [`TableWriter`] streams a flat table of
//! numeric (and string) columns, missing values as Arrow nulls, into a Snappy-compressed Parquet
//! file, one row group per chunk, with caller-supplied provenance stored as
//! Parquet file-level key-value metadata. [`atomic::write_atomic`] does the
//! same for small whole-file payloads such as `run.json`.

pub mod atomic;
mod parquet;
pub mod results_dir;

pub use self::parquet::{ColumnData, ColumnKind, ColumnSpec, TableWriter};

use std::path::PathBuf;

/// Errors raised while writing output files.
///
/// Every variant names the final output path (not the temporary file), and
/// column-level variants also name the column.
#[derive(Debug, thiserror::Error)]
pub enum OutputError {
    /// A filesystem operation (create, write, fsync, rename) failed.
    #[error("cannot write {path}: {source}")]
    Io {
        /// Final output path.
        path: PathBuf,
        /// Underlying I/O error.
        #[source]
        source: std::io::Error,
    },
    /// The Parquet encoder failed.
    #[error("cannot write Parquet file {path}: {source}")]
    Parquet {
        /// Final output path.
        path: PathBuf,
        /// Underlying Parquet error.
        #[source]
        source: ::parquet::errors::ParquetError,
    },
    /// Assembling an Arrow record batch from the chunk failed.
    #[error("cannot build Arrow batch for {path}: {source}")]
    Arrow {
        /// Final output path.
        path: PathBuf,
        /// Underlying Arrow error.
        #[source]
        source: arrow_schema::ArrowError,
    },
    /// A column of a chunk has a different length than the chunk's first column.
    #[error("column {column} of {path}: expected {expected} rows, got {got}")]
    RowCount {
        /// Final output path.
        path: PathBuf,
        /// Name of the offending column.
        column: String,
        /// Row count of the chunk (length of its first column).
        expected: usize,
        /// Length of the offending column.
        got: usize,
    },
    /// A column of a chunk does not have the kind declared in the schema.
    #[error("column {column} of {path}: expected a {expected} column, got {got}")]
    ColumnKind {
        /// Final output path.
        path: PathBuf,
        /// Name of the offending column.
        column: String,
        /// Kind declared in the [`ColumnSpec`].
        expected: ColumnKind,
        /// Kind of the data passed in.
        got: ColumnKind,
    },
    /// A chunk has a different number of columns than the schema.
    #[error("{path}: expected {expected} columns per chunk, got {got}")]
    ColumnCount {
        /// Final output path.
        path: PathBuf,
        /// Number of columns in the schema.
        expected: usize,
        /// Number of columns passed in.
        got: usize,
    },
    /// The string data of one chunk's UTF-8 column exceeds Arrow's 2 GiB offset limit.
    #[error("column {column} of {path}: {bytes} bytes of string data in one chunk exceeds 2 GiB; write smaller chunks")]
    Utf8Overflow {
        /// Final output path.
        path: PathBuf,
        /// Name of the offending column.
        column: String,
        /// Total string bytes in the chunk's column.
        bytes: usize,
    },
    /// Two columns of the schema share a name.
    #[error("column {column} of {path}: duplicate column name")]
    DuplicateColumn {
        /// Final output path.
        path: PathBuf,
        /// The repeated column name.
        column: String,
    },
    /// The schema has no columns.
    #[error("{path}: a table needs at least one column")]
    NoColumns {
        /// Final output path.
        path: PathBuf,
    },
    /// The output path has no file name component (e.g. `/` or `..`).
    #[error("cannot write {path}: path does not name a file")]
    InvalidPath {
        /// The rejected path.
        path: PathBuf,
    },
    /// An earlier encoder or I/O failure left the writer unusable.
    #[error("cannot write Parquet file {path}: an earlier write failed")]
    Poisoned {
        /// Final output path.
        path: PathBuf,
    },
}
