"""cryoslosh from Python: Monte Carlo dispersion campaigns of cryogenic propellant tanks.

Each function does what the ``cryoslosh`` command of the same name does, through the same Rust
library calls, and returns pyarrow tables (handed over through the Arrow C data interface). The
GIL is released while the engine integrates. Errors raise the classes of :mod:`cryoslosh.errors`,
one per CLI exit code, with the CLI's messages.
"""

from __future__ import annotations

import json
import os
from dataclasses import dataclass, field
from typing import Any, Dict, List, Optional, Sequence, Tuple, Union

import pyarrow as pa

from . import _native
from .errors import BadInputError, CryosloshError, RunFailedError, UntrustedError

__version__: str = _native.__version__

PathLike = Union[str, "os.PathLike[str]"]

__all__ = [
    "BadInputError",
    "CryosloshError",
    "Result",
    "RunFailedError",
    "Simulation",
    "UntrustedError",
    "VariantsResult",
    "check",
    "merge",
    "replay",
    "run",
    "simulate",
]


@dataclass(frozen=True)
class Result:
    """A finished run or merge: ``instances.parquet`` and ``statistics.parquet`` as tables and
    ``run.json`` as a dict."""

    instances: pa.Table
    statistics: pa.Table
    run_info: Dict[str, Any] = field(default_factory=dict)


@dataclass(frozen=True)
class VariantsResult:
    """A finished run or merge of a campaign with ``[[variants]]``: each variant's results (as
    ``DIR/variants/<name>/``, in the campaign's order: the first is the baseline), the paired
    differences against the baseline (``DIR/differences.parquet``) and ``DIR/run.json``."""

    variants: Dict[str, Result]
    differences: pa.Table
    run_info: Dict[str, Any] = field(default_factory=dict)

    @property
    def baseline(self) -> str:
        """The name of the baseline variant."""
        return next(iter(self.variants))


@dataclass(frozen=True)
class Simulation:
    """One simulated instance: its time history, its sampled inputs (key path → value; empty for
    the nominal) and the summary the CLI prints."""

    history: pa.Table
    inputs: Dict[str, float]
    summary: str


def _sets(sets: Optional[Union[Dict[str, Any], Sequence[str]]]) -> List[str]:
    """``--set`` overrides from ``{"tank.heat_leak_w": 40}`` or ``["tank.heat_leak_w=40"]``."""
    if sets is None:
        return []
    if isinstance(sets, dict):
        return [f"{k}={_value(v)}" for k, v in sets.items()]
    return [str(s) for s in sets]


def _value(v: Any) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    return str(v)


Raw = Tuple[
    Optional[pa.Table],
    Optional[pa.Table],
    str,
    Optional[str],
    List[Tuple[str, pa.Table, pa.Table, str]],
    Optional[pa.Table],
]


def _result(raw: Raw) -> Union[Result, VariantsResult]:
    instances, statistics, run_json, untrusted, variants, differences = raw
    result: Union[Result, VariantsResult]
    if differences is None:
        assert instances is not None and statistics is not None
        result = Result(instances, statistics, json.loads(run_json))
    else:
        result = VariantsResult(
            {name: Result(i, s, json.loads(r)) for name, i, s, r in variants},
            differences,
            json.loads(run_json),
        )
    if untrusted is not None:
        raise UntrustedError(
            f"{untrusted}: the statistics exclude them; see run.json and statistics.parquet",
            result,
        )
    return result


def run(
    campaign: PathLike,
    instances: Optional[int] = None,
    seed: Optional[int] = None,
    sets: Optional[Union[Dict[str, Any], Sequence[str]]] = None,
    backend: str = "cpu",
    threads: Optional[int] = None,
    *,
    shard: Optional[str] = None,
    out: Optional[PathLike] = None,
    chunk_size: Optional[int] = None,
    force: bool = False,
) -> Union[Result, VariantsResult]:
    """Run a dispersion campaign, as ``cryoslosh run CAMPAIGN --out DIR``.

    ``instances`` and ``seed`` default to the campaign's; ``sets`` are ``--set`` overrides;
    ``backend`` is ``cpu``, ``gpu`` or ``auto``; ``threads`` None or 0 takes one per core;
    ``shard`` is ``"I/N"``. With ``out`` the results directory is kept there (needed by
    :func:`replay` and :func:`merge`); without it a scratch directory is used and removed.
    A campaign with ``[[variants]]`` gives a :class:`VariantsResult` (every variant on the same
    instances, and the paired differences), with the files ``cryoslosh run`` writes.
    """
    raw = _native.run(
        os.fspath(campaign),
        out=None if out is None else os.fspath(out),
        instances=instances,
        seed=seed,
        sets=_sets(sets),
        backend=backend,
        threads=threads or 0,
        shard=shard,
        chunk_size=chunk_size,
        force=force,
    )
    return _result(raw)


def merge(
    dirs: Sequence[PathLike], out: PathLike, force: bool = False
) -> Union[Result, VariantsResult]:
    """Join shard directories into ``out``, as ``cryoslosh merge``: byte-identical to the
    unsharded run (a :class:`VariantsResult` for shards of a campaign with ``[[variants]]``)."""
    return _result(_native.merge([os.fspath(d) for d in dirs], os.fspath(out), force))


def check(
    campaign: PathLike, sets: Optional[Union[Dict[str, Any], Sequence[str]]] = None
) -> str:
    """Validate a campaign; the text ``cryoslosh check`` prints (resolved nominal, step plan)."""
    return _native.check(os.fspath(campaign), _sets(sets))


def simulate(
    campaign: PathLike,
    instance: Optional[int] = None,
    sets: Optional[Union[Dict[str, Any], Sequence[str]]] = None,
) -> Simulation:
    """Integrate the nominal (or instance ``instance`` of the campaign's dispersions), as
    ``cryoslosh simulate``; the history has the columns of the CLI's Parquet file."""
    history, inputs, summary = _native.simulate(os.fspath(campaign), instance, _sets(sets))
    return Simulation(history, dict(inputs), summary)


def replay(run_dir: PathLike, instance: int) -> Tuple[Optional[pa.Table], List[Tuple[str, float, float]]]:
    """Replay instance ``instance`` of the finished run in ``run_dir``, as ``cryoslosh simulate
    --run DIR --instance I``: its history (None when rejected) and the columns where the replay
    differs from its row (name, file value, replayed value); empty when bit-identical."""
    return _native.replay(os.fspath(run_dir), instance)
