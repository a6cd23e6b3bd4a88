"""The pool of ``pin.Data``: a finalizer that gives a Data back while the pool is busy in the same thread."""

from __future__ import annotations

import subprocess
import sys
import textwrap


def test_a_finalizer_run_while_the_pool_is_locked_does_not_hang():
    """The garbage collector may run a configuration's finalizer (``release``) in the middle of an allocation made
    while the same thread holds the pool's lock: here the owner is dropped inside the lock, which runs the
    finalizer at once. It used to wait for the lock forever (a finite analysis hung); now the Data is dropped.
    In a process of its own, bounded in time: a hang fails the test instead of stopping the suite."""
    code = textwrap.dedent("""
        import pinocchio as pin
        from pinmob.model import data_pool

        model = pin.buildSampleModelHumanoid()

        class Owner:
            pass

        owner = Owner()
        data_pool.release_with(owner, model, model.createData())
        with data_pool._LOCK:
            del owner  # the last reference: the finalizer runs here, the lock held
        data_pool.release_with(Owner(), model, model.createData())  # dropped at once, the lock free: pooled
        print(len(data_pool._POOL[model]))
    """)
    run = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60)
    assert run.returncode == 0, run.stderr
    assert run.stdout.split() == ["1"]  # the first Data dropped (the pool was busy), the second kept
