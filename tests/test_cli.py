"""The command line: models, analyze (text, JSON, paper view)."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

import pinmob
from pinmob.cli import main
from pinmob.exceptions import ConfigurationError
from pinmob.mobility import paper_view

DATA = Path(__file__).parent / "data"

JSON_KEYS = {
    "mechanism",
    "configuration",
    "dof",
    "motion_type",
    "translations",
    "rotations",
    "screws",
    "motions",
    "free_twists",
    "constraint_wrenches",
    "constraint_rank",
    "singular_values",
    "tolerance",
    "length_scale",
    "frame",
    "limbs",
}


def run(capsys: pytest.CaptureFixture[str], *args: str) -> str:
    assert main(list(args)) == 0
    return capsys.readouterr().out


def test_analyze_text(capsys: pytest.CaptureFixture[str]) -> None:
    out = run(capsys, "analyze", "3-PUU", "--config", "generic")
    assert out.startswith("3-PUU at 'generic': 3 DoF, 3T")
    assert "expected 3 DoF 3T" in out and "agrees with it" in out


def test_analyze_json_keys_and_values(capsys: pytest.CaptureFixture[str]) -> None:
    doc = json.loads(run(capsys, "analyze", "3-PUU-flat", "--config", "flat", "--json"))
    assert JSON_KEYS <= set(doc)
    assert (doc["dof"], doc["motion_type"], doc["constraint_rank"]) == (2, "1T1R", 4)
    assert [m["kind"] for m in doc["motions"]] == ["T", "R"]
    assert doc["motions"][0]["point"] is None and doc["motions"][0]["pitch"] is None
    assert all(len(t) == 6 for t in doc["free_twists"]) and len(doc["constraint_wrenches"]) == 4
    assert len(doc["singular_values"]) == 6
    assert [limb["twist_rank"] for limb in doc["limbs"]] == [4, 4, 4]
    assert [limb["wrench_count"] for limb in doc["limbs"]] == [2, 2, 2]


def test_paper_view_in_text_and_json(capsys: pytest.CaptureFixture[str]) -> None:
    out = run(capsys, "analyze", "3-PUU-flat", "--config", "flat", "--paper-view")
    assert "(paper's view" in out and "4 DoF, 3T1R" in out
    assert "difference: the paper's view gives 3T1R (4 DoF)" in out and "A, B, C" in out
    doc = json.loads(run(capsys, "analyze", "3-PUU-flat", "--config", "flat", "--paper-view", "--json"))
    assert doc["paper_view"]["motion_type"] == "3T1R" and doc["motion_type"] == "1T1R"


def test_models_lists_builtins(capsys: pytest.CaptureFixture[str]) -> None:
    out = run(capsys, "models")
    assert "3-PUU:" in out and "3-PUU-flat:" in out
    doc = json.loads(run(capsys, "models", "--json"))
    names = {m["name"] for m in doc}
    assert {"3-PUU", "3-PUU-flat", "3-PUU-vertical"} <= names
    puu = next(m for m in doc if m["name"] == "3-PUU")
    assert puu["configurations"]["generic"]["expected"] == {"dof": 3, "motion_type": "3T"}


def test_console_script_runs() -> None:
    proc = subprocess.run(
        [sys.executable, "-m", "pinmob", "analyze", "3-PUU", "-c", "offset"], capture_output=True, text=True
    )
    assert proc.returncode == 0, proc.stderr
    assert "3 DoF, 3T" in proc.stdout


#: keys issue 4 adds to ``pinmob analyze --json`` (whole-mechanism mobility and actuation)
MECHANISM_JSON_KEYS = {"mechanism_dof", "idle_dof", "redundant_constraints", "redundant_by_closure", "grubler"}
ACTUATION_KEYS = {"valid", "locked_dof", "remaining"}
#: keys issue 6 requires in the ``singularity`` entry
SINGULARITY_KEYS = {"constraint", "actuation", "limbs", "locked_dof", "uncontrolled", "distance", "generic_rank"}


def test_analyze_json_has_every_key_of_issues_2_4_and_6(capsys: pytest.CaptureFixture[str]) -> None:
    # a limb-and-platform model: issue 2's mobility, issue 4's mechanism keys, issue 6's singularity
    doc = json.loads(run(capsys, "analyze", "3-UPU", "--config", "constraint-singular", "--json"))
    assert JSON_KEYS | MECHANISM_JSON_KEYS | {"actuation", "singularity"} <= set(doc)
    assert ACTUATION_KEYS <= set(doc["actuation"]) and SINGULARITY_KEYS <= set(doc["singularity"])
    for key in ("dof", "constraint_rank", "mechanism_dof", "idle_dof", "redundant_constraints", "grubler"):
        assert type(doc[key]) is int, key
    assert type(doc["actuation"]["valid"]) is bool and type(doc["actuation"]["locked_dof"]) is int
    assert isinstance(doc["redundant_by_closure"], dict) and isinstance(doc["actuation"]["remaining"], list)
    s = doc["singularity"]
    assert (s["constraint"], s["actuation"], s["limbs"], s["generic_rank"]) == (True, True, [], 3)
    assert type(s["locked_dof"]) is int and isinstance(s["distance"], float)
    assert all({"kind", "direction"} <= set(m) for m in s["uncontrolled"])
    # the Extended URDF and MJCF loaders' JSON carries issue 4's keys too
    for path in (DATA / "fivebar" / "robot.yaml", DATA / "fourbar_connect.xml"):
        doc = json.loads(run(capsys, "analyze", str(path), "--json"))
        assert MECHANISM_JSON_KEYS | {"actuation"} <= set(doc), path
        assert ACTUATION_KEYS <= set(doc["actuation"]), path


def test_search_actuators_also_on_limb_models(capsys: pytest.CaptureFixture[str]) -> None:
    # Tsai's 3-UPU translates only, so each limb's U angles obey u2a = -u1b and u2b = -u1a (parallel axes,
    # no platform rotation): {A_u1a, A_u2b, ...} is a dependent set, while the three legs drive x, y, z
    doc = json.loads(run(capsys, "analyze", "3-UPU", "--config", "generic", "--json", "--search-actuators", "3"))
    sets = {frozenset(s) for s in doc["valid_actuator_sets"]}
    assert frozenset({"A_leg", "B_leg", "C_leg"}) in sets
    assert not any({"A_u1a", "A_u2b"} <= s or {"B_u1b", "B_u2a"} <= s for s in sets)
    out = run(capsys, "analyze", "3-UPU", "--config", "generic", "--search-actuators", "3")
    assert f"valid sets of 3 actuated joints: {len(sets)}" in out
    assert main(["analyze", "3-UPU", "--search-actuators", "0"]) == 2
    assert "1..15" in capsys.readouterr().err


def test_paper_view_without_approach_says_how_to_declare_one(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    """Serially singular limbs, no declared approach and no 'generic' configuration to come from."""
    models = pinmob.mechanism_file.builtin_dir()
    (tmp_path / "3puu_flat.urdf").write_text((models / "3puu_flat.urdf").read_text())
    text = "\n".join(
        line for line in (models / "3puu_flat.toml").read_text().splitlines() if not line.startswith("approach")
    )
    (tmp_path / "m.toml").write_text(text + "\n")
    assert main(["analyze", str(tmp_path / "m.toml"), "--config", "flat", "--paper-view"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "'flat'" in err and "'3-PUU-flat'" in err
    assert "approach = {" in err and "[configurations.<name>]" in err
    mech = pinmob.load("3-PUU-flat")
    with pytest.raises(ConfigurationError, match=r"declare one: 'flat', 'flat-raised'"):
        paper_view(mech, mech.configuration("flat"))
    with pytest.raises(ConfigurationError, match=r"unknown joint 'nope'; valid: .*'A_u1a'"):
        paper_view(mech, "flat", {"nope": 1.0})
