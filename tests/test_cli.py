"""The command line: models, analyze (text, JSON, paper view)."""

from __future__ import annotations

import json
import os
import re
import subprocess
import sys
from pathlib import Path

import pytest
from model_cases import model_configurations

import pinmob
from pinmob import paper_view
from pinmob.cli import main
from pinmob.exceptions import ConfigurationError

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
    models = pinmob.io.builtin_dir()
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
        paper_view(mech, pinmob.closed_configuration(mech, "flat"))
    with pytest.raises(ConfigurationError, match=r"unknown joint 'nope'; valid: .*'A_u1a'"):
        paper_view(mech, "flat", {"nope": 1.0})


def reject_constant(name: str) -> float:
    raise ValueError(f"JSON holds {name}, which is not plain JSON")


@pytest.mark.parametrize("name,config", model_configurations())
def test_to_dict_is_plain_json_everywhere(name: str, config: str) -> None:
    """Every built-in model and configuration: to_dict() dumps with allow_nan=False and reads back equal."""
    mob = pinmob.analyze(pinmob.load(name), config)
    doc = json.loads(json.dumps(mob.to_dict(), allow_nan=False), parse_constant=reject_constant)
    assert (doc["dof"], doc["motion_type"]) == (mob.dof, mob.motion_type)
    assert [c["kind"] for c in doc["constraints"]] == [c.kind.value for c in mob.constraints]
    assert all(type(c["kind"]) is str for c in doc["constraints"] + doc["motions"])


def test_cli_json_has_no_nan_or_infinity() -> None:
    proc = subprocess.run(
        [sys.executable, "-m", "pinmob", "analyze", "3-PUU-flat", "--config", "flat", "--json", "--paper-view"],
        capture_output=True,
        text=True,
    )
    assert proc.returncode == 0, proc.stderr
    doc = json.loads(proc.stdout, parse_constant=reject_constant)
    assert doc["motion_type"] == "1T1R" and doc["paper_view"]["motion_type"] == "3T1R"


def cli(*args: str, cwd: Path | None = None) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-m", "pinmob", *args], capture_output=True, text=True, cwd=cwd)


def one_line_error(proc: subprocess.CompletedProcess[str]) -> str:
    """The CLI's contract for bad input: exit 2, one line on stderr starting 'pinmob: error:', no traceback."""
    assert proc.returncode == 2, proc.stderr
    assert "Traceback" not in proc.stderr
    assert proc.stderr.startswith("pinmob: error: ") and proc.stderr.count("\n") == 1, proc.stderr
    return proc.stderr


@pytest.mark.parametrize(
    ("args", "line"),
    [
        (
            ["analyze", "3-PUU", "--cofnig", "generic"],
            "unrecognized arguments: --cofnig generic; see 'pinmob analyze --help'",
        ),
        (["analyze", "3-PUU", "--config"], "argument --config/-c: expected one argument; see 'pinmob analyze --help'"),
        (["scan", "6-UPS", "-n", "x"], "argument --samples/-n: invalid int value: 'x'; see 'pinmob scan --help'"),
        (["models", "--jsno"], "unrecognized arguments: --jsno; see 'pinmob models --help'"),
        (["anlyze", "3-PUU"], "argument command: invalid choice: 'anlyze' (choose from"),
    ],
)
def test_mistyped_command_line_points_to_the_right_help(args, line):
    """One line naming the bad argument and the help that lists the valid ones: the command's own help for its
    options (argparse reported unknown options on the top level, whose help does not list them)."""
    assert line in one_line_error(cli(*args))


BAD_INPUT = {
    # unknown frame: the message names the key path, the bad frame and lists the valid ones
    "frame": ('tip = "B_tip"', 'tip = "B_tpi"', r"limbs\[1\]\.tip: no frame 'B_tpi'.*valid frames: .*'B_tip'"),
    # a configuration that does not close: per-limb residuals
    "closure": (
        "A_slider = 0.0",
        "B_slider = 0.05",
        r"configuration 'home' of 'copy' does not close: residuals .*B: 5",
    ),
    # NaN in the file
    "nan": ("A_slider = 0.0", "A_slider = nan", r"configurations\.home\.joints\.A_slider must be a finite number"),
    # wrong number of values: a pose position with two numbers, a joint with a list
    "count": ("joints = { A_slider = 0.0 }", "pose = { xyz = [0.0, 0.2] }", r"pose\.xyz must be a list of 3 numbers"),
    "list": ("A_slider = 0.0", "A_slider = [0.0, 0.1]", r"joints\.A_slider must be a finite number .* got array"),
}


@pytest.mark.parametrize("case", sorted(BAD_INPUT))
def test_cli_bad_input_in_a_subprocess(tmp_path: Path, case: str) -> None:
    old, new, message = BAD_INPUT[case]
    models = pinmob.io.builtin_dir()
    (tmp_path / "3puu.urdf").write_text((models / "3puu.urdf").read_text())
    text = (
        'name = "copy"\nurdf = "3puu.urdf"\n[[limbs]]\nname = "A"\ntip = "A_tip"\n[[limbs]]\nname = "B"\n'
        'tip = "B_tip"\n[configurations.home]\njoints = { A_slider = 0.0 }\n'
    )
    assert old in text
    (tmp_path / "m.toml").write_text(text.replace(old, new))
    err = one_line_error(cli("analyze", str(tmp_path / "m.toml"), "--config", "home"))
    assert re.search(message, err), err
    assert (tmp_path / "m.toml").read_text() == text.replace(old, new)  # nothing the user gave is changed


def test_cli_urdf_parser_text_goes_into_the_one_line(tmp_path: Path) -> None:
    """urdfdom prints 'Error: ... at line N in .../joint.cpp' on fd 2; pinmob captures it into its message."""
    (tmp_path / "r.urdf").write_text(
        '<robot name="r"><link name="a"/><link name="b"/>'
        '<joint name="j" type="revolute"><parent link="a"/><child link="b"/></joint></robot>'
    )
    (tmp_path / "m.toml").write_text('name = "r"\nurdf = "r.urdf"\n[[limbs]]\nname = "A"\ntip = "b"\n')
    err = one_line_error(cli("analyze", str(tmp_path / "m.toml")))
    assert "does not parse" in err and "does not specify limits" in err and "joint.cpp" not in err


def test_cli_usage_errors_are_one_line() -> None:
    for args in (["analyze"], ["analyze", "3-PUU", "--rtol", "x"], ["nope"], []):
        err = one_line_error(cli(*args))
        assert "usage:" not in err and "--help" in err
    proc = cli("analyze", "--help")
    assert proc.returncode == 0 and proc.stdout.startswith("usage: pinmob analyze") and "--paper-view" in proc.stdout


def test_cli_runs_with_stderr_closed() -> None:
    """`pinmob analyze ... 2>&-`: Python starts with sys.stderr None; the answer is printed all the same (it
    exited 1 with nothing printed: an AttributeError on flushing None, turned into an UnboundLocalError), and an
    error still exits 2 (its message has nowhere to go)."""

    def close_stderr() -> None:
        os.close(2)

    ok = subprocess.run(
        [sys.executable, "-m", "pinmob", "analyze", "3-PUU", "--brief"],
        stdout=subprocess.PIPE,
        text=True,
        preexec_fn=close_stderr,
    )
    assert ok.returncode == 0 and ok.stdout.startswith("3-PUU at 'generic': 3 DoF, 3T"), ok
    bad = subprocess.run(
        [sys.executable, "-m", "pinmob", "analyze", "nothing-of-the-kind"],
        stdout=subprocess.PIPE,
        text=True,
        preexec_fn=close_stderr,
    )
    assert bad.returncode == 2 and bad.stdout == "", bad


def test_cli_closed_pipe_is_quiet() -> None:
    """`pinmob analyze ... | head -1`: the reader is gone before pinmob writes; no BrokenPipeError traceback.

    The pipe's read end is closed before the child starts, so its first write fails with EPIPE for sure.
    """
    read, write = os.pipe()
    os.close(read)
    try:
        proc = subprocess.run(
            [sys.executable, "-m", "pinmob", "analyze", "3-PUU-flat", "--config", "flat"],
            stdout=write,
            stderr=subprocess.PIPE,
            text=True,
        )
    finally:
        os.close(write)
    assert proc.stderr == ""
    assert proc.returncode == 128 + 13  # as a process killed by SIGPIPE reports itself to a shell


PROBE = """
import sys
from pinmob.cli import _interrupted
try:
    exec("raise KeyboardInterrupt")  # an interrupt through a string's evaluation, as in a dataclass made lazily
except KeyboardInterrupt:
    raise SystemExit({exit})
"""


def test_an_interrupt_through_an_evaluated_string_still_exits_130(tmp_path: Path) -> None:
    """CPython marks a process ended by Ctrl-C when a KeyboardInterrupt went through ``exec`` or ``eval`` of a
    string, caught or not, and kills it by SIGINT after its status (-2 seen by the parent, not 130). The CLI's
    interrupt exit clears the mark: 130 and its one line. The control, the same exit without it, shows the mark."""
    for name, exit_with in (("probe", "_interrupted()"), ("control", "130")):
        (tmp_path / f"{name}.py").write_text(PROBE.format(exit=exit_with))
    run = [subprocess.run([sys.executable, "-m", name], cwd=tmp_path, capture_output=True, text=True)
           for name in ("probe", "control")]  # fmt: skip
    assert (run[0].returncode, run[0].stderr) == (130, "pinmob: interrupted\n")
    assert run[1].returncode == -2, run[1].stderr


@pytest.mark.parametrize("cause", [KeyboardInterrupt, ValueError])
def test_a_system_error_caused_by_an_interrupt_is_the_interrupt(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str], cause: type[BaseException]
) -> None:
    """An interrupt inside a library's C code that went on (numba's compiled code unpickling a kernel's constants
    on its first call) comes out wrapped in SystemErrors, one a level (six deep in a scan sent SIGTERM while its
    batch analysis loaded): status 130 and one line. Any other SystemError is not hidden."""
    from pinmob.cli import COMMANDS

    def interrupted_inside(args: object) -> int:
        def level(depth: int) -> None:
            try:
                if depth == 0:
                    raise cause()
                level(depth - 1)
            except BaseException as exc:
                raise SystemError("<function _numba_unpickle> returned a result with an exception set") from exc

        level(5)
        return 0

    monkeypatch.setitem(COMMANDS, "models", interrupted_inside)
    if cause is KeyboardInterrupt:
        assert main(["models"]) == 130
        assert capsys.readouterr().err == "pinmob: interrupted\n"
    else:
        with pytest.raises(SystemError):
            main(["models"])


FROZEN = """
import gc, sys
from pinmob.cli import console, main
if sys.argv[1] == "console":
    sys.argv = ["pinmob", "glossary", "DoF"]
    status = console()
else:
    status = main(["glossary", "DoF"])
print("status", status, gc.get_freeze_count(), file=sys.stderr)
"""


def test_the_console_script_freezes_its_imports_and_main_does_not() -> None:
    """``pinmob`` and ``python -m pinmob`` (:func:`pinmob.cli.console`) move the objects of their imports out of
    the collector's full passes (``gc.freeze``); :func:`pinmob.cli.main`, which tests and scripts call in their own
    process, leaves the collector alone. Both give the command's status (fresh interpreters each), and the
    installed script is console's."""
    frozen = {}
    for how in ("console", "main"):
        out = subprocess.run(
            [sys.executable, "-c", FROZEN, how], capture_output=True, text=True, check=True, timeout=120
        )
        (status, count) = next(ln.split()[1:] for ln in out.stderr.splitlines() if ln.startswith("status"))
        assert status == "0", out.stderr
        frozen[how] = int(count)
    assert frozen["main"] == 0 and frozen["console"] > 10_000  # the interpreter's, numpy's, Pinocchio's, pinmob's
    assert cli("glossary", "DoF").returncode == 0
    import tomllib

    project = tomllib.loads((Path(__file__).resolve().parent.parent / "pyproject.toml").read_text())
    assert project["project"]["scripts"] == {"pinmob": "pinmob.cli:console"}
