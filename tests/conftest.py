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


def start_cluster():
    """A real Dask LocalCluster of two worker processes (pinmob's worker set-up preloaded), and its client."""
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
        preload=["pinmob.parallel.worker"],
    )
    return cluster, Client(cluster)


@pytest.fixture(scope="session")
def _dask_session():
    """The session's cluster, in a list so that a test's check can replace it."""
    held = [start_cluster()]
    yield held
    cluster, client = held[0]
    client.close()
    cluster.close()


@pytest.fixture
def dask_cluster(_dask_session):
    """The session's LocalCluster, with its two workers up: a worker lost by an earlier test (its nanny
    restarts it) is waited for, and a cluster whose workers do not come back within a minute is replaced,
    so that one test's lost worker does not fail every later cluster test."""
    cluster, client = _dask_session[0]
    try:
        client.wait_for_workers(2, timeout=60)
    except Exception:  # TimeoutError, or a scheduler that is gone: start again
        for stop in (client.close, cluster.close):
            try:
                stop()
            except Exception:  # a broken cluster may fail to close: a new one is started all the same
                pass
        _dask_session[0] = start_cluster()
        cluster = _dask_session[0][0]
    return cluster
