"""Small-matrix linear algebra on one BLAS thread: the limit holds inside analyses and is undone after."""

from __future__ import annotations

import sys
import threading

import pytest
from threadpoolctl import threadpool_info, threadpool_limits

import pinmob
from pinmob.analysis.batch.batch_analysis import analyze_batch
from pinmob.blas import one_blas_thread


def blas_threads() -> list[int]:
    return [lib["num_threads"] for lib in threadpool_info() if lib["user_api"] == "blas"]


@pytest.fixture
def two_threads():
    if not blas_threads():
        pytest.skip("no BLAS library that threadpoolctl can control")  # not counted as passing
    with threadpool_limits(2, user_api="blas"):
        if set(blas_threads()) != {2}:
            pytest.skip("this BLAS cannot be set to two threads")
        yield


def test_one_thread_inside_restored_after(two_threads):
    with one_blas_thread:
        assert set(blas_threads()) == {1}
        with one_blas_thread:  # nested: still one, and the inner exit does not restore
            assert set(blas_threads()) == {1}
        assert set(blas_threads()) == {1}
    assert set(blas_threads()) == {2}


def test_restored_after_an_error(two_threads):
    with pytest.raises(pinmob.ConfigurationError), one_blas_thread:
        pinmob.analyze(pinmob.load("3-PUU"), "no such configuration")
    assert set(blas_threads()) == {2}


def test_held_until_the_last_thread_leaves(two_threads):
    """Another thread leaving its analysis does not undo the limit this one still needs."""
    done = []

    def worker() -> None:
        with one_blas_thread:
            done.append(set(blas_threads()))

    with one_blas_thread:
        t = threading.Thread(target=worker)
        t.start()
        t.join()
        assert done == [{1}]
        assert set(blas_threads()) == {1}
    assert set(blas_threads()) == {2}


@pytest.mark.parametrize("name", ["3-PUU", "6-UPS"])
def test_analyses_run_on_one_blas_thread(two_threads, name):
    """Every rank decision of a whole report, a batch and an assembly runs on one BLAS thread; then the user's 2."""
    mech = pinmob.load(name)
    seen: list[list[int]] = []

    def watch(frame, event, arg):  # noqa: ANN001, ANN202 (sys.setprofile's signature)
        if event == "call" and frame.f_code.co_name == "decide_rank":
            seen.append(blas_threads())

    sys.setprofile(watch)
    try:
        report = pinmob.analyze(mech, "generic", paper=True)
        report.to_dict()
        q = pinmob.assemble_pose(mech, report.state.frame_placement(mech.platform_id), report.state.q)
        analyze_batch(mech, q[None, :], singular_values=True)
    finally:
        sys.setprofile(None)
    assert len(seen) > 20
    assert all(set(threads) == {1} for threads in seen), seen
    assert set(blas_threads()) == {2}
