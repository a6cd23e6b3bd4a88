"""An MJCF whose keyframes do not close (issue 31, item 5): a closed configuration is searched from each keyframe and
from ``qpos0``, the report says which start closed, and only a file where none closes is refused, naming its worst
closure.

The fixture ``tests/data/keyframes/fourbar_open_keys.xml`` is a planar four-bar (crank 0.1 m, coupler tip at
(0.28, 0.1) m, rocker 0.2 m, ground 0.3 m) closed by a ``connect`` between two sites, whose keyframes ``wide`` and
``folded`` and whose ``qpos0`` all miss. Truth by hand: 3 hinges, one point closure (3 rows) of which the one normal
to the plane is implied: rank 2, DoF 1; MuJoCo's own equality residuals vanish at the configuration pinmob found.
"""

from __future__ import annotations

import json
from pathlib import Path

import mujoco
import numpy as np
import pytest
from test_cad_gaps import pinmob_cli

import pinmob
from pinmob.exceptions import ClosureError

DATA = Path(__file__).parent / "data" / "keyframes"
OPEN_KEYS = DATA / "fourbar_open_keys.xml"


def equality_residual(path: Path, joint_values: dict[str, float]) -> float:
    """MuJoCo's largest equality residual (``efc_pos``) with the given joint values as ``qpos`` [m]."""
    m = mujoco.MjModel.from_xml_path(str(path))
    d = mujoco.MjData(m)
    for name, value in joint_values.items():
        d.qpos[m.jnt_qposadr[m.joint(name).id]] = value
    mujoco.mj_forward(m, d)
    eq = d.efc_type[: d.nefc] == mujoco.mjtConstraint.mjCNSTR_EQUALITY
    return float(np.abs(d.efc_pos[: d.nefc][eq]).max())


def test_no_keyframe_closes_as_given():
    """MuJoCo says so: each keyframe's and qpos0's residual is centimetres (the premise of the fixture)."""
    m = mujoco.MjModel.from_xml_path(str(OPEN_KEYS))
    names = ["crank", "coupler", "rocker"]
    for qpos in (m.qpos0, *m.key_qpos):
        assert equality_residual(OPEN_KEYS, dict(zip(names, qpos, strict=True))) > 1e-3


def test_a_closed_configuration_is_found_from_the_first_keyframe_and_named():
    """The CLI analyses the file (it refused, naming key 'wide', before): the method names the start that closed,
    MuJoCo's residuals vanish at the joint values found, and the counts are the hand counts."""
    done = pinmob_cli("analyze", str(OPEN_KEYS), "--json")
    assert done.returncode == 0, done.stderr
    doc = json.loads(done.stdout)
    assert doc["closed_configuration"]["method"].startswith("projection from 'wide'")
    assert (doc["nv"], doc["closure_rows"], doc["closure_rank"], doc["mechanism_dof"]) == (3, 3, 2, 1)
    assert equality_residual(OPEN_KEYS, doc["joint_values"]) < 1e-9
    text = pinmob_cli("analyze", str(OPEN_KEYS)).stdout
    assert "closed configuration: projection from 'wide', a start that does not close as given" in text


def test_the_keyframes_stay_starts_and_one_asked_for_is_checked_as_given():
    """The keyframes and qpos0 are starts, keyframes first; asking for one by name checks it as it is."""
    mech = pinmob.load(OPEN_KEYS)
    assert [(n, c.start) for n, c in mech.configurations.items()] == [
        ("wide", True),
        ("folded", True),
        ("reference", True),
    ]
    with pytest.raises(ClosureError, match="configuration 'wide' .* does not close"):
        pinmob.analyze(mech, "wide")
    report = pinmob.analyze(mech)
    assert report.mechanism_mobility.mechanism_dof == 1


def test_a_keyframe_that_closes_is_analysed_as_before(tmp_path):
    """A keyframe that closes is the configuration analysed (no search); the open one is a start after it."""
    found = json.loads(pinmob_cli("analyze", str(OPEN_KEYS), "--json").stdout)["joint_values"]
    closed = " ".join(repr(found[n]) for n in ("crank", "coupler", "rocker"))
    text = OPEN_KEYS.read_text().replace(
        '<key name="folded"', f'<key name="closed" qpos="{closed}"/>\n    <key name="x"'
    )
    path = tmp_path / "closed_key.xml"
    path.write_text(text)
    mech = pinmob.load(path)
    assert next(iter(mech.configurations)) == "closed" and not mech.configurations["closed"].start
    report = pinmob.analyze(mech)
    assert report.configuration == "closed" and report.mechanism_mobility.mechanism_dof == 1


def test_a_file_where_no_start_closes_is_refused_naming_the_starts_and_the_worst_closure(tmp_path):
    """Ground 0.5 m and the coupler's tip at (0.05, 0): crank, coupler and rocker reach at most
    0.1 + 0.05 + 0.2 = 0.35 < 0.5 m, so nothing closes. One line (exit 2), naming every start and the closure 'tip'."""
    text = OPEN_KEYS.read_text().replace('pos="0.3 0 0"', 'pos="0.5 0 0"').replace('pos="0.28 0.1 0"', 'pos="0.05 0 0"')
    path = tmp_path / "unclosable.xml"
    path.write_text(text)
    refused = pinmob_cli("analyze", str(path))
    assert refused.returncode == 2 and refused.stdout == ""
    line = refused.stderr.strip()
    assert "\n" not in line and "Traceback" not in line
    assert "nor from its starts that do not close as given ('wide', 'folded', 'reference')" in line
    assert line.endswith("at tip")
