"""Regression: `cryoslosh.run` refused a campaign with [[variants]] (exit-2 error telling the user
to use the CLI); it now runs every variant on the same instances and returns and writes what
`cryoslosh run` does (each variant's tables and the paired differences), and `merge` joins the
shards of such a run as `cryoslosh merge` does."""

from __future__ import annotations

import pyarrow.parquet as pq

import cryoslosh

TRADE = "campaigns/tank_design_trade.toml"
NAMES = [
    "baseline",
    "baffles",
    "thick_insulation",
    "baffles_insulation",
    "mixer",
    "pressure_control",
]
# The shipped trade, shortened (as tests/variants.rs does).
SHORT = {
    "phases.pad_hold.duration_s": 30,
    "phases.burn1.duration_s": 100,
    "phases.coast.duration_s": 300,
    "phases.restart.duration_s": 40,
}


def _cli_sets() -> list:
    return [a for k, v in SHORT.items() for a in ("--set", f"{k}={v}")]


def test_variants_run_returns_and_writes_what_the_cli_does(cli, tmp_path):
    cli_dir, py_dir = tmp_path / "cli", tmp_path / "py"
    done = cli("run", TRADE, "--out", str(cli_dir), "--instances", "6", "--backend", "cpu", *_cli_sets())
    assert done.returncode == 0, done.stderr
    r = cryoslosh.run(TRADE, instances=6, sets=SHORT, threads=1, out=py_dir)
    assert isinstance(r, cryoslosh.VariantsResult)
    assert list(r.variants) == NAMES and r.baseline == "baseline"
    for name in NAMES:
        for f in ("instances.parquet", "statistics.parquet"):
            want = cli_dir / "variants" / name / f
            assert (py_dir / "variants" / name / f).read_bytes() == want.read_bytes(), (name, f)
        v = r.variants[name]
        assert v.instances.equals(pq.read_table(cli_dir / "variants" / name / "instances.parquet"))
        assert v.statistics.equals(pq.read_table(cli_dir / "variants" / name / "statistics.parquet"))
        assert v.instances.num_rows == 6 and v.run_info["instances"] == 6
    diff = cli_dir / "differences.parquet"
    assert (py_dir / "differences.parquet").read_bytes() == diff.read_bytes()
    assert r.differences.equals(pq.read_table(diff))
    assert set(r.differences.column("variant").to_pylist()) == set(NAMES[1:])
    assert r.run_info["baseline"] == "baseline"
    assert [v["name"] for v in r.run_info["variants"]] == NAMES
    # Without `out` the same tables come back from a scratch directory.
    scratch = cryoslosh.run(TRADE, instances=6, sets=SHORT, threads=1)
    assert isinstance(scratch, cryoslosh.VariantsResult)
    assert scratch.differences.equals(r.differences)


def test_variants_shards_merge_to_the_whole_run(tmp_path):
    whole = cryoslosh.run(TRADE, instances=6, sets=SHORT, threads=1, out=tmp_path / "whole")
    shards = [tmp_path / f"s{i}" for i in range(2)]
    for i, d in enumerate(shards):
        part = cryoslosh.run(TRADE, instances=6, sets=SHORT, threads=1, shard=f"{i}/2", out=d)
        assert isinstance(part, cryoslosh.VariantsResult)
    merged = cryoslosh.merge(shards, tmp_path / "merged")
    assert isinstance(merged, cryoslosh.VariantsResult)
    assert merged.differences.equals(whole.differences)
    for name in NAMES:
        assert merged.variants[name].instances.equals(whole.variants[name].instances)
