"""Shared fixtures: built-in mechanisms loaded once per session."""

from __future__ import annotations

import numpy as np
import pytest

import pinmob


@pytest.fixture(scope="session")
def puu() -> pinmob.Mechanism:
    return pinmob.load("3-PUU")


@pytest.fixture(scope="session")
def puu_flat() -> pinmob.Mechanism:
    return pinmob.load("3-PUU-flat")


@pytest.fixture(scope="session")
def puu_vertical() -> pinmob.Mechanism:
    return pinmob.load("3-PUU-vertical")


@pytest.fixture
def rng() -> np.random.Generator:
    return np.random.default_rng(20261122)


@pytest.fixture(scope="session")
def dask_cluster():
    """A real Dask LocalCluster of two worker processes (pinmob's worker set-up preloaded), shared by the session."""
    import logging

    from dask.distributed import Client, LocalCluster

    cluster = LocalCluster(
        n_workers=2,
        threads_per_worker=1,
        processes=True,
        host="127.0.0.1",
        dashboard_address="127.0.0.1:0",
        worker_dashboard_address="127.0.0.1:0",
        silence_logs=logging.CRITICAL,
        preload=["pinmob.engine.worker"],
    )
    client = Client(cluster)
    yield cluster
    client.close()
    cluster.close()
