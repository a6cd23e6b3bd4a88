"""One door: ``pinmob analyze`` parses, calls the library and formats; the library checks each argument once.

The command line used to resolve the configuration name itself (``cli/common.py``) before the library did it
again (``Configuration``), and to check ``--rtol`` and ``--closure-tol`` before :func:`pinmob.analyze` checked
them again (``closure_tol`` a third time in ``Configuration``).
"""

from __future__ import annotations

import ast
import re
import sys
from collections import Counter
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest
from sweep_specs import SPEC

import pinmob
from pinmob.cli import main

#: a sweep of 1 x 2 designs, a 2 x 2 workspace grid each (tests/sweep_specs.py's, smaller)
SWEEP = SPEC.format(title="one door", lo=0.3, hi=0.3, n=2, m=2).replace("link = [0.3, 0.3, 2]", "link = [0.3, 0.3, 1]")


def count_calls(monkeypatch: pytest.MonkeyPatch, calls: Counter[str], name: str, original: Callable[..., Any]) -> None:
    """Replace ``original`` by a wrapper counting its calls, in every pinmob module that holds it under ``name``."""

    def counted(*args: Any, **kwargs: Any) -> Any:
        calls[name] += 1
        return original(*args, **kwargs)

    for module in list(sys.modules.values()):
        if getattr(module, "__name__", "").startswith("pinmob") and getattr(module, name, None) is original:
            monkeypatch.setattr(module, name, counted)


@pytest.mark.parametrize(
    "argv",
    [
        ["analyze", "3-PRS", "--config", "home", "--rtol", "1e-7", "--closure-tol", "1e-5"],
        ["analyze", "3-PRS", "--config", "HOME"],
        ["analyze", "3-PRS", "--joints", "A_slider=0.3", "--closure-tol", "1e-5"],
    ],
)
def test_analyze_checks_each_argument_once(monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str], argv):
    """One ``pinmob analyze``: rtol checked once, closure_tol once (by the library), the name resolved by the library.

    On the old code: rtol twice with --rtol, closure_tol 14 to 15 times (twice at the door, then in every
    Configuration the generic-rank estimate built), and the name resolved by ``cli/common.py`` first."""
    import pinmob.analysis.entry_point  # noqa: F401  (loaded, so that its names are wrapped too)
    import pinmob.cli.analyze  # noqa: F401
    import pinmob.cli.common  # noqa: F401

    calls: Counter[str] = Counter()
    count_calls(monkeypatch, calls, "check_rtol", pinmob.screw.rank.check_rtol)
    count_calls(monkeypatch, calls, "check_closure_tol", pinmob.assembly.residual.check_closure_tol)
    resolve = pinmob.model.mechanism.Mechanism.configuration_name

    def counted_name(self: Any, name: str) -> str:
        caller = sys._getframe(1).f_globals["__name__"]
        calls["configuration_name in the CLI" if caller.startswith("pinmob.cli") else "configuration_name"] += 1
        return resolve(self, name)

    monkeypatch.setattr(pinmob.model.mechanism.Mechanism, "configuration_name", counted_name)
    assert main(argv) == 0, capsys.readouterr().err
    assert "DoF" in capsys.readouterr().out
    assert calls["check_rtol"] == 1
    assert calls["check_closure_tol"] == 1
    assert calls["configuration_name in the CLI"] == 0  # the library resolves the name, the CLI passes it on
    assert calls["configuration_name"] >= (0 if "--joints" in argv else 1)


def test_a_bad_argument_and_an_unknown_configuration_are_told_apart() -> None:
    """Both used to be a bare ConfigurationError; the subclasses carry what was wrong as data, and the library's
    messages name its Python parameters, not the command line's options."""
    import pickle

    import pinmob

    mech = pinmob.load("3-PRS")
    with pytest.raises(pinmob.ArgumentError) as bad:
        pinmob.analyze(mech, "home", closure_tol=1.0)
    assert isinstance(bad.value, pinmob.ConfigurationError)
    assert (bad.value.parameter, bad.value.value) == ("closure_tol", 1.0) and "--" not in str(bad.value)
    again = pickle.loads(pickle.dumps(bad.value))  # as a Dask worker sends it back
    assert (type(again), str(again), again.parameter, again.parameters) == (
        pinmob.ArgumentError,
        str(bad.value),
        "closure_tol",
        ("closure_tol",),
    )
    with pytest.raises(pinmob.ArgumentError, match=r"^the number of random restarts \(restarts\) must be") as neg:
        pinmob.analyze(mech, None, restarts=-1)
    assert neg.value.parameter == "restarts"
    with pytest.raises(pinmob.UnknownConfigurationError, match="did you mean 'home'") as unknown:
        pinmob.analyze(mech, "hme")
    assert isinstance(unknown.value, pinmob.ConfigurationError) and unknown.value.name == "hme"


def test_the_command_line_words_the_parameters_as_its_options(capsys: pytest.CaptureFixture[str]) -> None:
    """The library says ``restarts``; the command line prints ``--restarts`` (pinmob/cli/flags.py)."""
    assert main(["analyze", "3-PRS", "--config", "home", "--restarts=-1"]) == 2
    assert capsys.readouterr().err == (
        "pinmob: error: the number of random restarts (--restarts) must be at least 0, got -1\n"
    )
    assert main(["analyze", "3-PRS", "--config", "hme"]) == 2
    err = capsys.readouterr().err
    assert err.startswith("pinmob: error: no configuration 'hme' in '3-PRS' (did you mean 'home'?)")


#: String literals under pinmob/ (outside pinmob/cli/) that may name command-line options: where the options are the
#: subject. Docstrings are documentation (they may say which option of the command line a parameter is).
FLAGS_ALLOWED = {
    "pinmob/viewer/server.py": "the meshcat server's own command line (python -m pinmob.viewer.server --port P ...)",
}

FLAG = re.compile(r"(?<![\w-])--[a-z][a-z0-9-]*")


def literals_naming_flags(path: Path) -> list[str]:
    """``line: text`` of each string literal of ``path`` (docstrings aside, f-strings' parts included) naming an option."""
    tree = ast.parse(path.read_text(encoding="utf-8"))
    docstrings = {
        id(node.body[0].value)
        for node in ast.walk(tree)
        if isinstance(node, ast.Module | ast.ClassDef | ast.FunctionDef | ast.AsyncFunctionDef)
        and node.body
        and isinstance(node.body[0], ast.Expr)
        and isinstance(node.body[0].value, ast.Constant)
    }
    return [
        f"{node.lineno}: {node.value!r}"
        for node in ast.walk(tree)
        if isinstance(node, ast.Constant)
        and isinstance(node.value, str)
        and id(node) not in docstrings
        and FLAG.search(node.value)
    ]


def test_the_library_names_no_command_line_option() -> None:
    """Errors name CLI flags only in the CLI: no string under pinmob/ outside pinmob/cli/ names an option.

    On the old code: 23 literals in 13 modules (the sweep store's --out and --force, the output files' --force,
    --sample, --actuated, --workers, --grid, --steps, --finite, --frame, --paper-view, --rtol / --closure-tol,
    `pinmob scan --from A --to B`)."""
    package = Path(pinmob.__file__).parent
    found = {
        str(path.relative_to(package.parent)): hits
        for path in sorted(package.rglob("*.py"))
        if path.relative_to(package).parts[0] != "cli" and (hits := literals_naming_flags(path))
    }
    assert {p: h for p, h in found.items() if p not in FLAGS_ALLOWED} == {}
    assert set(FLAGS_ALLOWED) <= set(found)  # each exception still needed


def test_the_scan_of_literals_finds_an_option(tmp_path: Path) -> None:
    """The scan above can fail: it finds an option in a message and in an f-string's part, not in a docstring."""
    path = tmp_path / "probe.py"
    path.write_text('"""Docstring: ``--rtol``."""\nx = f"{a} (--force)"\ny = "rtol must be positive"\n')
    assert literals_naming_flags(path) == ["2: ' (--force)'"]


def run_cli(capsys: pytest.CaptureFixture[str], argv: list[str]) -> str:
    """The one error line of ``pinmob ARGV`` (exit status 2)."""
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1
    return err


@pytest.mark.parametrize(
    ("argv", "line"),
    [
        (["show", "3-PRS", "--html", "exists.html"],
         "html file 'exists.html' exists already; choose another file name or allow overwriting (--force)"),
        (["sweep", "SPEC", "--out", "not.parquet"],
         "--out 'not.parquet' exists and is not a pinmob sweep file; choose another file name, or replace it (--force)"),
        (["scan", "3-PUU", "--grid", "x:0:1"],
         "--grid 'x:0:1': expected COORD:LO:HI:N (four fields separated by ':'), e.g. x:-0.1:0.1:21"),
        (["scan", "3-PUU", "--grid", "x:0:1:2", "x:0:1:2"],
         "--grid needs one to three different coordinates, got ['x', 'x']"),
        (["scan", "3-PUU", "--grid", "x:0:1:2", "--workers", "0"],
         "--workers must be a whole number of worker processes, at least 1, got 0"),
        (["show", "3-PUU", "--steps", "100000", "--html", "out.html"],
         "the animation (--steps): 100,000 steps, over the bound of 2,000; ask for fewer, or set PINMOB_MAX_STEPS to "
         "raise the bound"),
    ],
)  # fmt: skip
def test_the_command_line_prints_its_options_as_before(tmp_path, monkeypatch, capsys, argv, line):
    """The library now names its parameters (``target``, ``overwrite=True``, ``workers``, ``axes``, ``steps``); the
    command line prints what it printed before (the lines of the old code, word for word)."""
    monkeypatch.chdir(tmp_path)
    (tmp_path / "exists.html").write_text("mine")
    (tmp_path / "not.parquet").write_text("mine")
    spec = Path(__file__).parent.parent / "examples" / "3puu_sweep.toml"
    argv = [str(spec) if a == "SPEC" else a for a in argv]
    assert run_cli(capsys, argv) == f"pinmob: error: {line}\n"


def test_a_report_names_parameters_and_the_command_line_prints_options(capsys) -> None:
    """A report is library output read in Python too: it names ``paper=True``, ``rtol``, ``closure_tol``; ``pinmob
    analyze`` prints ``--paper-view``, ``--rtol``, ``--closure-tol`` as before (pinmob.cli.flags.worded_report)."""
    from pinmob.analysis.ambiguity import AmbiguousRank
    from pinmob.cli.flags import worded_report

    report = pinmob.analyze(pinmob.load("3-PUU-flat"), "flat")
    assert str(report).count("misses them: see `paper=True`.") == 1 and "--" not in str(report)
    assert main(["analyze", "3-PUU-flat", "--config", "flat"]) == 0
    assert capsys.readouterr().out == worded_report(str(report)) + "\n"
    assert worded_report(str(report)) == str(report).replace("`paper=True`", "--paper-view")
    ambiguous = str(AmbiguousRank("closure rank", 3, 2e-7, 5e-8, 1e-7))
    assert ambiguous.endswith("(check the model's accuracy, or set `rtol` / `closure_tol`)")
    assert worded_report(ambiguous).endswith("(check the model's accuracy, or set --rtol / --closure-tol)")


def count_checks(monkeypatch: pytest.MonkeyPatch) -> Counter[str]:
    """Count, during the test, the calls of pinmob's argument checks and of the motion follower's two doors.

    Keys: the check's name; ``NAME in the CLI`` for a call made by a module of pinmob.cli; ``NAME per
    Configuration`` for one made by a Configuration's constructor (each object it builds checks its own)."""
    import pinmob.analysis.follow.motion_path as paths
    import pinmob.parallel.cluster
    import pinmob.screw.rank

    calls: Counter[str] = Counter()

    def counting(name: str, original: Callable[..., Any]) -> None:
        def counted(*args: Any, **kwargs: Any) -> Any:
            caller = sys._getframe(1)
            calls[name] += 1
            if caller.f_globals["__name__"].startswith("pinmob.cli"):
                calls[f"{name} in the CLI"] += 1
            if caller.f_code.co_name == "__init__" and caller.f_globals["__name__"] == "pinmob.analysis.configuration":
                calls[f"{name} per Configuration"] += 1
            return original(*args, **kwargs)

        for module in list(sys.modules.values()):
            if getattr(module, "__name__", "").startswith("pinmob") and getattr(module, name, None) is original:
                monkeypatch.setattr(module, name, counted)

    counting("check_rtol", pinmob.screw.rank.check_rtol)
    counting("check_closure_tol", pinmob.assembly.residual.check_closure_tol)
    counting("check_workers", pinmob.parallel.cluster.check_workers)
    counting("follow_motion", paths.follow_motion)
    counting("follow_rates", paths.follow_rates)
    return calls


def test_show_checks_closure_tol_at_the_library_doors_only(monkeypatch, capsys, tmp_path) -> None:
    """``pinmob show``: the CLI checks nothing; the library checks closure_tol exactly once, for the configuration,
    never per step nor per motion followed: the viewer's clips and the finite analysis' paths start from that
    Configuration (follow_motion, follow_rates: a Configuration is not checked again).

    On the old code: 77 checks for the 3-PRS, the CLI's (cli/common.closure_tol_of) among them, and one per
    step of every clip (the follower built a checked Configuration at each); then 8, one per motion followed
    (follow_motion 6 times: the three clips and the finite analysis' three traces; follow_rates once)."""
    import pinmob.cli.show  # noqa: F401  (loaded, so that its names are wrapped too)
    import pinmob.viewer.prepared  # noqa: F401

    calls = count_checks(monkeypatch)
    argv = ["show", "3-PRS", "--config", "home", "--closure-tol", "1e-5", "--html", str(tmp_path / "s.html")]
    assert main(argv) == 0, capsys.readouterr().err
    assert "3-PRS at 'home': 3 DoF" in capsys.readouterr().out
    assert calls["check_closure_tol in the CLI"] == 0 and calls["check_rtol in the CLI"] == 0
    assert calls["follow_motion"] == 6  # the three clips, and the finite analysis' three traces
    assert calls["check_closure_tol"] == 1
    assert calls["check_rtol"] == 1


@pytest.mark.parametrize(
    "shape",
    [
        ["--grid", "x:-0.01:0.01:2", "y:-0.01:0.01:2"],
        ["--from", "home", "--to", "0,0,0.3,0,0,0.1", "-n", "3"],
    ],
)
def test_scan_checks_each_argument_once_in_the_library(monkeypatch, capsys, shape) -> None:
    """``pinmob scan``: --rtol, --closure-tol and --workers are checked once each, by the library (grid_spec or
    path_spec, and the Engine), none by the CLI.

    On the old code: the CLI checked --rtol (the library not at all), --closure-tol (then path_spec passed it on
    unchecked; grid_spec ignored it) and --workers (then scan() twice more: 3 checks)."""
    import pinmob.cli.scan  # noqa: F401
    import pinmob.scan.scan_run  # noqa: F401

    calls = count_checks(monkeypatch)
    argv = ["scan", "3-PRS", *shape, "--rtol", "1e-7", "--closure-tol", "1e-5", "--no-progress"]
    assert main(argv) == 0, capsys.readouterr().err
    assert "samples in" in capsys.readouterr().out
    assert calls["check_rtol in the CLI"] == calls["check_closure_tol in the CLI"] == 0
    assert calls["check_workers in the CLI"] == 0
    assert (calls["check_rtol"], calls["check_workers"]) == (1, 1)
    assert calls["check_closure_tol"] - calls["check_closure_tol per Configuration"] == 1


def test_a_grid_scan_closes_its_samples_within_closure_tol(capsys) -> None:
    """--closure-tol reaches a grid scan: ScanSpec.closure_tol is what was asked (it stayed 2e-05 before)."""
    import pinmob.scan as scans

    mech = pinmob.load("3-PRS")
    spec = scans.grid_spec(mech, "home", [("z", 0.29, 0.31, 2)], closure_tol=1e-5)
    assert spec.closure_tol == 1e-5
    with pytest.raises(pinmob.ArgumentError, match="^closure_tol must be a finite number"):
        scans.grid_spec(mech, "home", [("z", 0.29, 0.31, 2)], closure_tol=1.0)
    with pytest.raises(pinmob.ArgumentError, match="^rtol must be"):
        scans.path_spec(mech, "home", "home", 3, rtol=-1.0)


def test_sweep_checks_workers_once_in_the_library(monkeypatch, capsys, tmp_path) -> None:
    """``pinmob sweep --workers 1``: workers checked once (the Engine), not by the CLI (3 checks before)."""
    import pinmob.cli.sweep  # noqa: F401
    import pinmob.sweeps.sweep_run  # noqa: F401

    spec = tmp_path / "s.toml"
    spec.write_text(SWEEP)
    calls = count_checks(monkeypatch)
    assert main(["sweep", str(spec), "--workers", "1", "--no-progress", "--no-plots"]) == 0, capsys.readouterr().err
    assert "2 designs" in capsys.readouterr().out
    assert calls["check_workers"] == 1 and calls["check_workers in the CLI"] == 0
    assert calls["check_rtol in the CLI"] == calls["check_closure_tol in the CLI"] == 0


def test_scan_is_one_door(monkeypatch, capsys, tmp_path) -> None:
    """``pinmob scan`` parses, calls :func:`pinmob.scan.scan` once and prints its report: the summary is the
    library's (``str(report)``), cli/scan.py reads no row (``row["..."]``) and imports nothing from inside
    pinmob.scan, only its face.

    On the old code: cli/scan.py aggregated and formatted the rows itself (19 ``row["..."]`` reads) and imported 7
    scan internals; a Python user could not get the summary it printed."""
    import pinmob.cli.scan as cli_scan

    tree = ast.parse(Path(cli_scan.__file__).read_text(encoding="utf-8"))
    reads = [n.lineno for n in ast.walk(tree)
             if isinstance(n, ast.Subscript) and isinstance(n.value, ast.Name) and n.value.id in ("row", "r")]  # fmt: skip
    deep = [
        n.module
        for n in ast.walk(tree)
        if isinstance(n, ast.ImportFrom) and (n.module or "").startswith("pinmob.scan.")
    ]
    assert reads == [] and deep == []
    reports: list[Any] = []
    library = cli_scan.scan

    def recorded(*args: Any, **kwargs: Any) -> Any:
        reports.append(library(*args, **kwargs))
        return reports[-1]

    monkeypatch.setattr(cli_scan, "scan", recorded)
    j = tmp_path / "g.json"
    argv = ["scan", "3-PUU", "--grid", "x:-0.02:0.02:2", "y:-0.02:0.02:2", "--at", "generic", "--json", str(j)]
    assert main([*argv, "--no-progress"]) == 0, capsys.readouterr().err
    (report,) = reports
    assert capsys.readouterr().out == str(report) + "\n"
    assert str(report).endswith(f"json: {j}") and report.table is None  # nothing kept: no plot, no 3D view
