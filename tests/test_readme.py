"""The README is the first thing users try: its commands and snippet print what it says they print.

Run as a user would, with the installed ``pinmob`` entry point (``python -m pinmob`` when there is none), in a
fresh folder holding links to the checkout's ``tests/`` (paths such as ``tests/data/...`` work, files written
by a command such as ``flat.html`` land in the fresh folder):

* every ```` ```text ```` block made of ``$ pinmob ...`` lines, each followed by its output;
* the first command (in the ```` ```bash ```` block of "Two commands") and the output block that follows it;
* every ```` ```python ```` block followed by "prints" and a ```` ```text ```` block.

Output is stdout and stderr as a terminal shows them (interleaved in the order written), compared line by line.
Exact, except for what legitimately differs between runs and machines (:func:`same_line`):

* a line ``...`` in the README stands for any lines (an excerpt);
* numbers below 1e-6 in magnitude are round-off (1e-6 is the analysis' rank tolerance, below which pinmob
  counts a value as zero): any two of them match (e.g. ``8.9e-16 rad`` and ``0 rad``, a residual
  ``5.4e-16``);
* in ``N samples in T s (R samples/s, W worker(s))`` (a scan) and ``N designs computed in T s (R designs/s, W
  worker(s), ...)`` (a sweep) the elapsed time T and the rate R are timings: any numbers match there;
* in an output that says ``cannot decide`` (a finite-mobility verdict left undecided), the ``note:`` lines
  give its reasons in words, and their numbers match any numbers (not the digits of a name such as ``T1``,
  which must match): what cannot be decided sits at its
  tolerance, so its residuals and counts of samples are round-off (the Delta with horizontal rods: a linear
  component's order-2 condition 1.06e-07 to 5.95e-07 against the tolerance 4.15e-07, and 5 to 8 closed samples
  off the branches found, under four OpenBLAS kernels of one machine).

Nothing else may differ: a figure that round-off decides is not printed where the docs show it (the
iteration count of a failed solve; a scan's distance at a singularity is listed as ``distance <= 1e-06``).

The exit status must be 2 when the output shows ``pinmob: error:``, else 0.
"""

from __future__ import annotations

import os
import re
import shlex
import subprocess
import sys
from dataclasses import dataclass
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
README = ROOT / "README.md"
BLOCK = re.compile(r"^```(\w*)\n(.*?)^```$", re.MULTILINE | re.DOTALL)
NUMBER = re.compile(r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?")
TIMING = re.compile(r"(\d+ (?:samples|designs computed) in )[-+\d.eE]+( s \()[-+\d.eE]+( (?:samples|designs)/s)")
#: magnitude below which a printed number is round-off (the default rank tolerance rtol)
ROUND_OFF = 1e-6
#: an output with these words holds a verdict left undecided: its ``note:`` lines' numbers are free
UNDECIDED = "cannot decide"


@dataclass(frozen=True)
class Example:
    """One documented run: a shell command (``pinmob ...``) or Python code, and the lines the README shows."""

    name: str
    command: list[str] | None
    code: str | None
    expected: list[str]


def blocks(text: str) -> list[tuple[str, str, int, int]]:
    """(language, body, start and end offsets) of every fenced block of a Markdown text."""
    return [(m.group(1), m.group(2), m.start(), m.end()) for m in BLOCK.finditer(text)]


def examples(text: str) -> list[Example]:
    """The README's runnable examples (module docstring), in order."""
    found: list[Example] = []
    fenced = blocks(text)
    for i, (lang, body, _, end) in enumerate(fenced):
        if lang == "text" and body.startswith("$ "):
            found.extend(commands(body))
        elif lang == "bash" and "/pinmob analyze" in body:
            args = shlex.split(body[body.index("/pinmob analyze") + 1 :].splitlines()[0])
            after = next(b for b in fenced[i + 1 :] if b[0] == "text")
            found.append(Example(f"first command: $ {' '.join(args)}", args, None, after[1].splitlines()))
        elif lang == "python" and i + 1 < len(fenced):
            between = text[end : fenced[i + 1][2]]
            if between.strip() == "prints" and fenced[i + 1][0] == "text":
                number = sum(e.code is not None for e in found) + 1
                found.append(Example(f"python snippet {number}", None, body, fenced[i + 1][1].splitlines()))
    return found


def commands(body: str) -> list[Example]:
    """The ``$ ...`` lines of a block's body, each with the lines after it up to the next (its output)."""
    found: list[Example] = []
    for line in body.splitlines():
        if line.startswith("$ "):
            found.append(Example(f"$ {line[2:]}", shlex.split(line[2:]), None, []))
        else:
            found[-1].expected.append(line)
    return found


def same_line(expected: str, actual: str, free_numbers: bool = False) -> bool:
    """One line of output against the README's (module docstring: round-off numbers, timings).

    ``free_numbers``: only the words and the names' digits must match (an undecided verdict's note).
    """
    expected, actual = TIMING.sub(r"\1T\2R\3", expected), TIMING.sub(r"\1T\2R\3", actual)
    if NUMBER.split(expected) != NUMBER.split(actual):
        return False
    if free_numbers:  # a label's digits (T1, R2 y) still count
        return labels(expected) == labels(actual)
    for a, b in zip(NUMBER.findall(expected), NUMBER.findall(actual)):
        if a != b and not (abs(float(a)) < ROUND_OFF and abs(float(b)) < ROUND_OFF):
            return False
    return True


def labels(line: str) -> list[str]:
    """The digits of the names in ``line``: each number written right after a letter (``T1``, ``R2``, ``sv3``)."""
    return [
        m.group(0)
        for m in NUMBER.finditer(line)
        if m.start() and line[m.start() - 1].isalpha() and m.group(0)[0].isdigit()
    ]


def matches(expected: list[str], actual: list[str]) -> bool:
    """Whether ``actual`` lines are ``expected``, where a line ``...`` stands for any lines.

    In an output that says ``cannot decide``, the numbers of the ``note:`` lines are free (module docstring).
    """
    undecided = any(UNDECIDED in line for line in expected)
    free = [undecided and line.lstrip().startswith("note:") for line in expected]

    def rest(i: int, j: int) -> bool:
        if i == len(expected):
            return j == len(actual)
        if expected[i] == "...":
            return any(rest(i + 1, k) for k in range(j, len(actual) + 1))
        return j < len(actual) and same_line(expected[i], actual[j], free[i]) and rest(i + 1, j + 1)

    return rest(0, 0)


def pinmob_command() -> list[str]:
    """The installed entry point beside this Python, else ``python -m pinmob``."""
    script = Path(sys.executable).parent / "pinmob"
    return [str(script)] if script.exists() else [sys.executable, "-m", "pinmob"]


def environment() -> dict[str, str]:
    """The examples' environment: this one, unbuffered (stdout and stderr in the order written), 200 columns."""
    return os.environ | {"PYTHONUNBUFFERED": "1", "COLUMNS": "200"}


def run(example: Example, cwd: Path) -> subprocess.CompletedProcess[str]:
    env = environment()
    if example.command is not None:
        assert example.command[0] == "pinmob", example.name
        argv = pinmob_command() + example.command[1:]
    else:
        argv = [sys.executable, "-c", example.code or ""]
    return subprocess.run(
        argv, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, cwd=cwd, env=env, timeout=300
    )


EXAMPLES = examples(README.read_text())


def test_readme_examples_are_found():
    """The parser finds what the README shows: its one example, the first command with its output (the other
    examples are on the docs pages, run by ``tests/test_docs_examples.py``)."""
    names = [e.name for e in EXAMPLES]
    assert names == ["first command: $ pinmob analyze 3-PUU --config generic"], names
    assert all(len(e.expected) >= 20 for e in EXAMPLES), names


@pytest.mark.parametrize("example", EXAMPLES, ids=[e.name for e in EXAMPLES])
def test_readme_example_prints_what_the_readme_shows(example, tmp_path):
    (tmp_path / "tests").symlink_to(ROOT / "tests")
    out = run(example, tmp_path)
    lines = out.stdout.splitlines()
    shown = "\n".join(lines)
    assert matches(example.expected, lines), f"{example.name} printed:\n{shown}"
    error = any(line.startswith("pinmob: error:") for line in lines)
    assert out.returncode == (2 if error else 0), f"{example.name}: exit status {out.returncode}\n{shown}"


@pytest.mark.parametrize(
    ("expected", "actual", "same"),
    [
        (["a 0.0424 m, 8.9e-16 rad"], ["a 0.0424 m, 0 rad"], True),
        (["a 0.0424 m"], ["a 0.0425 m"], False),
        (["distance 2.67e-12"], ["distance 2e-06"], False),
        (
            ["7 samples in 0.09 s (82.1 samples/s, 1 worker(s))"],
            ["7 samples in 1.5 s (4.7 samples/s, 1 worker(s))"],
            True,
        ),
        (
            ["7 samples in 0.09 s (82.1 samples/s, 1 worker(s))"],
            ["8 samples in 0.09 s (82.1 samples/s, 1 worker(s))"],
            False,
        ),
        (
            ["7 samples in 0.09 s (82.1 samples/s, 1 worker(s))"],
            ["7 samples in 0.09 s (82.1 samples/s, 2 worker(s))"],
            False,
        ),
        (
            ["49 designs computed in 33.3 s (1.47 designs/s, 2 worker(s), Dask LocalCluster)"],
            ["49 designs computed in 4.4 s (11.09 designs/s, 2 worker(s), Dask LocalCluster)"],
            True,
        ),
        (
            ["49 designs computed in 33.3 s (1.47 designs/s, 2 worker(s), Dask LocalCluster)"],
            ["48 designs computed in 33.3 s (1.47 designs/s, 2 worker(s), Dask LocalCluster)"],
            False,
        ),
        (
            ["a: cannot decide", "  note: a condition: 1.06e-07 is within a factor 10 of the tolerance 4.15e-07"],
            ["a: cannot decide", "  note: a condition: 5.95e-07 is within a factor 10 of the tolerance 4.15e-07"],
            True,
        ),
        (["a: cannot decide", "  note: 7 samples lie off"], ["a: cannot decide", "  note: 5 samples lie off"], True),
        (["a: cannot decide", "  note: 7 samples lie off"], ["a: cannot decide", "  note: 5 samples are off"], False),
        (["a: cannot decide", "  7 samples lie off"], ["a: cannot decide", "  5 samples lie off"], False),
        (["a: finite", "  note: 7 samples lie off"], ["a: finite", "  note: 5 samples lie off"], False),
        (["a: cannot decide 2", "  note: x"], ["a: cannot decide 3", "  note: x"], False),
        (
            ["a: cannot decide", "  note: T1 z, R1 x at order-2"],
            ["a: cannot decide", "  note: T1 z, R1 x at order-4"],
            True,
        ),
        (
            ["a: cannot decide", "  note: T1 z, R1 x at order-2"],
            ["a: cannot decide", "  note: T1 z, R2 x at order-2"],
            False,
        ),
        (["did not converge: residuals 4.39e-02 m"], ["did not converge: residuals 4.40e-02 m"], False),
        (["x", "...", "y"], ["x", "1", "2", "y"], True),
        (["x", "...", "y"], ["x", "y"], True),
        (["x", "...", "y"], ["x", "1", "z"], False),
        (["x"], ["x", "extra"], False),
        (["x", "y"], ["x"], False),
    ],
)
def test_comparison_rule(expected, actual, same):
    """The rule of the module docstring: what it lets through, and what it does not."""
    assert matches(expected, actual) == same


def test_print_report_is_what_the_cli_prints():
    """The README: ``print(report)`` prints exactly what the installed ``pinmob analyze`` prints."""
    import pinmob

    report = pinmob.analyze(pinmob.load("3-PUU"), "generic")
    cli = subprocess.run(
        [*pinmob_command(), "analyze", "3-PUU", "--config", "generic"], capture_output=True, text=True, timeout=120
    )
    assert cli.returncode == 0 and cli.stdout == str(report) + "\n"
