"""A Dask LocalCluster with 2 workers and 4 shards gives the one-machine tables."""

from __future__ import annotations

import pytest

import cryoslosh
import cryoslosh.dask
from conftest import CAMPAIGN

distributed = pytest.importorskip("distributed")


def test_local_cluster_four_shards_equal_one_machine():
    whole = cryoslosh.run(CAMPAIGN, instances=40, seed=3)
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                  dashboard_address=None) as cluster:
        with distributed.Client(cluster) as client:
            r = cryoslosh.dask.run(CAMPAIGN, 40, client, shards=4, seed=3, threads=1)
    assert r.instances.equals(whole.instances)
    assert r.statistics.equals(whole.statistics)
    assert r.instances.schema.metadata == whole.instances.schema.metadata
    assert r.run_info["instances"] == 40
