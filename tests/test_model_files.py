"""The built-in model files: up to date with the catalog, listed by the CLI; the catalog command; testing helpers."""

from __future__ import annotations

import json
import os
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
from pinmob.catalog.freshness import HINT, TOLERANCE, difference, out_of_date
from pinmob.cli import main
from pinmob.exceptions import ConfigurationError
from pinmob.io.builtin import builtin_dir
from pinmob.testing import assert_mobility

MODELS = Path(__file__).resolve().parent.parent / "models"
#: what another machine changes: other OpenBLAS kernels, numpy without its AVX2/AVX-512 code paths (unknown
#: names are ignored by numpy and OpenBLAS, so this runs everywhere)
OTHER_MACHINE = {
    "OPENBLAS_CORETYPE": "Prescott",
    "NPY_DISABLE_CPU_FEATURES": "X86_V3,X86_V4,AVX512_ICL,AVX512_SPR,AVX2,FMA3",
}


@pytest.fixture(scope="module")
def fresh(tmp_path_factory: pytest.TempPathFactory) -> Path:
    out = tmp_path_factory.mktemp("fresh")
    written = catalog.write_all(out)
    assert {p.stem for p in written} == set(catalog.CATALOG)
    return out


def test_generated_models_are_up_to_date(fresh):
    """Regenerate every catalogued model; models/ must hold exactly those files, with equivalent contents
    (:mod:`pinmob.catalog.freshness`: numbers within 1e-9 [m or rad], angles modulo 2 pi; 1e-9 is 1e5 times the
    differences seen between machines and 1e3 times below the closure and rank tolerances)."""
    problems = out_of_date(MODELS, fresh)
    assert not problems, "\n".join(problems)


def test_models_regenerated_as_on_another_machine_are_equivalent(tmp_path):
    """``python -m pinmob.catalog`` with other BLAS kernels and numpy's SIMD paths reduced to the baseline (as on
    another machine; here that changed numbers in the last digit and, before angles were written in (-pi, pi],
    the Delta's rods-horizontal values by 2 pi): the output is equivalent to models/."""
    env = os.environ | OTHER_MACHINE
    run = subprocess.run(
        [sys.executable, "-m", "pinmob.catalog", str(tmp_path / "out")],
        capture_output=True,
        text=True,
        env=env,
        timeout=300,
    )
    assert run.returncode == 0, run.stderr
    problems = out_of_date(MODELS, tmp_path / "out")
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
    assert any("sarrus.urdf is out of date (line" in p and "-0.1000001 in the file" in p for p in problems)
    assert any("bennett.toml is missing" in p for p in problems)


DELTA_LINE = "joints = { A_motor = -0.46, A_a_topa = 1.18, A_a_bota = -0.72, A_slide = 0.3 }"


@pytest.mark.parametrize(
    ("old", "new", "same"),
    [
        (DELTA_LINE, DELTA_LINE.replace("-0.72", repr(-0.72 + 2 * np.pi)), True),  # a revolute angle, 2 pi apart
        (DELTA_LINE, DELTA_LINE.replace("1.18", repr(1.18 - 4 * np.pi)), True),
        (DELTA_LINE, DELTA_LINE.replace("-0.72", repr(-0.72 + 0.5 * TOLERANCE)), True),  # round-off
        (DELTA_LINE, DELTA_LINE.replace("-0.72", repr(-0.72 + 2 * TOLERANCE)), False),
        (DELTA_LINE, DELTA_LINE.replace("-0.72", repr(-0.72 + np.pi)), False),  # a half turn is another pose
        (DELTA_LINE, DELTA_LINE.replace("0.3", repr(0.3 + 2 * np.pi)), False),  # a prismatic value is no angle
        (DELTA_LINE, DELTA_LINE.replace("joints", "approach").replace("-0.72", repr(-0.72 + 2 * np.pi)), False),
        (
            '<origin xyz="0 -0.12 0" rpy="3.14159265358979 0 1.5"/>',
            '<origin xyz="0 -0.12 0" rpy="-3.14159265358979 0 1.5"/>',
            True,
        ),
        ('<origin xyz="0.1 0 0" rpy="0 0 0"/>', f'<origin xyz="{0.1 + 2 * np.pi!r} 0 0" rpy="0 0 0"/>', False),
        (
            "pose = { xyz = [0.1, 0.0, 0.2], rpy = [0.0, 0.0, 3.0] }",
            f"pose = {{ xyz = [0.1, 0.0, 0.2], rpy = [0.0, 0.0, {3.0 - 2 * np.pi!r}] }}",
            True,
        ),
        (
            "pose = { xyz = [0.1, 0.0, 0.2], rpy = [0.0, 0.0, 3.0] }",
            f"pose = {{ xyz = [{0.1 + 2 * np.pi!r}, 0.0, 0.2], rpy = [0.0, 0.0, 3.0] }}",
            False,
        ),
        ('name = "A 60 deg arm"', 'name = "A 60.0000001 deg arm"', False),
    ],
    ids=[
        "revolute+2pi",
        "revolute-4pi",
        "round-off",
        "2e-9",
        "half-turn",
        "prismatic+2pi",
        "approach+2pi",
        "urdf-roll-pi",
        "urdf-length+2pi",
        "toml-yaw-2pi",
        "toml-xyz+2pi",
        "string",
    ],
)
def test_equivalence_rule(old, new, same):
    """The freshness rule on single lines: revolute joint values (joints and seed tables) and rpy angles modulo
    2 pi, every number within TOLERANCE = 1e-9, nothing else (a prismatic value, an approach direction, a length
    2 pi apart, a number in a string that changed)."""
    revolute = {"A_motor", "A_a_topa", "A_a_bota"}  # A_slide is prismatic
    for a, b in ((old, new), (old.replace("joints", "seed"), new.replace("joints", "seed"))):
        assert (difference(a + "\n", b + "\n", revolute) is None) == same, (a, b)


def test_catalog_leaves_equivalent_files_alone(fresh, tmp_path, capsys):
    """``python -m pinmob.catalog DIR`` rewrites a file only when it is not equivalent to the new output: a
    revolute value 2 pi apart and a round-off change stay as they are (no diff after regenerating on another
    machine), a changed length is rewritten."""
    out = tmp_path / "models"
    shutil.copytree(MODELS, out, ignore=shutil.ignore_patterns("__pycache__"))
    delta, sarrus, bennett = out / "delta.toml", out / "sarrus.urdf", out / "bennett.urdf"
    line = next(line for line in delta.read_text().splitlines() if "A_a_bota = -0.72" in line)
    value = re.search(r"A_a_bota = (\S+),", line).group(1)
    delta.write_text(delta.read_text().replace(f"A_a_bota = {value},", f"A_a_bota = {float(value) + 2 * np.pi!r},"))
    sarrus.write_text(sarrus.read_text().replace('xyz="0 -0.1 0"', 'xyz="0 -0.1000000000001 0"', 1))
    bennett.write_text(bennett.read_text().replace('xyz="-0.0347296355333861', 'xyz="-0.0347297', 1))
    before = {p.name: p.read_text() for p in out.iterdir()}
    assert catalog.main([str(out)]) == 0
    printed = capsys.readouterr().out
    assert printed.splitlines()[0] == f"wrote {bennett}" and f"35 file(s) in {out} unchanged" in printed
    after = {p.name: p.read_text() for p in out.iterdir()}
    assert {name for name in before if before[name] != after[name]} == {"bennett.urdf"}
    assert after["bennett.urdf"] == (MODELS / "bennett.urdf").read_text()
    assert out_of_date(out, fresh) == []


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


def test_source_tree_without_the_install_finds_its_models():
    """A source tree imported ahead of any install (``python -m pinmob`` in a checkout whose package is not
    importable as ``pinmob.models``: no editable finder) reads the checkout's models/ folder."""
    code = (
        "import sys\n"
        "sys.meta_path[:] = [f for f in sys.meta_path if 'editable' not in repr(f).lower()]\n"
        f"sys.path.insert(0, {str(MODELS.parent)!r})\n"
        "import pinmob\n"
        "from pinmob.io.builtin import builtin_dir, builtin_models\n"
        "print(pinmob.__file__)\n"
        "print(builtin_dir())\n"
        "print(len(builtin_models()))\n"
    )
    run = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60)
    assert run.returncode == 0, run.stderr
    module, folder, count = run.stdout.split("\n")[:3]
    assert Path(module).resolve() == MODELS.parent / "pinmob" / "__init__.py"
    assert Path(folder) in (MODELS, MODELS.parent / "pinmob" / "models")  # the checkout's own files either way
    assert int(count) == len(list(MODELS.glob("*.toml"))) > 0


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


def test_expectations_name_no_file_of_the_test_suite() -> None:
    """A report's "expected" line is read by pip users, who have no tests/ folder: a source names a derivation, a
    publication or the pinmob test suite, never a path in it."""
    from pinmob import builtin_models, load

    sources = {(name, config): e.source for name in builtin_models() for config, e in load(name).expected.items()}
    assert sources, "no built-in model has an expectation"
    assert not {k: s for k, s in sources.items() if "tests/" in s or "test_" in s}
