"""An installed pinmob writes nothing inside its own package (its numba cache goes to a per-user folder); its wheel builds cleanly."""

from __future__ import annotations

import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

import pinmob
from pinmob.io import builtin_dir

SCRIPT = """
import contextlib, io
import pinmob
from pinmob.analysis.batch.batch_analysis import analyze_batch
from pinmob.analysis.batch.batch_kernel import ranks
from pinmob.cli import main

mech = pinmob.load("3-PUU")
print(pinmob.__file__)
print(analyze_batch(mech, pinmob.closed_configuration(mech, "generic")[None]).dof.tolist())
print(sum(ranks.stats.cache_hits.values()))
with contextlib.redirect_stdout(io.StringIO()):  # the CLI's paths too: analysis, scan with a plot
    assert main(["analyze", "3-PUU"]) == 0
    assert main(["scan", "3-PUU", "--from", "generic", "--to", "offset", "-n", "3", "--plot", "s.png", "--force"]) == 0
"""


def _files(folder: Path) -> dict[str, int]:
    return {str(p.relative_to(folder)): p.stat().st_mtime_ns for p in sorted(folder.rglob("*"))}


@pytest.fixture
def package(tmp_path) -> Path:
    """A fresh copy of the installed package (pinmob/ with its models/, as pip lays it out), no __pycache__."""
    package = tmp_path / "site" / "pinmob"
    shutil.copytree(Path(pinmob.__file__).parent, package, ignore=shutil.ignore_patterns("__pycache__"))
    if not (package / "models").is_dir():  # editable install: the models sit in the checkout's models/
        shutil.copytree(builtin_dir(), package / "models", ignore=shutil.ignore_patterns("__pycache__"))
    return package


def run_batch(package: Path, cache_home: Path) -> int:
    """Run the compiled batch path (and the CLI's analyze and scan) on the copy in a new process; returns the
    loop's cache hits there."""
    env = {k: v for k, v in os.environ.items() if k not in ("NUMBA_CACHE_DIR", "PYTHONPATH")}
    env |= {"PYTHONPATH": str(package.parent), "XDG_CACHE_HOME": str(cache_home), "PYTHONDONTWRITEBYTECODE": "1"}
    run = subprocess.run(
        [sys.executable, "-c", SCRIPT], capture_output=True, text=True, env=env, cwd=package.parent, timeout=300
    )
    assert run.returncode == 0, run.stderr
    where, dof, hits = run.stdout.split()
    assert Path(where).parent == package and dof == "[3]"
    return int(hits)


def test_compiled_loop_is_cached_outside_the_package(package, tmp_path):
    """The compiled batch path, twice in new processes: no file appears or changes under pinmob/ (numba's
    ``cache=True`` wrote ``pinmob/__pycache__/batch._ranks-*.nbi`` there, which then shadowed a later editable
    install of the same environment), the cache is in ``$XDG_CACHE_HOME/pinmob/numba`` and the second process
    loads the loop from it."""
    before = _files(package)
    cache = tmp_path / "cache"
    assert [run_batch(package, cache), run_batch(package, cache)] == [0, 1]
    assert _files(package) == before
    assert sorted(p.name.split("-")[0] for p in (cache / "pinmob" / "numba").rglob("*.nbi")) == [
        "batch_kernel.ranks",
        "batch_kernel.stack_columns",
        "batch_newton_kernel.damped_steps",  # the scan's batched predictor (a pose path of the 3-PUU)
        "batch_newton_kernel.iterate",
        "batch_newton_kernel.log3",
        "batch_newton_kernel.pose_errors",
        "batch_newton_kernel.rpy_matrix",
        "batch_newton_kernel.solve_stack",  # the whole Newton loop in one call, the kernels above inside it
        "batch_newton_kernel.step_structure",  # the damped steps' sparsity, once per solve
        "batch_newton_kernel.wrap_and_check",
        "batch_stopping.advance",
        "block_svd.block_svd",  # the single-sample solve's SVD, a block a limb
        "jacobi.column_rank",  # the kernels' Jacobi SVDs
        "jacobi.complete",
        "jacobi.orthogonalize",
        "jacobi.rotation",
        "jacobi.round_robin",
        "jacobi.span",
        "kinematics_kernel._axis_rotation",  # the predictor's compiled frame kinematics (model/compiled_kinematics)
        "kinematics_kernel._column",
        "kinematics_kernel._quaternion",
        "kinematics_kernel._unit_columns",
        "kinematics_kernel.difference_kernel",  # pin.difference, compiled into the secant moves
        "kinematics_kernel.frames_kernel",
        "kinematics_kernel.integrate_kernel",  # pin.integrate, compiled into solve_stack
        "pose_solve_kernel._keep",  # the scan's single-sample solver at a platform pose (its seeding walk)
        "pose_solve_kernel._residual",
        "pose_solve_kernel._scaled_svd",
        "pose_solve_kernel._step_direction",
        "pose_solve_kernel._trial",
        "pose_solve_kernel._work",
        "pose_solve_kernel.solve_pose",
        "rpy_kernel.matrix_rpy",  # the batch rows' angles (pin.rpy.matrixToRpy of a stack)
        "se3_log._add_half_skew",
        "se3_log.log6_jlog6",
        "secant_kernel.close_moved",  # the predictor's moved starts, solve and check in one call
        "secant_kernel.move_length",
        "secant_kernel.short_move",
    ]


PREDICTOR = """
import numpy as np
import pinmob
from pinmob.assembly.batched.batch_newton_kernel import solve_stack
from pinmob.scan import path_spec, scan

mech = pinmob.load("3-PUU")
rows = list(scan(mech, path_spec(mech, "generic", "offset", 3)))
print(sum(solve_stack.stats.cache_hits.values()), len(rows))
"""


def test_an_edit_of_a_function_a_compiled_loop_calls_recompiles_the_loop(package, tmp_path):
    """The predictor's compiled loop (``solve_stack``, through ``iterate``) calls ``batch_stopping.advance`` (another
    file), compiled into it.

    numba stamps a cached function with its own file: after an edit of batch_stopping.py alone, the next process
    loaded the old iteration from the cache (a reviewer's run: the numpy path took the edited stopping rule, the
    compiled one the old). Now the stamp covers the files of the compiled functions it calls: the edit recompiles."""
    env = {k: v for k, v in os.environ.items() if k not in ("NUMBA_CACHE_DIR", "PYTHONPATH")}
    env |= {
        "PYTHONPATH": str(package.parent),
        "XDG_CACHE_HOME": str(tmp_path / "cache"),
        "PYTHONDONTWRITEBYTECODE": "1",
    }

    def hits() -> int:
        run = subprocess.run(
            [sys.executable, "-c", PREDICTOR], capture_output=True, text=True, env=env, cwd=package.parent, timeout=300
        )
        assert run.returncode == 0, run.stderr
        found, rows = run.stdout.split()
        assert int(rows) >= 3
        return int(found)

    assert hits() == 0 and hits() > 0  # compiled, then loaded from the cache
    stopping = package / "assembly" / "batched" / "batch_stopping.py"
    stopping.write_text(stopping.read_text() + "\n# edited\n")
    assert hits() == 0  # compiled again, not the old code from the cache


def test_unwritable_cache_folder_means_no_disk_cache(package, tmp_path):
    """When the cache folder cannot be created (here ``$XDG_CACHE_HOME`` is a file), the loop is compiled in
    the process and still nothing is written under pinmob/."""
    before = _files(package)
    blocker = tmp_path / "not-a-folder"
    blocker.write_text("")
    assert run_batch(package, blocker) == 0
    assert _files(package) == before and blocker.read_text() == ""


def test_the_wheel_builds_without_warnings_and_ships_the_licence_and_the_panel(tmp_path):
    """`pip install .` builds a wheel with no setuptools warning (a folder of data Python sees as a package, absent
    from the packages list, used to warn), carrying LICENSE and the viewer panel's script and style."""
    root = Path(__file__).resolve().parent.parent
    source = tmp_path / "src"
    for name in ("pinmob", "models"):
        shutil.copytree(root / name, source / name, ignore=shutil.ignore_patterns("__pycache__"))
    for name in ("pyproject.toml", "README.md", "LICENSE"):
        shutil.copy(root / name, source / name)
    run = subprocess.run(
        [sys.executable, "-m", "pip", "wheel", "--no-deps", "-v", "-w", str(tmp_path / "dist"), str(source)],
        capture_output=True, text=True, timeout=600,
    )  # fmt: skip
    assert run.returncode == 0, run.stderr[-2000:]
    warned = re.compile(r"\.py:\d+: \w*Warning: ")  # a Python warning of the build backend (setuptools)
    warnings = [line.strip() for line in (run.stdout + run.stderr).splitlines() if warned.search(line)]
    assert not warnings, "\n".join(warnings)
    import zipfile

    (wheel,) = (tmp_path / "dist").glob("pinmob-*.whl")
    names = zipfile.ZipFile(wheel).namelist()
    assert any(n.endswith("licenses/LICENSE") for n in names)
    assert {"pinmob/viewer/static/panel.js", "pinmob/viewer/static/panel.css"} <= set(names)
    # every module is shipped: a subpackage missing from pyproject's packages list is left out of the wheel
    # (five were, and a regular install could not import pinmob)
    modules = {p.relative_to(root).as_posix() for p in (root / "pinmob").rglob("*.py") if "__pycache__" not in p.parts}
    assert not sorted(modules - set(names)), f"modules left out of the wheel: {sorted(modules - set(names))}"
