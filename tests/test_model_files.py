"""The built-in model files: up to date with the catalog, listed by the CLI, builder and testing helpers."""

from __future__ import annotations

import json
import re
import subprocess
import sys
import tomllib
from pathlib import Path

import numpy as np
import pytest

import pinmob
from pinmob import catalog
from pinmob.builder import MechanismBuilder, polar, radial, rotation, symmetric_angles
from pinmob.cli import main
from pinmob.exceptions import ConfigurationError
from pinmob.mechanism_file import builtin_dir
from pinmob.testing import assert_mobility

MODELS = Path(__file__).resolve().parent.parent / "models"
NUMBER = re.compile(r"-?\d+(?:\.\d+)?(?:[eE][-+]?\d+)?")


def _split(text: str) -> tuple[list[str], np.ndarray]:
    """Text with numbers replaced by a marker, and the numbers (compared with a tolerance: solver digits)."""
    return NUMBER.split(text), np.array([float(x) for x in NUMBER.findall(text)])


def test_generated_models_are_up_to_date(tmp_path):
    """Regenerate every catalogued model into a temporary folder; each file in models/ must match it (numbers to
    1e-9, since closed configurations come from an iterative solve). Fix: ``python -m pinmob.catalog models``."""
    written = catalog.write_all(tmp_path)
    assert {p.stem for p in written} == set(catalog.CATALOG)
    for new in sorted(tmp_path.iterdir()):
        old = MODELS / new.name
        assert old.exists(), f"models/{new.name} is missing: run python -m pinmob.catalog models"
        (text_new, num_new), (text_old, num_old) = _split(new.read_text()), _split(old.read_text())
        assert text_new == text_old, f"models/{new.name} is out of date: run python -m pinmob.catalog models"
        assert num_new.shape == num_old.shape and np.allclose(num_new, num_old, rtol=0, atol=1e-9), new.name
    stale = {p.name for p in MODELS.glob("*.toml")} - {p.name for p in tmp_path.glob("*.toml")}
    assert not stale, f"models/ holds files no catalog entry writes: {stale}"


@pytest.mark.parametrize("stem", sorted(catalog.CATALOG))
def test_every_model_has_generic_and_expectations(stem):
    """Each model: at least two named configurations, one called generic, each with dof, motion_type, source."""
    doc = tomllib.loads((MODELS / f"{stem}.toml").read_text())
    confs = doc["configurations"]
    assert len(confs) >= 2 and doc.get("description")
    if stem != "3puu_flat":  # that geometry assembles only flat (see its description): no generic pose exists
        assert "generic" in confs
    for conf in confs.values():
        assert set(conf["expected"]) == {"dof", "motion_type", "source"}


def test_models_readme_lists_every_model():
    text = (MODELS / "README.md").read_text()
    for name in pinmob.builtin_models():
        assert f"`{name}`" in text, name
    assert "`6-UPS`" in text


# --------------------------------------------------------------------------- CLI


def test_cli_models_json(capsys):
    assert main(["models", "--json"]) == 0
    rows = json.loads(capsys.readouterr().out)
    by_name = {r["name"]: r for r in rows}
    assert set(by_name) == set(pinmob.builtin_models())
    bennett = by_name["Bennett"]
    assert [limb["name"] for limb in bennett["limbs"]] == ["X", "Y"]
    assert bennett["limbs"][0]["joints"] == ["X_j1", "X_j2"]
    assert bennett["configurations"]["generic"]["expected"] == {"dof": 1, "motion_type": "1H"}
    for row in rows:
        assert {"name", "limbs", "configurations"} <= set(row)
        for conf in row["configurations"].values():
            assert set(conf["expected"]) == {"dof", "motion_type"}


def test_cli_models_text(capsys):
    assert main(["models"]) == 0
    out = capsys.readouterr().out
    assert "five-bar: limbs A (2 joints), B (3 joints)" in out
    assert "    limb-B-stretched: expected 1 DoF 1R" in out


def test_cli_analyze_reports_agreement(capsys):
    assert main(["analyze", "Sarrus", "--config", "generic"]) == 0
    out = capsys.readouterr().out
    assert "Sarrus at 'generic': 1 DoF, 1T" in out
    assert "expected 1 DoF 1T" in out and "analysis agrees with it" in out


def test_cli_models_subprocess():
    run = subprocess.run(
        [sys.executable, "-m", "pinmob", "models", "--json"], capture_output=True, text=True, timeout=60
    )
    assert run.returncode == 0, run.stderr
    assert "3-RRR-spherical" in {r["name"] for r in json.loads(run.stdout)}


# --------------------------------------------------------------------------- builder


def test_layout_helpers():
    e, t = radial(np.pi / 2)
    np.testing.assert_allclose(e, [0, 1, 0], atol=1e-15)
    np.testing.assert_allclose(t, [-1, 0, 0], atol=1e-15)
    np.testing.assert_allclose(polar(2.0, np.pi, 0.5), [-2, 0, 0.5], atol=1e-15)
    np.testing.assert_allclose(symmetric_angles(4, 0.1), [0.1, 0.1 + np.pi / 2, 0.1 + np.pi, 0.1 + 1.5 * np.pi])
    np.testing.assert_allclose(rotation([0, 0, 2], np.pi / 2) @ [1, 0, 0], [0, 1, 0], atol=1e-15)


def test_builder_sketch_and_analyze():
    """A user's sketch: a planar 2-RRR (Sarrus-like check of the builder API) analysed without writing files."""
    b = MechanismBuilder("2-RRR", "two planar RRR limbs")
    for name, theta in zip("AB", symmetric_angles(2), strict=True):
        limb = b.limb(name)
        limb.revolute("r1", at=polar(0.3, theta), axis=[0, 0, 1], actuated=True)
        limb.revolute("r2", at=polar(0.2, theta + 0.5), axis=[0, 0, 1])
        limb.revolute("r3", at=polar(0.05, theta), axis=[0, 0, 1])
        limb.tip(at=[0, 0, 0])
    mech = b.mechanism()
    assert_mobility(
        mech, mech.neutral(), dof=3, motion_type="2T1R", directions={"T": [[1, 0, 0], [0, 1, 0]], "R": [[0, 0, 1]]}
    )


def test_urdf_limb_errors():
    ur5 = catalog._ur5_path()
    b = MechanismBuilder("arm")
    with pytest.raises(ConfigurationError, match="no link 'nope' in ur5_robot.urdf; valid: .*tool0"):
        b.urdf_limb("A", ur5, "base_link", "nope", (np.eye(3), [0, 0, 0]))
    with pytest.raises(ConfigurationError, match="not in the chain"):
        b.urdf_limb("A", ur5, "base_link", "tool0", (np.eye(3), [0, 0, 0]), actuated=["elbow"])
    limb = b.urdf_limb("A", ur5, "base_link", "tool0", (np.eye(3), [0, 0, 0]), actuated=["elbow_joint"])
    assert limb.joints[0] == "A_shoulder_pan_joint" and limb.actuated == ["A_elbow_joint"]


def test_installed_models_folder_holds_the_files():
    assert {p.name for p in builtin_dir().glob("*.toml")} >= {f"{s}.toml" for s in catalog.CATALOG}


# --------------------------------------------------------------------------- assert_mobility


def test_assert_mobility_failure_message():
    mech = pinmob.load("Sarrus")
    with pytest.raises(AssertionError) as info:
        assert_mobility(mech, "generic", dof=2, motion_type="1T1R", directions={"T": [[1, 0, 0]]})
    msg = str(info.value)
    assert "mobility of 'Sarrus' at 'generic' differs from the expectation" in msg
    assert "dof: expected 2, found 1" in msg
    assert "motion type: expected 1T1R, found 1T" in msg
    assert "T directions: expected span of ['[1, 0, 0]'], found ['[0, 0, 1]']" in msg
    assert re.search(
        r"singular values of the constraint wrenches \[.*\], tolerance [0-9.e-]+ \(rtol 1e-06 x largest\)", msg
    )


def test_assert_mobility_through_and_bad_kind():
    mech = pinmob.load("3-RRR-spherical")
    assert_mobility(mech, "generic", through=[0, 0, 0])
    with pytest.raises(AssertionError, match="axis misses the point"):
        assert_mobility(mech, "generic", through=[0, 0, 0.1])
    with pytest.raises(ValueError, match="valid: T, R, H"):
        assert_mobility(mech, "generic", directions={"X": [[1, 0, 0]]})
