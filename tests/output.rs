//! Integration tests for the Parquet output module.

use std::fs::{self, File};
use std::path::{Path, PathBuf};
use std::process::Command;

use arrow_array::cast::AsArray;
use arrow_array::types::{Float64Type, Int32Type, UInt64Type};
use arrow_array::{Array, RecordBatch};
use cryoslosh::output::atomic::{temp_path, write_atomic};
use cryoslosh::output::*;
use parquet::arrow::arrow_reader::ParquetRecordBatchReaderBuilder;
use parquet::basic::{Compression, Repetition};
use parquet::file::metadata::ParquetMetaData;

/// Fresh, empty scratch directory unique to this test and process.
fn scratch_dir(test: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("cryoslosh-output-{test}-{}", std::process::id()));
    let _ = fs::remove_dir_all(&dir);
    fs::create_dir_all(&dir).unwrap();
    dir
}

fn specs() -> Vec<ColumnSpec> {
    vec![
        ColumnSpec::new("time_s", ColumnKind::F64),
        ColumnSpec::new("instance_id", ColumnKind::U64),
        ColumnSpec::new("regime_code", ColumnKind::I32),
        ColumnSpec::new("vented", ColumnKind::Bool),
        ColumnSpec::new("label", ColumnKind::Utf8),
    ]
}

fn metadata() -> Vec<(String, String)> {
    vec![
        (
            "cryoslosh.campaign".to_string(),
            "lh2-ground-hold".to_string(),
        ),
        ("cryoslosh.seed".to_string(), "12345".to_string()),
    ]
}

/// One chunk of synthetic data, rows `start..start + len`.
struct Chunk {
    time: Vec<f64>,
    id: Vec<u64>,
    code: Vec<i32>,
    vented: Vec<bool>,
    label: Vec<String>,
}

impl Chunk {
    fn new(start: usize, len: usize) -> Self {
        let rows = start..start + len;
        Chunk {
            time: rows.clone().map(|i| i as f64 * 0.25 - 3.5).collect(),
            id: rows.clone().map(|i| u64::MAX - i as u64).collect(),
            code: rows.clone().map(|i| i as i32 - 7).collect(),
            vented: rows.clone().map(|i| i % 3 == 0).collect(),
            label: rows.map(|i| format!("run-{i}-µ")).collect(),
        }
    }

    fn data(&self) -> Vec<ColumnData<'_>> {
        vec![
            ColumnData::F64(&self.time),
            ColumnData::U64(&self.id),
            ColumnData::I32(&self.code),
            ColumnData::Bool(&self.vented),
            ColumnData::Utf8(&self.label),
        ]
    }
}

/// Reads a Parquet file back: its metadata and all record batches.
fn read_back(path: &Path) -> (ParquetMetaData, Vec<RecordBatch>) {
    let builder = ParquetRecordBatchReaderBuilder::try_new(File::open(path).unwrap()).unwrap();
    let meta = builder.metadata().as_ref().clone();
    let batches = builder
        .build()
        .unwrap()
        .collect::<Result<Vec<_>, _>>()
        .unwrap();
    (meta, batches)
}

fn kv(meta: &ParquetMetaData, key: &str) -> Option<String> {
    meta.file_metadata()
        .key_value_metadata()?
        .iter()
        .find(|entry| entry.key == key)
        .and_then(|entry| entry.value.clone())
}

#[test]
fn round_trip_three_chunks() {
    let dir = scratch_dir("round-trip");
    let path = dir.join("history.parquet");
    let lens = [5usize, 1, 1234];
    let mut chunks = Vec::new();
    let mut start = 0;
    for len in lens {
        chunks.push(Chunk::new(start, len));
        start += len;
    }
    let total = start;

    let mut writer = TableWriter::create(&path, specs(), metadata()).unwrap();
    assert!(temp_path(&path).unwrap().exists());
    assert!(!path.exists());
    for chunk in &chunks {
        writer.write_chunk(&chunk.data()).unwrap();
    }
    assert_eq!(writer.rows_written(), total as u64);
    assert_eq!(writer.finish().unwrap(), total as u64);
    assert!(path.exists());
    assert!(!temp_path(&path).unwrap().exists());

    let (meta, batches) = read_back(&path);
    assert_eq!(meta.file_metadata().num_rows(), total as i64);
    assert_eq!(meta.num_row_groups(), 3);
    for (i, len) in lens.iter().enumerate() {
        let row_group = meta.row_group(i);
        assert_eq!(row_group.num_rows(), *len as i64);
        for column in row_group.columns() {
            assert_eq!(column.compression(), Compression::SNAPPY);
        }
    }
    let schema = meta.file_metadata().schema_descr();
    assert_eq!(schema.num_columns(), 5);
    for (i, spec) in specs().iter().enumerate() {
        let column = schema.column(i);
        assert_eq!(column.name(), spec.name);
        // F64 columns hold nulls (NaN is written as null); the others are required.
        let expected = if spec.nullable {
            Repetition::OPTIONAL
        } else {
            Repetition::REQUIRED
        };
        assert_eq!(column.self_type().get_basic_info().repetition(), expected);
    }
    assert_eq!(
        kv(&meta, "cryoslosh.campaign").as_deref(),
        Some("lh2-ground-hold")
    );
    assert_eq!(kv(&meta, "cryoslosh.seed").as_deref(), Some("12345"));

    let mut time: Vec<f64> = Vec::new();
    let mut id: Vec<u64> = Vec::new();
    let mut code: Vec<i32> = Vec::new();
    let mut vented: Vec<bool> = Vec::new();
    let mut label: Vec<String> = Vec::new();
    for batch in &batches {
        assert_eq!(batch.schema().field(0).name(), "time_s");
        assert!(batch.schema().field(0).is_nullable());
        assert_eq!(batch.column(0).null_count(), 0);
        time.extend(batch.column(0).as_primitive::<Float64Type>().values());
        id.extend(batch.column(1).as_primitive::<UInt64Type>().values());
        code.extend(batch.column(2).as_primitive::<Int32Type>().values());
        vented.extend(batch.column(3).as_boolean().iter().map(Option::unwrap));
        label.extend(
            batch
                .column(4)
                .as_string::<i32>()
                .iter()
                .map(|s| s.unwrap().to_string()),
        );
    }
    let expected = Chunk::new(0, total);
    assert_eq!(time, expected.time);
    assert_eq!(id, expected.id);
    assert_eq!(code, expected.code);
    assert_eq!(vented, expected.vented);
    assert_eq!(label, expected.label);

    fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn empty_chunk_and_empty_table() {
    let dir = scratch_dir("empty");
    let path = dir.join("empty.parquet");
    let mut writer = TableWriter::create(&path, specs(), metadata()).unwrap();
    writer.write_chunk(&Chunk::new(0, 0).data()).unwrap();
    assert_eq!(writer.finish().unwrap(), 0);
    let (meta, batches) = read_back(&path);
    assert_eq!(meta.num_row_groups(), 0);
    assert_eq!(meta.file_metadata().num_rows(), 0);
    assert!(batches.iter().all(|b| b.num_rows() == 0));
    assert_eq!(kv(&meta, "cryoslosh.seed").as_deref(), Some("12345"));
    fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn dropped_writer_leaves_nothing() {
    let dir = scratch_dir("dropped");
    let path = dir.join("partial.parquet");
    let mut writer = TableWriter::create(&path, specs(), metadata()).unwrap();
    writer.write_chunk(&Chunk::new(0, 10).data()).unwrap();
    assert!(temp_path(&path).unwrap().exists());
    drop(writer);
    assert!(!path.exists());
    assert!(!temp_path(&path).unwrap().exists());
    assert_eq!(fs::read_dir(&dir).unwrap().count(), 0);
    fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn wrong_row_count_names_column() {
    let dir = scratch_dir("row-count");
    let path = dir.join("bad.parquet");
    let mut writer = TableWriter::create(&path, specs(), metadata()).unwrap();
    let chunk = Chunk::new(0, 4);
    let short = [1i32, 2, 3];
    let mut data = chunk.data();
    data[2] = ColumnData::I32(&short);
    let err = writer.write_chunk(&data).unwrap_err();
    assert!(matches!(
        err,
        OutputError::RowCount {
            expected: 4,
            got: 3,
            ..
        }
    ));
    let message = err.to_string();
    assert!(message.contains("regime_code"), "{message}");
    assert!(message.contains(&path.display().to_string()), "{message}");

    // A rejected chunk writes nothing; the writer stays usable.
    writer.write_chunk(&chunk.data()).unwrap();
    assert_eq!(writer.finish().unwrap(), 4);
    let (meta, _) = read_back(&path);
    assert_eq!(meta.num_row_groups(), 1);
    fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn wrong_kind_and_count_are_errors() {
    let dir = scratch_dir("kind");
    let path = dir.join("bad.parquet");
    let mut writer = TableWriter::create(&path, specs(), metadata()).unwrap();
    let chunk = Chunk::new(0, 4);
    let mut data = chunk.data();
    let wrong = [1.0f64, 2.0, 3.0, 4.0];
    data[1] = ColumnData::F64(&wrong);
    let err = writer.write_chunk(&data).unwrap_err();
    assert!(matches!(
        err,
        OutputError::ColumnKind {
            expected: ColumnKind::U64,
            got: ColumnKind::F64,
            ..
        }
    ));
    let message = err.to_string();
    assert!(message.contains("instance_id"), "{message}");
    assert!(message.contains(&path.display().to_string()), "{message}");

    let err = writer.write_chunk(&chunk.data()[..3]).unwrap_err();
    assert!(matches!(
        err,
        OutputError::ColumnCount {
            expected: 5,
            got: 3,
            ..
        }
    ));
    drop(writer);
    assert_eq!(fs::read_dir(&dir).unwrap().count(), 0);
    fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn invalid_schemas_are_rejected() {
    let dir = scratch_dir("schema");
    let path = dir.join("bad.parquet");
    let err = TableWriter::create(&path, Vec::new(), metadata()).unwrap_err();
    assert!(matches!(err, OutputError::NoColumns { .. }));
    let dup = vec![
        ColumnSpec::new("x_m", ColumnKind::F64),
        ColumnSpec::new("x_m", ColumnKind::U64),
    ];
    let err = TableWriter::create(&path, dup, metadata()).unwrap_err();
    assert!(err.to_string().contains("x_m"), "{err}");
    assert_eq!(fs::read_dir(&dir).unwrap().count(), 0);
    fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn existing_file_replaced_only_on_finish() {
    let dir = scratch_dir("replace");
    let path = dir.join("results.parquet");
    fs::write(&path, b"previous results").unwrap();

    // Abandoned writer: previous file untouched.
    let mut writer = TableWriter::create(&path, specs(), metadata()).unwrap();
    writer.write_chunk(&Chunk::new(0, 3).data()).unwrap();
    drop(writer);
    assert_eq!(fs::read(&path).unwrap(), b"previous results");

    // Writer in progress: previous file untouched until finish.
    let mut writer = TableWriter::create(&path, specs(), metadata()).unwrap();
    writer.write_chunk(&Chunk::new(0, 3).data()).unwrap();
    assert_eq!(fs::read(&path).unwrap(), b"previous results");
    writer.finish().unwrap();
    let (meta, _) = read_back(&path);
    assert_eq!(meta.file_metadata().num_rows(), 3);
    assert_eq!(fs::read_dir(&dir).unwrap().count(), 1);
    fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn missing_directory_errors_with_path() {
    let dir = scratch_dir("missing");
    let path = dir.join("no_such_dir").join("out.parquet");
    let err = TableWriter::create(&path, specs(), metadata()).unwrap_err();
    assert!(matches!(err, OutputError::Io { .. }));
    let message = err.to_string();
    assert!(message.contains(&path.display().to_string()), "{message}");

    let json = dir.join("no_such_dir").join("run.json");
    let err = write_atomic(&json, b"{}").unwrap_err();
    assert!(
        err.to_string().contains(&json.display().to_string()),
        "{err}"
    );
    fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn write_atomic_replaces_file() {
    let dir = scratch_dir("atomic");
    let path = dir.join("run.json");
    write_atomic(&path, b"{\"a\":1}").unwrap();
    assert_eq!(fs::read(&path).unwrap(), b"{\"a\":1}");
    write_atomic(&path, b"{\"a\":2}").unwrap();
    assert_eq!(fs::read(&path).unwrap(), b"{\"a\":2}");
    assert!(!temp_path(&path).unwrap().exists());
    assert_eq!(fs::read_dir(&dir).unwrap().count(), 1);
    assert!(matches!(
        temp_path(Path::new("/")),
        Err(OutputError::InvalidPath { .. })
    ));
    let tmp = temp_path(&path).unwrap();
    assert_eq!(tmp.parent(), path.parent());
    assert_eq!(
        tmp.file_name().unwrap().to_str().unwrap(),
        format!("run.json.tmp-{}", std::process::id())
    );
    fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn pyarrow_reads_file_metadata() {
    let has_pyarrow = Command::new("python3")
        .args(["-c", "import pyarrow"])
        .output()
        .map(|out| out.status.success())
        .unwrap_or(false);
    if !has_pyarrow {
        eprintln!("skipping pyarrow_reads_file_metadata: python3 with pyarrow not available");
        return;
    }
    let dir = scratch_dir("pyarrow");
    let path = dir.join("history.parquet");
    let mut writer = TableWriter::create(&path, specs(), metadata()).unwrap();
    let chunks = [Chunk::new(0, 100), Chunk::new(100, 57)];
    for chunk in &chunks {
        writer.write_chunk(&chunk.data()).unwrap();
    }
    writer.finish().unwrap();

    let script = r#"
import sys
import pyarrow.parquet as pq
path = sys.argv[1]
meta = pq.read_metadata(path)
kv = meta.metadata
assert kv[b"cryoslosh.campaign"] == b"lh2-ground-hold", kv
assert kv[b"cryoslosh.seed"] == b"12345", kv
assert meta.num_row_groups == 2, meta.num_row_groups
table = pq.read_table(path)
assert table.schema.field("instance_id").type == "uint64"
assert table.schema.field("time_s").nullable and table.column("time_s").null_count == 0
assert not table.schema.field("instance_id").nullable
print(repr(sum(table.column("time_s").to_pylist())), sum(table.column("regime_code").to_pylist()), table.num_rows)
"#;
    let out = Command::new("python3")
        .arg("-c")
        .arg(script)
        .arg(&path)
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "python failed: {stdout}\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let fields: Vec<&str> = stdout.split_whitespace().collect();
    let all = Chunk::new(0, 157);
    let time_sum: f64 = fields[0].parse().unwrap();
    let expected_time: f64 = all.time.iter().sum();
    assert!(
        (time_sum - expected_time).abs() < 1e-9,
        "{time_sum} vs {expected_time}"
    );
    let code_sum: i64 = fields[1].parse().unwrap();
    assert_eq!(
        code_sum,
        all.code.iter().map(|&c| i64::from(c)).sum::<i64>()
    );
    assert_eq!(fields[2], "157");
    fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn large_chunk_is_one_row_group() {
    // Larger than parquet's default 1 Mi-row row-group limit: must not be split.
    let dir = scratch_dir("large");
    let path = dir.join("large.parquet");
    let rows = 1_200_000usize;
    let values: Vec<f64> = (0..rows).map(|i| i as f64).collect();
    let ids: Vec<u64> = (0..rows as u64).collect();
    let specs = vec![
        ColumnSpec::new("mass_kg", ColumnKind::F64),
        ColumnSpec::new("instance_id", ColumnKind::U64),
    ];
    let mut writer = TableWriter::create(&path, specs, Vec::new()).unwrap();
    writer
        .write_chunk(&[ColumnData::F64(&values), ColumnData::U64(&ids)])
        .unwrap();
    writer
        .write_chunk(&[ColumnData::F64(&values[..10]), ColumnData::U64(&ids[..10])])
        .unwrap();
    assert_eq!(writer.finish().unwrap(), rows as u64 + 10);
    let (meta, batches) = read_back(&path);
    assert_eq!(meta.num_row_groups(), 2);
    assert_eq!(meta.row_group(0).num_rows(), rows as i64);
    assert_eq!(meta.row_group(1).num_rows(), 10);
    let sum: f64 = batches
        .iter()
        .flat_map(|b| b.column(0).as_primitive::<Float64Type>().values().to_vec())
        .sum();
    let expected: f64 = values.iter().sum::<f64>() + values[..10].iter().sum::<f64>();
    assert_eq!(sum, expected);
    fs::remove_dir_all(&dir).unwrap();
}

/// NaN in an F64 column and "" in an optional UTF-8 column are written as Arrow nulls (a NaN made
/// DuckDB's avg and max NaN and shifted its quantiles), so every reader skips them alike.
#[test]
fn missing_values_are_arrow_nulls() {
    let dir = scratch_dir("nulls");
    let path = dir.join("t.parquet");
    let specs = vec![
        ColumnSpec::new("x", ColumnKind::F64),
        ColumnSpec::optional("input", ColumnKind::Utf8),
        ColumnSpec::new("quantity", ColumnKind::Utf8),
    ];
    let mut w = TableWriter::create(&path, specs, vec![]).unwrap();
    let x = [1.0, f64::NAN, 3.0, f64::INFINITY];
    let input: Vec<String> = ["a", "", "b", ""].iter().map(|s| s.to_string()).collect();
    let quantity: Vec<String> = ["", "q", "q", "q"].iter().map(|s| s.to_string()).collect();
    w.write_chunk(&[
        ColumnData::F64(&x),
        ColumnData::Utf8(&input),
        ColumnData::Utf8(&quantity),
    ])
    .unwrap();
    w.finish().unwrap();
    let (_, batches) = read_back(&path);
    let b = &batches[0];
    let xs = b.column(0).as_primitive::<Float64Type>();
    assert_eq!(xs.null_count(), 1);
    assert!(xs.is_null(1));
    assert_eq!(xs.value(3), f64::INFINITY, "only NaN is a missing value");
    assert_eq!(b.column(1).null_count(), 2);
    assert!(b.column(1).is_null(1) && b.column(1).is_null(3));
    assert_eq!(
        b.column(2).null_count(),
        0,
        "a required string column keeps \"\""
    );
    fs::remove_dir_all(&dir).unwrap();
}
