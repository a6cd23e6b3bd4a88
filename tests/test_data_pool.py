"""The pool of ``pin.Data``: a finalizer that gives a Data back while the pool is busy in the same thread."""

from __future__ import annotations

import ast
import subprocess
import sys
import textwrap
from pathlib import Path

PACKAGE = Path(__file__).resolve().parent.parent / "pinmob"


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


def test_a_fresh_data_is_made_as_pin_data():
    """pinmob makes a fresh ``pin.Data`` as ``pin.Data(model)``: Pinocchio's ``model.createData()`` builds one and
    returns a copy of it (twice the work, the pool's ``acquire`` says). No ``model.createData()`` (nor
    ``<x>.model.createData()``) is called anywhere in the package (there were 11, in analysis, io and viewer)."""
    found = []
    for path in sorted(PACKAGE.rglob("*.py")):
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute) and node.func.attr == "createData":
                owner = node.func.value
                name = (
                    owner.id if isinstance(owner, ast.Name) else owner.attr if isinstance(owner, ast.Attribute) else ""
                )
                if name == "model" and not node.args:
                    found.append(f"{path.relative_to(PACKAGE.parent)}:{node.lineno}")
    assert not found, f"model.createData() (a copy of a new Data) where pin.Data(model) will do: {found}"
