"""`simulate`, `check`, `merge` and `replay` from Python match the CLI."""

from __future__ import annotations

import pyarrow.parquet as pq

import cryoslosh
from conftest import CAMPAIGN


def test_simulate_equals_cli_history(cli, tmp_path):
    out = tmp_path / "h.parquet"
    assert cli("simulate", CAMPAIGN, "--out", str(out), "--instance", "3").returncode == 0
    s = cryoslosh.simulate(CAMPAIGN, instance=3)
    assert s.history.equals(pq.read_table(out))
    assert set(s.inputs) == {"tank.heat_leak_w", "propellant.fill_fraction", "tank.wall_areal_mass_kg_per_m2"}
    assert s.summary.startswith("peak pressure")


def test_check_text_is_the_cli_output(cli):
    assert cryoslosh.check(CAMPAIGN) == cli("check", CAMPAIGN).stdout


def test_shards_merge_to_the_one_machine_run_and_replay(tmp_path):
    whole = cryoslosh.run(CAMPAIGN, instances=30, out=tmp_path / "whole")
    dirs = [tmp_path / f"s{i}" for i in range(3)]
    for i, d in enumerate(dirs):
        cryoslosh.run(CAMPAIGN, instances=30, shard=f"{i}/3", out=d)
    merged = cryoslosh.merge(dirs, tmp_path / "merged")
    assert merged.instances.equals(whole.instances)
    assert merged.statistics.equals(whole.statistics)
    for f in ("instances.parquet", "statistics.parquet"):
        assert (tmp_path / "merged" / f).read_bytes() == (tmp_path / "whole" / f).read_bytes()
    history, diffs = cryoslosh.replay(tmp_path / "merged", 17)
    assert diffs == [] and history is not None and history.num_rows > 0
