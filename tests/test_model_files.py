"""The built-in model files: up to date with the catalog, listed by the CLI; the catalog command; testing helpers."""

from __future__ import annotations

import json
import re
import shutil
import subprocess
import sys
import tomllib
from pathlib import Path

import numpy as np
import pytest

import pinmob
from pinmob import catalog
from pinmob.catalog.registry import HINT, KEPT
from pinmob.cli import main
from pinmob.exceptions import ConfigurationError
from pinmob.io.builtin import builtin_dir
from pinmob.testing import assert_mobility

MODELS = Path(__file__).resolve().parent.parent / "models"
NUMBER = re.compile(r"-?\d+(?:\.\d+)?(?:[eE][-+]?\d+)?")


def _split(text: str) -> tuple[list[str], np.ndarray]:
    """Text with numbers replaced by a marker, and the numbers (compared with a tolerance: solver digits)."""
    return NUMBER.split(text), np.array([float(x) for x in NUMBER.findall(text)])


def out_of_date(models: Path, fresh: Path) -> list[str]:
    """Problems of ``models`` against freshly generated files in ``fresh``, each ending with the fix.

    The set of files must be the same (besides README.md, __init__.py); texts must be equal with numbers
    replaced by a marker, and numbers equal to 1e-9 (closed configurations come from an iterative solve).
    """
    problems = []
    have = {p.name for p in models.iterdir() if p.name not in KEPT}
    want = {p.name for p in fresh.iterdir()}
    for name in sorted(want - have):
        problems.append(f"models/{name} is missing: {HINT}")
    for name in sorted(have - want):
        problems.append(f"models/{name} is not written by the catalog (stale or stray): {HINT}")
    for name in sorted(have & want):
        (text_new, num_new), (text_old, num_old) = (
            _split((fresh / name).read_text()),
            _split((models / name).read_text()),
        )
        if text_new != text_old or num_new.shape != num_old.shape:
            problems.append(f"models/{name} is out of date (text differs): {HINT}")
        elif not np.allclose(num_new, num_old, rtol=0, atol=1e-9):
            i = int(np.argmax(np.abs(num_new - num_old)))
            problems.append(
                f"models/{name} is out of date (number {i}: {num_old[i]!r} in the file, {num_new[i]!r} now): {HINT}"
            )
    return problems


@pytest.fixture(scope="module")
def fresh(tmp_path_factory: pytest.TempPathFactory) -> Path:
    out = tmp_path_factory.mktemp("fresh")
    written = catalog.write_all(out)
    assert {p.stem for p in written} == set(catalog.CATALOG)
    return out


def test_generated_models_are_up_to_date(fresh):
    """Regenerate every catalogued model; models/ must hold exactly those files, with the same contents."""
    problems = out_of_date(MODELS, fresh)
    assert not problems, "\n".join(problems)


def test_out_of_date_check_catches_stray_and_changed_files(fresh, tmp_path):
    """The check itself: a stray file, a changed number and a missing file are each reported with the hint."""
    copy = tmp_path / "models"
    shutil.copytree(MODELS, copy)
    assert out_of_date(copy, fresh) == []
    (copy / "old_thing.urdf").write_text("<robot/>\n")
    sarrus = copy / "sarrus.urdf"
    sarrus.write_text(sarrus.read_text().replace('xyz="0 -0.1 0"', 'xyz="0 -0.1000001 0"', 1))
    (copy / "bennett.toml").unlink()
    problems = out_of_date(copy, fresh)
    assert len(problems) == 3 and all(p.endswith(HINT) for p in problems), problems
    assert any("old_thing.urdf is not written by the catalog" in p for p in problems)
    assert any("sarrus.urdf is out of date (number" in p and "-0.1000001" in p for p in problems)
    assert any("bennett.toml is missing" in p for p in problems)


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
    """models/README.md: a row per model with every configuration's expected mobility."""
    text = (MODELS / "README.md").read_text()
    rows = {line.split("|")[1].strip(): line for line in text.splitlines() if line.startswith("| `")}
    for path in sorted(MODELS.glob("*.toml")):
        doc = tomllib.loads(path.read_text())
        row = rows[f"`{doc['name']}`"]
        for config, conf in doc["configurations"].items():
            exp = conf["expected"]
            assert f"{config}: {exp['motion_type']}" in row or f"{config}: {exp['dof']} DoF" in row, (path, config)
    assert "Fichter" in rows["`6-UPS`"] and "type2: 3T3R, actuation (Type II) singular" in rows["`6-UPS`"]


# --------------------------------------------------------------------------- CLI


def test_cli_models_json(capsys):
    assert main(["models", "--json"]) == 0
    rows = json.loads(capsys.readouterr().out)
    by_name = {r["name"]: r for r in rows}
    assert set(by_name) == set(pinmob.builtin_models())
    bennett = by_name["Bennett"]
    assert [limb["name"] for limb in bennett["limbs"]] == ["X", "Y"]
    assert bennett["limbs"][0]["joints"] == ["X_j1", "X_j2"] and bennett["limbs"][0]["actuated"] == ["X_j1"]
    assert bennett["configurations"]["generic"]["expected"] == {"dof": 1, "motion_type": "1H"}
    assert [c["name"] for c in by_name["Delta"]["closures"]] == ["A_b", "B_b", "C_b"]
    for row in rows:
        assert {"name", "limbs", "configurations"} <= set(row)
        for conf in row["configurations"].values():
            assert set(conf["expected"]) == {"dof", "motion_type"}


def test_cli_models_text(capsys):
    """Each model with its limbs' joints (limb prefix dropped, * actuated) and expectations."""
    assert main(["models"]) == 0
    out = capsys.readouterr().out
    assert "five-bar: 3 limbs\n    limb A: r1* r2 r3\n    limb B: r1* r2 r3\n    limb V: x y\n" in out
    assert "    limb-B-stretched: expected 1 DoF 1T" in out
    assert "Delta: 3 limbs, closures A_b (3d), B_b (3d), C_b (3d)" in out


def test_cli_analyze_reports_agreement(capsys):
    assert main(["analyze", "Sarrus", "--config", "generic"]) == 0
    out = capsys.readouterr().out
    assert "Sarrus at 'generic': 1 DoF, 1T" in out
    assert "expected 1 DoF 1T" in out and "analysis agrees with it" in out


def test_cli_analyze_check(capsys, tmp_path):
    """--check: exit 0 when the analysis agrees, 1 with one line on stderr when it differs (also with --json),
    2 when there is nothing to check against."""
    assert main(["analyze", "Sarrus", "--config", "stretched", "--check"]) == 0
    capsys.readouterr()
    src = builtin_dir() / "sarrus.toml"
    shutil.copy(src.with_suffix(".urdf"), tmp_path / "sarrus.urdf")
    text = src.read_text().replace('dof = 1, motion_type = "1T"', 'dof = 2, motion_type = "1T1R"')
    (tmp_path / "wrong.toml").write_text(text)
    for extra in ([], ["--json"]):
        assert main(["analyze", str(tmp_path / "wrong.toml"), "-c", "generic", "--check", *extra]) == 1
        err = capsys.readouterr().err
        assert (
            err == "pinmob: check failed: Sarrus at 'generic': analysis gives 1 DoF 1T, the file expects 2 DoF 1T1R\n"
        )
    assert main(["analyze", str(tmp_path / "wrong.toml"), "-c", "generic"]) == 0  # without --check: report only
    capsys.readouterr()
    (tmp_path / "none.toml").write_text(re.sub(r"(?m)^expected = .*$", "", text))
    assert main(["analyze", str(tmp_path / "none.toml"), "--check"]) == 2
    assert "has no expected table" in capsys.readouterr().err


def test_cli_models_subprocess():
    run = subprocess.run(
        [sys.executable, "-m", "pinmob", "models", "--json"], capture_output=True, text=True, timeout=60
    )
    assert run.returncode == 0, run.stderr
    assert "3-RRR-spherical" in {r["name"] for r in json.loads(run.stdout)}


def test_installed_models_folder_holds_the_files():
    assert {p.name for p in builtin_dir().glob("*.toml")} >= {f"{s}.toml" for s in catalog.CATALOG}


# --------------------------------------------------------------------------- python -m pinmob.catalog


def test_catalog_help_writes_nothing(tmp_path):
    run = subprocess.run(
        [sys.executable, "-m", "pinmob.catalog", "--help"], capture_output=True, text=True, cwd=tmp_path, timeout=60
    )
    assert run.returncode == 0 and "usage: python -m pinmob.catalog [-h] [target]" in run.stdout
    assert list(tmp_path.iterdir()) == []


def test_catalog_default_target_is_the_checkout_models(capsys):
    """Run from the checkout (editable install), the default target is its models/; from a regular install
    (as in CI) there is none, and the command without a target says so in one line, exit 2."""
    from_checkout = Path(catalog.__file__).resolve().parents[2] == MODELS.parent
    assert catalog.checkout_models() == (MODELS if from_checkout else None)
    if not from_checkout:
        assert catalog.main([]) == 2
        assert "does not run from a source checkout" in capsys.readouterr().err


def test_catalog_refuses_unexpected_targets(tmp_path, capsys):
    """A folder holding other files, or a file, is refused with one line and exit 2; nothing is written."""
    (tmp_path / "notes.txt").write_text("mine\n")
    assert catalog.main([str(tmp_path)]) == 2
    err = capsys.readouterr().err
    assert err.startswith("pinmob.catalog: error: refusing to write into") and "notes.txt" in err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["notes.txt"]
    assert catalog.main([str(tmp_path / "notes.txt")]) == 2
    assert "is a file, not a folder" in capsys.readouterr().err


def test_catalog_writes_and_prunes_its_own_stale_files(tmp_path, capsys, monkeypatch):
    """A folder is filled with every entry's files; an earlier generated file no entry writes any more is
    removed (it carries the builder's marker), README.md is kept. (A one-entry catalogue, for speed.)"""
    from pinmob.catalog import registry

    monkeypatch.setattr(registry, "CATALOG", {"sarrus": catalog.CATALOG["sarrus"]})
    out = tmp_path / "m"
    out.mkdir()
    (out / "README.md").write_text("mine\n")
    (out / "gone.toml").write_text("# generated by pinmob.builder; edit the builder, not this file\n")
    assert catalog.main([str(out)]) == 0
    assert f"removed stale {out / 'gone.toml'}" in capsys.readouterr().out
    assert {p.name for p in out.iterdir()} == {"sarrus.toml", "sarrus.urdf", "README.md"}
    assert (out / "sarrus.urdf").read_text() == (MODELS / "sarrus.urdf").read_text()


# --------------------------------------------------------------------------- assert_mobility


def test_assert_mobility_failure_message():
    mech = pinmob.load("Sarrus")
    with pytest.raises(AssertionError) as info:
        assert_mobility(mech, "generic", dof=2, motion_type="1T1R", directions={"T": [[1, 0, 0]]})
    msg = str(info.value)
    assert "mobility of 'Sarrus' at 'generic' (limbs method) differs from the expectation" in msg
    assert "dof: expected 2, found 1" in msg
    assert "motion type: expected 1T1R, found 1T" in msg
    assert "T directions: expected span of ['[1, 0, 0]'], found ['[0, 0, 1]']" in msg
    assert re.search(
        r"singular values of the constraint wrenches \[.*\], tolerance [0-9.e-]+ \(rtol 1e-06 x largest\)", msg
    )
    with pytest.raises(AssertionError, match=r"\(mechanism method\)[\s\S]*singular values of the closure Jacobian"):
        assert_mobility(mech, "generic", dof=2, method="mechanism")


def test_assert_mobility_through_and_bad_arguments():
    mech = pinmob.load("3-RRR-spherical")
    assert_mobility(mech, "generic", through=[0, 0, 0])
    assert_mobility(mech, "generic", through=[0, 0, 0], method="mechanism")
    with pytest.raises(AssertionError, match="axis misses the point"):
        assert_mobility(mech, "generic", through=[0, 0, 0.1])
    with pytest.raises(ConfigurationError, match="valid: T, R, H"):
        assert_mobility(mech, "generic", directions={"X": [[1, 0, 0]]})
    with pytest.raises(ConfigurationError, match=r"directions\['R'\]\[1\] = \[0.0, 0.0, 0.0\] is not a direction"):
        assert_mobility(mech, "generic", directions={"R": [[1, 0, 0], [0, 0, 0]]})
    with pytest.raises(ConfigurationError, match="is not a direction"):
        assert_mobility(mech, "generic", directions={"R": [[np.nan, 0, 1]]})
    with pytest.raises(ConfigurationError, match="must be 3-vectors"):
        assert_mobility(mech, "generic", directions={"R": [[1, 0]]})
    with pytest.raises(ConfigurationError, match="method 'wrenches'; valid: limbs, mechanism"):
        assert_mobility(mech, "generic", method="wrenches")
