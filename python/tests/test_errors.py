"""Errors raise the class of the CLI's exit code, with the CLI's message naming the key."""

from __future__ import annotations

import pytest

import cryoslosh
from conftest import CAMPAIGN


def test_bad_value_names_file_key_value_and_range(cli, tmp_path):
    with pytest.raises(cryoslosh.BadInputError) as e:
        cryoslosh.run(CAMPAIGN, instances=8, sets={"tank.heat_leak_w": -5})
    err = e.value
    assert err.exit_code == 2
    assert (err.file, err.key, err.value) == (CAMPAIGN, "tank.heat_leak_w", "-5")
    assert "[0, 1e7]" in err.allowed
    done = cli("run", CAMPAIGN, "--out", str(tmp_path / "x"), "--instances", "8",
               "--set", "tank.heat_leak_w=-5")
    assert done.returncode == 2
    assert done.stderr.strip() == f"error: {err}"
    assert isinstance(err, ValueError) and isinstance(err, cryoslosh.CryosloshError)


def test_unknown_key_and_bad_option():
    with pytest.raises(cryoslosh.BadInputError) as e:
        cryoslosh.check(CAMPAIGN, sets=["tank.no_such_key=1"])
    assert e.value.key == "tank.no_such_key"
    with pytest.raises(cryoslosh.BadInputError, match="--backend warp: expected cpu, gpu or auto"):
        cryoslosh.run(CAMPAIGN, instances=4, backend="warp")
    with pytest.raises(cryoslosh.BadInputError, match="--shard 4/4"):
        cryoslosh.run(CAMPAIGN, instances=4, shard="4/4")
    with pytest.raises(cryoslosh.BadInputError, match="cannot read campaign"):
        cryoslosh.run("campaigns/missing.toml")


def test_dispersed_key_refused_like_the_cli(cli, tmp_path):
    with pytest.raises(cryoslosh.BadInputError) as e:
        cryoslosh.run(CAMPAIGN, instances=4, sets={"propellant.fill_fraction": 0.5})
    done = cli("run", CAMPAIGN, "--out", str(tmp_path / "x"), "--instances", "4",
               "--set", "propellant.fill_fraction=0.5")
    assert done.returncode == 2
    assert done.stderr.strip() == f"error: {e.value}"
