"""Campaigns across a Dask cluster: one task per shard, each calling the engine in-process, then
an exact merge on the client.

Each task runs ``cryoslosh run --shard I/N`` into a scratch directory on its worker and sends the
shard's files back as bytes, so workers need no shared output filesystem; the client writes them
out and merges them (``cryoslosh merge``), which gives the bytes of the one-machine run. Every
worker must read the campaign (and any excitation table it names) at the same path as the
client: the path is part of the results' metadata.
"""

from __future__ import annotations

import os
import tempfile
from pathlib import Path
from typing import Any, Dict, List, Optional, Sequence, Union

import cryoslosh
from cryoslosh import PathLike, Result, UntrustedError, VariantsResult


def _shard_files(
    campaign: str,
    instances: Optional[int],
    seed: Optional[int],
    sets: List[str],
    index: int,
    count: int,
    threads: Optional[int],
) -> Dict[str, bytes]:
    """Run shard ``index`` of ``count`` on this worker; its results directory as {relative path: bytes}."""
    with tempfile.TemporaryDirectory(prefix="cryoslosh-shard-") as tmp:
        out = Path(tmp) / f"shard-{index}"
        try:
            cryoslosh.run(
                campaign,
                instances=instances,
                seed=seed,
                sets=sets,
                threads=threads,
                shard=f"{index}/{count}",
                out=out,
            )
        except UntrustedError:
            pass  # the shard's files are written; the merge judges the whole campaign
        return {
            str(p.relative_to(out)): p.read_bytes() for p in sorted(out.rglob("*")) if p.is_file()
        }


def run(
    campaign: PathLike,
    instances: Optional[int],
    client: Any,
    shards: Optional[int] = None,
    *,
    seed: Optional[int] = None,
    sets: Optional[Union[Dict[str, Any], Sequence[str]]] = None,
    threads: Optional[int] = None,
    out: Optional[PathLike] = None,
) -> Union[Result, VariantsResult]:
    """Run ``campaign`` as ``shards`` Dask tasks on ``client`` (a ``distributed.Client``) and
    merge them exactly: the tables equal those of :func:`cryoslosh.run` on one machine.

    ``shards`` defaults to the number of workers; ``threads`` per task to every core of its
    worker. With ``out`` the merged results directory is kept there.
    """
    if shards is None:
        shards = max(1, len(client.scheduler_info().get("workers", {})))
    if shards < 1:
        raise cryoslosh.BadInputError(f"shards = {shards}: expected at least 1")
    path = os.fspath(campaign)
    overrides = cryoslosh._sets(sets)
    futures = client.map(
        _shard_files,
        [path] * shards,
        [instances] * shards,
        [seed] * shards,
        [overrides] * shards,
        list(range(shards)),
        [shards] * shards,
        [threads] * shards,
        pure=False,
    )
    parts: List[Dict[str, bytes]] = client.gather(futures)
    with tempfile.TemporaryDirectory(prefix="cryoslosh-merge-") as tmp:
        dirs = []
        for index, files in enumerate(parts):
            d = Path(tmp) / f"shard-{index}"
            for rel, data in files.items():
                (d / rel).parent.mkdir(parents=True, exist_ok=True)
                (d / rel).write_bytes(data)
            dirs.append(d)
        merged = Path(tmp) / "merged" if out is None else Path(os.fspath(out))
        return cryoslosh.merge(dirs, merged)
