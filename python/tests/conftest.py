"""Shared fixtures: the repository root (campaign paths are relative to it, as in the CLI's
metadata) and the `cryoslosh` CLI binary the Python results are compared with."""

from __future__ import annotations

import os
import shutil
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
CAMPAIGN = "campaigns/mhtb_selfpress.toml"


def cli_binary() -> str:
    """$CRYOSLOSH_BIN, else target/release/cryoslosh (under $CARGO_TARGET_DIR when set), else PATH."""
    if os.environ.get("CRYOSLOSH_BIN"):
        return os.environ["CRYOSLOSH_BIN"]
    target = Path(os.environ.get("CARGO_TARGET_DIR", ROOT / "target"))
    built = target / "release" / "cryoslosh"
    if built.is_file():
        return str(built)
    found = shutil.which("cryoslosh")
    if found is None:
        pytest.fail("no cryoslosh binary: build it with `cargo build --release` or set CRYOSLOSH_BIN")
    return found


@pytest.fixture(autouse=True)
def _in_root(monkeypatch: pytest.MonkeyPatch) -> None:
    """Run every test from the repository root, like the CLI commands of the README."""
    monkeypatch.chdir(ROOT)


@pytest.fixture
def cli():
    """Run the CLI; returns the completed process (not checked)."""

    def call(*args: str) -> subprocess.CompletedProcess:
        return subprocess.run([cli_binary(), *args], capture_output=True, text=True, cwd=ROOT)

    return call
