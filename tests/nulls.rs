//! Regression: a rejected instance was written as NaN, which made DuckDB's `avg`/`max` NaN, shifted
//! `quantile_cont`, and had polars, DuckDB and pandas count `boiloff_kg > x` differently.

mod common;
use common::load;
use cryoslosh::engine::{Backend, CpuEngine};
use cryoslosh::montecarlo::{self, RunOptions, Shard};
use std::process::Command;

#[test]
fn rejected_instances_are_nulls_and_readers_agree() {
    if !common::python_with("pyarrow, polars, duckdb, pandas") {
        return;
    }
    // relief.crack_pa ~ N(165 kPa, 1.5 kPa) falls below a 164 kPa reseat in some samples: those
    // instances are rejected, and their QoIs must be nulls.
    let c = load(
        "lch4_coast",
        &["phases.0.duration_s=3600", "relief.reseat_pa=164000"],
    );
    let dir = std::env::temp_dir().join(format!("cryoslosh-nulls-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let opts = RunOptions {
        out_dir: dir.clone(),
        instances: 64,
        seed: 9,
        shard: Shard::ALL,
        chunk_size: 64,
        progress: false,
        histories: Vec::new(),
        until: None,
        force: false,
        resume: false,
    };
    let backend = Backend::Cpu(CpuEngine::new(2).unwrap());
    let r = montecarlo::run(&c, &backend, &opts).unwrap();
    assert!(r.rejected > 0, "the campaign must reject some samples");
    let script = format!(
        r#"
import duckdb, polars as pl, pandas as pd, pyarrow.parquet as pq
d = "{dir}"
inst = d + "/instances.parquet"
stats = pl.read_parquet(d + "/statistics.parquet")
pdf = pd.read_parquet(inst)
pldf = pl.read_parquet(inst)
rejected = int(pldf["rejected"].sum())
assert rejected == {rejected}, rejected
for q in ["peak_pressure_pa", "boiloff_kg"]:
    # Nulls exactly where the instance is rejected or diverged.
    nulls = pldf.filter(pl.col("rejected") | pl.col("diverged")).height
    assert pldf[q].null_count() == nulls, (q, pldf[q].null_count(), nulls)
    def stat(s):
        return stats.filter((pl.col("quantity") == q) & (pl.col("statistic") == s))["value"][0]
    want = {{"mean": stat("mean"), "max": stat("max"), "p99": stat("p99")}}
    got = {{
        "duckdb": duckdb.sql(f"select avg({{q}}), max({{q}}), quantile_cont({{q}}, 0.99) from '{{inst}}'").fetchall()[0],
        "polars": (pldf[q].mean(), pldf[q].max(), pldf[q].quantile(0.99, "linear")),
        "pandas": (pdf[q].mean(), pdf[q].max(), pdf[q].quantile(0.99)),
    }}
    for reader, (mean, mx, p99) in got.items():
        for name, value in [("mean", mean), ("max", mx), ("p99", p99)]:
            ref = want[name]
            assert abs(value - ref) <= 1e-12 * abs(ref), (reader, q, name, value, ref)
    # The same count of instances above a threshold in every reader.
    x = want["mean"]
    counts = (
        duckdb.sql(f"select count(*) from '{{inst}}' where {{q}} > {{x}}").fetchall()[0][0],
        pldf.filter(pl.col(q) > x).height,
        int((pdf[q] > x).sum()),
    )
    assert len(set(counts)) == 1, (q, counts)
# Outcome flags of rejected rows are nulls too, so avg(overpressure) agrees with the statistics.
bad = pldf.filter(pl.col("rejected") | pl.col("diverged"))
for flag in ["cavitation", "overpressure", "pressurant_exhausted", "depleted", "slosh_out_of_range"]:
    assert bad[flag].null_count() == bad.height, (flag, bad[flag].null_count(), bad.height)
    assert pldf[flag].null_count() == bad.height, flag
assert pldf["rejected"].null_count() == 0 and pldf["diverged"].null_count() == 0
# "No input" is a null, not an empty string.
plain = stats.filter(pl.col("statistic") == "mean")
assert plain["input"].null_count() == plain.height
assert stats.filter(pl.col("statistic") == "spearman")["input"].null_count() == 0
print("ok")
"#,
        dir = dir.display(),
        rejected = r.rejected
    );
    let out = Command::new("python3")
        .args(["-c", &script])
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    std::fs::remove_dir_all(dir).ok();
}
