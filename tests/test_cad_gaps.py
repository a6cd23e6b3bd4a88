"""CAD files whose loops miss by about a micron analyse with the one flag their error names.

Fixtures (``tests/data/cad_gaps``, written by its ``make_cad_gaps.py``): a spherical 3-RRR in
onshape-to-robot's URDF convention whose closing frames can never meet better than 1.0 and 0.6 um, and a
five-bar-legged quadruped (MJCF, ``<connect site1 site2>``) whose keyframe ``stand`` misses by 1.04 um.
Each is run as a user runs it (the CLI in a subprocess); the flag is read from the error line, the file is
analysed again with it, and the answer is checked against a count by hand and, for the MJCF, MuJoCo's rank.
"""

from __future__ import annotations

import json
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from test_third_party import mujoco_at

import pinmob
from pinmob.assembly.closure_miss import accepting_tol

DATA = Path(__file__).parent / "data" / "cad_gaps"
FLAG = re.compile(r"(--closure-tol) (\S+) \(Python: closure_tol=(\S+)\) would accept it$")


def pinmob_cli(*args: str) -> subprocess.CompletedProcess[str]:
    """``python -m pinmob ARGS`` in a subprocess, as a user runs it."""
    return subprocess.run(
        [sys.executable, "-m", "pinmob", *args], capture_output=True, text=True, timeout=600, check=False
    )


def suggested(stderr: str) -> list[str]:
    """The one flag the error line names, with its value: ``['--closure-tol', '2e-05']``."""
    assert stderr.count("\n") == 1 and stderr.startswith("pinmob: error: "), stderr
    match = FLAG.search(stderr.strip())
    assert match, stderr
    assert match.group(2) == match.group(3)
    return [match.group(1), match.group(2)]


def test_spherical_urdf_with_a_cad_gap_analyses_with_the_flag_its_error_names():
    """Every axis of the spherical 3-RRR passes through one centre C, so every body turns about C: the closing
    points of legs 2 and 3 stay on concentric spheres 1.0 and 0.6 um apart and no configuration closes better.
    The search for a closed configuration used to ignore --closure-tol (refused at every value); now the error
    names the value that accepts the 1.0 um miss (relative to L, as the tolerance), and with it:

    by hand, nv 7 (leg 1: 3 hinges to the platform; legs 2, 3: 2 hinges each), 2 point closures (6 rows). A
    closing point lies on the platform's hinge axis of its leg, through C: the relative motion of the two bodies
    is a rotation about C, so the point closure leaves exactly the rotation about that axis (a hinge), and its
    radial row is implied (the relative velocity of two points on a line through C is normal to it). The
    platform's angular velocity is free (each leg's three axes are independent): DoF 3, rank 4, 2 redundant."""
    path = DATA / "spherical_3rrr" / "robot.urdf"
    refused = pinmob_cli("analyze", str(path), "--json")
    assert refused.returncode == 2
    flag = suggested(refused.stderr)
    assert "leg2: 1.00e-06 m" in refused.stderr and "--relax" not in refused.stderr
    done = pinmob_cli("analyze", str(path), "--json", *flag)
    assert done.returncode == 0, done.stderr
    doc = json.loads(done.stdout)
    tol = float(flag[1])
    assert 1.0e-6 / doc["length_scale"] < tol < 3 * 1.0e-6 / doc["length_scale"]  # the miss, relative to L
    assert (doc["nv"], doc["closure_rows"]) == (7, 6)
    assert (doc["mechanism_dof"], doc["redundant_constraints"]) == (3, 2)
    assert doc["ambiguous_ranks"] == []  # the radial rows are exactly implied: no singular value near the tolerance


def mujoco_rank(path: Path, joint_values: dict[str, float | list[float]], rtol: float) -> tuple[int, int, np.ndarray]:
    """(nv, rank, singular values) of MuJoCo's equality rows (efc_J) at the given joint values."""
    m, d, eq = mujoco_at(path, joint_values)
    s = np.linalg.svd(d.efc_J[: d.nefc * m.nv].reshape(d.nefc, m.nv)[eq], compute_uv=False)
    return m.nv, int(np.count_nonzero(s > rtol * s[0])), s


def test_mjcf_keyframe_with_a_cad_gap_analyses_with_the_flag_its_error_names():
    """The quadruped's keyframe misses by 1.04 um (1.2e-5 L): refused at the default and at --closure-tol 1e-5
    (as a user tries), each time naming the value that accepts it and listing 3 of the 4 residuals, the
    worst first; the flag read from the error is accepted.

    By hand: nv 22 (free base 6, 4 legs x 4 hinges), 4 point closures (12 rows). Each leg is a planar five-bar
    (hinges about the torso's y): 2 independent rows, the one normal to its plane implied: rank 8, DoF 14,
    4 redundant. MuJoCo's efc_J at the same joint values says the same once the singular values the 1 um miss
    creates (below 1e-4 of the largest: the base's turn moves the two missing points apart) are not counted."""
    path = DATA / "legged" / "robot.xml"
    flags = []
    for extra in ([], ["--closure-tol", "1e-5"]):
        refused = pinmob_cli("analyze", str(path), "--config", "stand", "--json", *extra)
        assert refused.returncode == 2
        flags.append(suggested(refused.stderr))
        assert "equality#0: 1.04e-06 m" in refused.stderr and "equality#3" not in refused.stderr
    assert "4 of 4 above the tolerance 1e-06" in pinmob_cli("analyze", str(path), "--config", "stand").stderr
    assert flags[0] == flags[1]
    done = pinmob_cli("analyze", str(path), "--config", "stand", "--json", *flags[0])
    assert done.returncode == 0, done.stderr
    doc = json.loads(done.stdout)
    assert 1.04e-6 / doc["length_scale"] < float(flags[0][1]) < 3 * 1.04e-6 / doc["length_scale"]
    assert (doc["nv"], doc["closure_rows"], doc["mechanism_dof"], doc["redundant_constraints"]) == (22, 12, 14, 4)
    nv, rank, s = mujoco_rank(path, doc["joint_values"], 1e-4)
    assert nv - rank == 14 and s[rank] < 1e-4 * s[0] < 1e-2 * s[rank - 1]  # a clear gap at MuJoCo's rank 8
    assert doc["ambiguous_ranks"] == []


@pytest.mark.parametrize(
    ("miss", "tol"), [(1.42e-6, 2e-6), (1.04e-6, 2e-6), (1.2e-5, 2e-5), (9.6e-6, 2e-5), (4e-7, 1e-6), (3e-4, 4e-4)]
)
def test_the_suggested_tolerance_is_the_miss_rounded_up(miss, tol):
    """One significant digit, rounded up from 1.05 x the miss (so that the rerun accepts the same miss)."""
    assert accepting_tol(miss) == tol


def test_no_tolerance_is_suggested_for_loops_that_do_not_close():
    """A miss beyond CAD accuracy (1e-3 L) is not a gap to accept: no tolerance is suggested."""
    assert accepting_tol(2e-3) is None and accepting_tol(float("nan")) is None


def test_a_closure_tolerance_beyond_a_cad_gap_is_refused():
    """--closure-tol stops where a miss stops being a CAD gap (1e-3): at 0.1 a four-bar open by 0.09 L was analysed
    as closed and came out with 3 DoF (the loop open, its rank 1 of 3)."""
    four_bar = str(Path(__file__).parent / "data" / "fourbar.toml")
    refused = pinmob_cli("analyze", four_bar, "--closure-tol", "0.1", "--joints", "crank=0.05")
    assert refused.returncode == 2 and refused.stderr.count("\n") == 1 and "Traceback" not in refused.stderr
    assert "--closure-tol must be a finite number in [1e-14, 0.001]" in refused.stderr
    with pytest.raises(pinmob.ConfigurationError, match=r"in \[1e-14, 0\.001\]"):
        pinmob.analyze(pinmob.load(four_bar), "home", closure_tol=0.01)


#: the built-in spherical 3-RRR's joint values rounded to 5 digits: the loops miss by 2.3e-6 m and 1e-5 rad
ROUNDED = (
    "A_r1=0.1,A_r2=-0.14742,A_r3=0.016424,B_r1=-0.1,B_r2=0.20041,B_r3=-0.15103,C_r1=0.1,C_r2=-0.032098,C_r3=-0.016722"
)


def test_joint_values_that_miss_by_a_cad_gap_name_the_flag_and_keep_the_generic_ranks():
    """Every joint value given, rounded (as a user copies them): the error names the --closure-tol that accepts the
    miss (it listed 12 residuals and no flag); with it, 3 DoF 3R (by hand: the agile-eye type), and the constraint
    is not singular: the generic rank is estimated on exactly closed samples at the asked tolerance (at the raised
    one, sqrt(2.5e-4) = 0.016 called limbs singular in random samples: 'generic 4', a constraint singularity)."""
    refused = pinmob_cli("analyze", "3-RRR-spherical", "--joints", ROUNDED)
    flag = suggested(refused.stderr)
    assert refused.returncode == 2 and "forward kinematics" in refused.stderr
    doc = json.loads(pinmob_cli("analyze", "3-RRR-spherical", "--joints", ROUNDED, *flag, "--json").stdout)
    assert (doc["dof"], doc["motion_type"]) == (3, "3R")
    sing = doc["singularity"]
    assert sing["classes"] == [] and sing["generic_rank"] == 3
