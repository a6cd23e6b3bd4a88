"""The pool of ``pin.Data``: a finalizer that gives a Data back while the pool is busy in the same thread, and a
configuration that gives its Data back early (parked) and reads its kinematics again."""

from __future__ import annotations

import ast
import subprocess
import sys
import textwrap
import threading
from pathlib import Path

import numpy as np
import pinocchio as pin

import pinmob
from pinmob.analysis import Configuration, closed_chain, generic_constraint_rank, generic_states
from pinmob.scan import grid_spec

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
        print(len(data_pool.spares(model)))
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


def _kinematics(model: pin.Model, q: np.ndarray) -> pin.Data:
    """Pinocchio's own kinematics at q in a new Data: the joint Jacobians and the frame placements."""
    data = pin.Data(model)
    pin.computeJointJacobians(model, data, q)
    pin.updateFramePlacements(model, data)
    return data


def _same_kinematics(data: pin.Data, truth: pin.Data) -> bool:
    frames = all(np.array_equal(a.homogeneous, b.homogeneous) for a, b in zip(data.oMf, truth.oMf))
    return frames and np.array_equal(np.array(data.J), np.array(truth.J))


def test_a_parked_configuration_reads_its_kinematics_again():
    """Parked, a configuration's Data goes back to the pool; the next configuration made takes that very Data and
    overwrites it; read again, the parked one's kinematics are Pinocchio's at its q (computed here in a Data of
    their own), bit for bit, and what it cached is the same object. A copy (``with_name``) reads its original's
    Data, and parking the copy parks the original."""
    mech = pinmob.load("6-UPS")
    model = mech.model
    conf = Configuration(mech, "home")
    truth = _kinematics(model, conf.q)
    chain = closed_chain(conf, 1e-9)
    lent = conf.data
    conf.park()
    other = Configuration.unchecked(mech, pin.randomConfiguration(model, -np.ones(model.nq), np.ones(model.nq)))
    assert other.data is lent  # the parked Data, now holding another configuration's kinematics
    assert not _same_kinematics(lent, truth)
    assert _same_kinematics(conf.data, truth)
    assert closed_chain(conf, 1e-9) is chain
    copy = conf.with_name("copy")
    assert copy.data is conf.data
    copy.park()
    Configuration.unchecked(mech, other.q)  # takes the Data the copy's original gave back
    assert _same_kinematics(copy.data, truth) and copy.data is conf.data


def test_the_generic_states_hold_no_data_once_used():
    """The 3-PUU's generic states (eight configurations, each with a ``pin.Data`` held for the life of the mechanism
    before: a 6-UPS's twelve weighed about 3 MB each) give their Data back once the generic rank and a grid's held
    coordinates (its rotations: the same at every generic state) have read them; another thread has states of its
    own (its parking cannot take the kinematics from under this one's), at the same configurations."""
    mech = pinmob.load("3-PUU")
    assert generic_constraint_rank(mech) == 3  # three constraint moments: a translational platform
    spec = grid_spec(mech, "generic", [("x", -0.05, 0.05, 3), ("y", -0.05, 0.05, 3)])
    assert [name for name, _ in spec.held] == ["z", "roll", "pitch", "yaw"]  # the rotations: constant coordinates
    states = generic_states(mech)
    assert len(states) == 8
    assert all(s.__dict__["_data"] is None for s in states)  # parked (the Data is the pool's again)
    theirs: list[Configuration] = []
    worker = threading.Thread(target=lambda: theirs.extend(generic_states(mech)))
    worker.start()
    worker.join()
    assert not {id(s) for s in states} & {id(s) for s in theirs}
    assert all(np.array_equal(a.q, b.q) for a, b in zip(states, theirs))
    assert generic_states(mech)[0] is states[0]  # this thread's are cached


def test_a_scan_makes_hardly_a_new_data(monkeypatch):
    """A 6-UPS ``pin.Data`` takes about 0.5 ms to make (its nv is 36), and a 21 x 21 grid's whole run used to make
    twelve: each predictor's problem and each frame-kinematics engine made one it never used with the compiled
    kinematics, and the batch's platform poses one per group. Now they are made where Pinocchio's kinematics need
    them, or borrowed from the model's pool: the grid's set-up and its scan make at most three new ones, with the
    compiled kinematics or Pinocchio's (11 before, counted here the same way)."""
    from pinmob.scan.scan_run import scan_table

    mech = pinmob.load("6-UPS")
    made: list[int] = []
    original = pin.Data
    monkeypatch.setattr(pin, "Data", lambda *args: made.append(1) or original(*args))
    spec = grid_spec(mech, "home", [("x", -0.03, 0.03, 5), ("y", -0.03, 0.03, 5)])
    table = scan_table(mech, spec)
    monkeypatch.undo()
    assert len(table) == 25 and all(table.column("reachable"))
    assert len(made) <= 3, f"{len(made)} pin.Data made by a 5 x 5 scan of the 6-UPS"


def test_a_spare_made_before_the_model_grew_is_not_lent():
    """A reader borrows a Data while it builds a model (``motion_subspaces`` checks the axes, then the URDF's loop
    joints add frames): a spare made before is one frame short, and Pinocchio's algorithms, which do not check its
    sizes, wrote past its end (an analysis raised ``IndexError``, a CLI run died of a segmentation fault). The pool
    lends only a Data that fits the model as it is now."""
    from pinmob.model import borrowed

    model = pin.buildSampleModelManipulator()
    with borrowed(model) as data:
        assert len(data.oMf) == model.nframes
    model.addFrame(pin.Frame("added", 1, 0, pin.SE3.Identity(), pin.FrameType.OP_FRAME))
    with borrowed(model) as data:
        assert len(data.oMf) == model.nframes and len(data.oMi) == model.njoints
        pin.framesForwardKinematics(model, data, pin.neutral(model))
