"""The one entry point and the one state object: Report == the CLI's output, Configuration computed once."""

from __future__ import annotations

import dataclasses
import io
import json
import pickle
import tomllib
import warnings
from contextlib import redirect_stderr, redirect_stdout
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest
from test_errors import GOOD, write_mechanism

import pinmob
import pinmob.assembly.assemble as assemble_module
from pinmob.cli import main
from pinmob.cli.flags import worded_report

MODELS = Path(__file__).resolve().parent.parent / "models"

#: every built-in model and configuration, read from the files (no model is loaded to list them)
CASES = [
    (tomllib.loads(p.read_text())["name"], config)
    for p in sorted(MODELS.glob("*.toml"))
    for config in tomllib.loads(p.read_text())["configurations"]
]


def cli(*args: str) -> str:
    out = io.StringIO()
    with redirect_stdout(out):
        assert main(list(args)) == 0
    return out.getvalue()


@pytest.mark.parametrize(("name", "config"), CASES)
def test_report_is_what_the_cli_prints(name: str, config: str) -> None:
    """``to_dict()`` is the document of ``pinmob analyze --json``, ``str()`` the text of ``pinmob analyze``."""
    report = pinmob.analyze(pinmob.load(name), config)
    assert json.loads(cli("analyze", name, "--config", config, "--json")) == json.loads(
        json.dumps(report.to_dict(), allow_nan=False)
    )
    assert cli("analyze", name, "--config", config) == worded_report(str(report)) + "\n"  # paper=True: --paper-view


FINITE_CASES = [("3-PUU-flat", "flat"), ("Sarrus", "stretched"), ("6-UPS", "type2"), ("3-UPU", "constraint-singular")]


@pytest.mark.parametrize(("name", "config"), FINITE_CASES)
def test_finite_report_is_what_the_cli_prints(name: str, config: str) -> None:
    """With ``--finite``: the same equality, and the JSON keys of the finite analysis."""
    report = pinmob.analyze(pinmob.load(name), config, finite=True)
    document = json.loads(cli("analyze", name, "--config", config, "--json", "--finite"))
    assert document == json.loads(json.dumps(report.to_dict(), allow_nan=False))
    assert cli("analyze", name, "--config", config, "--finite") == worded_report(str(report)) + "\n"
    for key in ("finite_dof", "finite_mechanism_dof", "finite_dof_locked", "finite"):
        assert key in document
    assert all({"finite", "order", "branches"} <= set(m) for m in document["finite"]["motions"])
    assert "finite mobility: higher-order conditions up to order 4" in str(report)


def test_finite_json_without_actuators_has_no_locked_key() -> None:
    """``finite_dof_locked`` only where actuators are declared (the line-symmetric Bricard declares none)."""
    from finite_cases import bricard_line_symmetric

    mech = bricard_line_symmetric()
    document = pinmob.analyze(mech, mech.neutral(), finite=True, generic_rank=5).to_dict()
    assert document["finite_dof"] == 1 and "finite_dof_locked" not in document and "locked" not in document["finite"]


def test_a_bad_finite_order_is_one_line() -> None:
    out, err = io.StringIO(), io.StringIO()
    with redirect_stdout(out), redirect_stderr(err):
        status = main(["analyze", "3-PUU", "--finite", "--finite-order", "9"])
    assert status == 2 and out.getvalue() == ""
    assert err.getvalue() == (
        "pinmob: error: the order bound of the finite analysis must be an integer from 2 to 8, got 9\n"
    )


def test_report_of_a_closed_chain_is_what_the_cli_prints() -> None:
    """A mechanism described by closures only: the report finds a closed configuration, as the CLI does."""
    path = Path(__file__).resolve().parent / "data" / "example-parallel-robots" / "5bar_linkage" / "robot.yaml"
    report = pinmob.analyze(pinmob.load(path))
    assert report.mobility is None and report.mechanism_mobility.mechanism_dof == 3
    assert json.loads(cli("analyze", str(path), "--json")) == json.loads(json.dumps(report.to_dict()))
    assert cli("analyze", str(path)).startswith(str(report).splitlines()[0])


def test_cli_leaves_the_warning_state_as_it_found_it() -> None:
    before = (list(warnings.filters), warnings.showwarning, warnings.formatwarning)
    cli("analyze", "3-PUU", "--config", "generic")
    cli("analyze", "3-PUU", "--config", "generic", "--json")
    assert (list(warnings.filters), warnings.showwarning, warnings.formatwarning) == before


def test_results_are_frozen_for_real() -> None:
    mech = pinmob.load("3-PUU")
    report = pinmob.analyze(mech, "generic")
    with pytest.raises(ValueError, match="read-only"):
        report.free_twists[0, 0] = 99
    with pytest.raises(ValueError, match="read-only"):
        report.motions[0].direction[0] = 99
    with pytest.raises(ValueError, match="read-only"):
        report.mechanism_mobility.singular_values[0] = 99
    with pytest.raises(ValueError, match="read-only"):
        report.state.q[0] = 99
    with pytest.raises(dataclasses.FrozenInstanceError):
        report.rtol = 0.5  # type: ignore[misc]
    assert isinstance(report.view, pinmob.View) and isinstance(report.method, pinmob.Method)
    assert all(isinstance(c.type, pinmob.ClosureType) for c in mech.all_closures)


def test_a_mechanisms_cached_arrays_stay_read_only_when_pickled() -> None:
    """A mechanism sent to a Dask worker is pickled with its per-mechanism cache (generic ranks, index arrays):
    the copy's cached arrays are read-only as the original's (unpickled numpy arrays are writeable), and the
    copy analyses alike (found by a review)."""
    mech = pinmob.load("3-PUU")
    expected = pinmob.analyze(mech, "generic").to_dict()
    cached = [k for k, v in mech._memo.items() if isinstance(v, np.ndarray)]
    assert cached and not any(mech._memo[k].flags.writeable for k in cached)
    copy = pickle.loads(pickle.dumps(mech))
    assert [k for k in cached if copy._memo[k].flags.writeable] == []
    assert pinmob.analyze(copy, "generic").to_dict() == expected


def test_a_named_configuration_is_closed_once(monkeypatch: pytest.MonkeyPatch) -> None:
    """The whole report (with the paper's view) assembles the named pose configuration once (it was 3 times)."""
    mech = pinmob.load("3-RPS")
    assert mech.configurations["tilted-x"].pose is not None
    pinmob.analyze(mech, "tilted-x", paper=True).to_dict()  # generic ranks estimated and cached per mechanism
    for key in [k for k in mech._memo if k[0] == "named pose"]:
        del mech._memo[key]  # the assembled poses are kept too: forgotten, to count one report's assemblies
    calls = {"n": 0}
    real = assemble_module.assemble_pose

    def counted(*args: object, **kwargs: object) -> np.ndarray:
        calls["n"] += 1
        return real(*args, **kwargs)  # type: ignore[arg-type]

    monkeypatch.setattr("pinmob.assembly.named_assembly.assemble_pose", counted)
    report = pinmob.analyze(mech, "tilted-x", paper=True)
    report.to_dict()
    str(report)
    assert calls["n"] == 1


def test_configuration_state() -> None:
    """Validated once, kinematics in a pooled Data (reused by the next configuration), picklable."""
    mech = pinmob.load("3-PUU")
    conf = pinmob.Configuration(mech, "generic")
    data = conf.data
    assert conf.name == "generic" and conf.residual < 1e-12 and conf.source == "named configuration 'generic'"
    assert conf.memo("x", lambda: 1) == 1 and conf.memo("x", lambda: 2) == 1
    q = conf.q.copy()
    del conf
    again = pinmob.Configuration(mech, q)
    assert again.data is data  # the Data went back to the pool and was taken again
    copy = pickle.loads(pickle.dumps(again))
    assert np.array_equal(copy.q, again.q) and copy.data is not again.data
    assert pinmob.analyze(copy).to_dict() == pinmob.analyze(again).to_dict()
    with pytest.raises(pinmob.ConfigurationError, match="not both"):
        pinmob.analyze(again, q)


def test_each_way_of_making_a_configuration_pickles_as_it_was_made() -> None:
    """The constructor, from_checked and unchecked; unpickled, each is rebuilt the way it was made.

    An unchecked configuration (its closure tolerance inf, at a q whose loops are open) went through the
    constructor on unpickling, which refused its tolerance: ArgumentError on the old code."""
    mech = pinmob.load("3-PUU")
    q_open = pin.integrate(mech.model, mech.neutral(), np.full(mech.model.nv, 0.1))  # every joint moved: loops open
    with pytest.raises(pinmob.ClosureError):
        pinmob.Configuration(mech, q_open)
    made = {
        "constructor": pinmob.Configuration(mech, "generic", closure_tol=1e-7),
        "from_checked": pinmob.Configuration.from_checked(mech, "generic", 1e-7, name="g", source="test"),
        "unchecked": pinmob.Configuration.unchecked(mech, q_open).with_name("open"),
    }
    for way, conf in made.items():
        copy = pickle.loads(pickle.dumps(conf))
        assert np.array_equal(copy.q, conf.q) and not copy.q.flags.writeable, way
        assert (copy.name, copy.source, copy.closure_tol) == (conf.name, conf.source, conf.closure_tol), way
        assert copy.residuals == conf.residuals, way
        assert np.array_equal(copy.world_jacobian, conf.world_jacobian), way
    assert made["unchecked"].closure_tol == np.inf and made["unchecked"].source == "unchecked"
    assert made["constructor"].source == "named configuration 'generic'" and made["from_checked"].source == "test"


ENTRY_POINTS = {
    "analyze": lambda m, q, **kw: pinmob.analyze(m, q, **kw),
    "analyze_mechanism": lambda m, q, **kw: pinmob.analyze_mechanism(m, q, **kw),
    "analyze_singularity": lambda m, q, **kw: pinmob.analyze_singularity(m, q, generic_rank=2, **kw),
    "paper_view": lambda m, q, **kw: pinmob.paper_view(m, q, **kw),
    "closure_jacobian_twists": lambda m, q, **kw: pinmob.closure_jacobian_twists(m, q, **kw),
    "frame_mobility": lambda m, q, **kw: pinmob.frame_mobility(m, q, "platform", **kw),
    "actuator_sets": lambda m, q, **kw: pinmob.actuator_sets(m, q, 2, **kw),
}


@pytest.mark.parametrize("entry", sorted(ENTRY_POINTS))
def test_every_entry_point_checks_its_arguments_the_same_way(entry: str, tmp_path: Path) -> None:
    """rtol and closure_tol are checked (and used) by every entry point, for a name as for a vector:
    ``analyze_mechanism`` used to accept rtol = -1 and ignore closure_tol for a named configuration."""
    call = ENTRY_POINTS[entry]
    mech = pinmob.load(write_mechanism(tmp_path, GOOD.replace("A_slider = 0.0", "B_slider = 1e-5")))
    for rtol in (-1.0, 0.0, float("nan"), 1.5):
        with pytest.raises(pinmob.ConfigurationError, match="rtol"):
            call(mech, "home", rtol=rtol, closure_tol=1e-3)
    for tol in (-1.0, float("nan"), 1.0):
        with pytest.raises(pinmob.ConfigurationError, match="closure_tol"):
            call(mech, "home", closure_tol=tol)
    with pytest.raises(pinmob.ClosureError, match="B: 1.00e-05 m"):
        call(mech, "home")
    with pytest.raises(pinmob.ClosureError, match="B: 1.00e-05 m"):
        call(mech, pinmob.closed_configuration(mech, "home", 1e-3))
    call(mech, "home", closure_tol=1e-3)  # loosened: accepted, by name
