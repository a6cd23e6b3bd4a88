"""The command line: models, analyze (text, JSON, paper view)."""

from __future__ import annotations

import json
import subprocess
import sys

import pytest

from pinmob.cli import main

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
