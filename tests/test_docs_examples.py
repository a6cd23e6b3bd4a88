"""The commands shown in ``docs/*.md`` print what the docs show, by the README's rule (``tests/test_readme.py``).

A docs block whose first line starts with ``$ pinmob`` is a documented run. Its fence says whether it is run:

* ```` ```console ```` or ```` ```text ````: run and compared. Its ``$ ...`` lines run in order in one fresh
  folder (a later command may see what an earlier one wrote, e.g. ``--html flat.html`` twice), each compared
  with the lines after it, exactly as the README's examples (:func:`test_readme.matches`: a ``...`` line
  stands for any lines, numbers below 1e-6 match each other, timings match any timing, the notes of a
  verdict that cannot decide match by their words; the exit status is 2 when the output shows ``pinmob:
  error:``, else 0).
* ```` ```shell ````: shown, not run. Only for a block that cannot run standalone: one that starts a server
  that keeps running (``show --detach``), needs files no block or snippet of its page makes, writes into the
  repository, or takes too long for the test suite (the prose beside such a block says why). They are listed
  in ``SHOWN_ONLY``: :func:`test_every_documented_run_says_whether_it_runs` fails on a ``$ pinmob`` block with
  any other fence, and on a ```` ```shell ```` block not listed, so that not running one is a decision.

A ```` ```python ```` snippet followed by the word "prints" and a ```` ```text ```` block runs with this Python in a
fresh folder (the same links) and must print that block, by the same rule.

The fresh folder holds links to the checkout's ``tests/`` and ``examples/`` (so ``tests/data/...`` and
``examples/3puu_sweep.toml`` work) and an empty ``docs/img/`` folder, so that ``--plot docs/img/x.png``
writes there and nothing in the checkout changes. Before a block's commands, every ```` ```python ````
snippet above it on its page that writes into ``my_models/`` (the builder's examples) is run there, in
order, with this Python: the commands then analyse the files the snippets wrote, as a reader following the
page would; so is every ```` ```xml ```` or ```` ```toml ```` block above it whose first line is a comment
naming a file under ``my_models/`` (``<!-- my_models/five_bar.urdf -->``): the file is written there with the
block's text, as a reader copies it (the tutorial's URDF, TOML and MJCF). A command line with a pipe (``| python3 -c ...``, ``| grep ...``) runs through ``bash -c`` with
``set -o pipefail``, ``pinmob`` being the same entry point as for the other commands and this Python's
folder first on ``PATH`` (so ``python3`` is this Python).
"""

from __future__ import annotations

import re
import shlex
import subprocess
import sys
from dataclasses import dataclass
from pathlib import Path

import pytest
from test_readme import Example, blocks, commands, environment, examples, matches, pinmob_command, run

ROOT = Path(__file__).resolve().parent.parent
DOCS = sorted((ROOT / "docs").glob("*.md"))
#: fences of the documented runs that are run and compared; ``SHOWN`` is shown only
RUN = ("console", "text")
SHOWN = "shell"
#: the blocks shown and not run, by page and the start of their first line (each page says why beside it)
SHOWN_ONLY = [
    ("models.md", "$ pinmob analyze my_models/wrong.toml "),  # the reader's file, exit status 1
    ("viewer.md", "$ pinmob show 3-PUU --detach"),  # leaves a meshcat server running
]


@dataclass(frozen=True)
class DocBlock:
    """One ``$ pinmob`` block of a docs page: where it is, its fence, the snippets it needs and its commands."""

    page: str
    line: int
    language: str
    setup: tuple[str, ...]
    examples: tuple[Example, ...]

    @property
    def name(self) -> str:
        return f"{self.page}:{self.line}"


def documented_runs(page: Path) -> list[DocBlock]:
    """Every block of ``page`` whose first line starts with ``$ pinmob``, with the snippets run before it."""
    text = page.read_text()
    found: list[DocBlock] = []
    snippets: list[str] = []
    for language, body, start, _ in blocks(text):
        if language == "python" and "my_models" in body:
            snippets.append(body)
        written = FILE_BLOCK.match(body)
        if language in ("xml", "toml") and written:  # a file the reader writes: the snippet writes it
            path = written.group(1)
            snippets.append(f"from pathlib import Path\nPath({path!r}).parent.mkdir(parents=True, exist_ok=True)\n"
                            f"Path({path!r}).write_text({body!r})\n")  # fmt: skip
        if body.startswith("$ pinmob"):
            line = text.count("\n", 0, start) + 1
            found.append(DocBlock(page.name, line, language, tuple(snippets), tuple(commands(body))))
    return found


#: an ```` ```xml ```` or ```` ```toml ```` block whose first line is a comment naming a file under ``my_models/``
#: (``<!-- my_models/five_bar.urdf -->``, ``# my_models/five_bar.toml``): the file a reader following the page
#: writes, written before the page's later commands run
FILE_BLOCK = re.compile(r"(?:<!--|#) (my_models/[\w./-]+?)(?: -->)?\n")


BLOCKS = [block for page in DOCS for block in documented_runs(page)]
RUNS = [block for block in BLOCKS if block.language in RUN]
#: every ```` ```python ```` snippet followed by "prints" and the ```` ```text ```` block of its output, by page
SNIPPETS = [
    (f"{page.name}:{example.name}", example)
    for page in DOCS
    for example in examples(page.read_text())
    if example.code is not None
]


def run_line(example: Example, cwd: Path) -> subprocess.CompletedProcess[str]:
    """Run one ``$`` line: as :func:`test_readme.run`, or through ``bash -c`` when it has a pipe."""
    line = example.name[2:]
    if "|" not in (example.command or []):
        return run(example, cwd)
    bin_folder = str(Path(sys.executable).parent)
    env = environment()
    env["PATH"] = bin_folder + ":" + env.get("PATH", "")
    script = f'set -o pipefail; pinmob() {{ {shlex.join(pinmob_command())} "$@"; }}; {line}'
    return subprocess.run(
        ["bash", "-c", script],
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
        cwd=cwd,
        env=env,
        timeout=300,
    )


def test_docs_examples_are_found():
    """The parser finds the docs' runs on every page that shows one, and most of them are run."""
    pages = {block.page for block in BLOCKS}
    assert pages >= {"closed-chains.md", "finite-mobility.md", "models.md", "singularities.md", "viewer.md"}, pages
    assert len(BLOCKS) >= 30 and len(RUNS) >= 25, [b.name for b in BLOCKS]
    assert all(e.expected for block in RUNS for e in block.examples), [b.name for b in RUNS]
    four_bar = next(b for b in RUNS if "my_models/four_bar" in b.examples[0].name)  # the builder's, with its setup
    assert len(four_bar.setup) == 2 and "four_bar" in four_bar.setup[-1], four_bar.setup
    assert {"usage.md", "seed-paper.md"} <= pages, pages  # the pages that took the README's examples


def test_docs_snippets_are_found():
    """The Python snippets shown with what they print: the Report's tour and the finite analysis' at least."""
    names = [name for name, _ in SNIPPETS]
    assert any(n.startswith("python-api.md:") for n in names) and any(
        n.startswith("finite-mobility.md:") for n in names
    )
    assert all(example.expected for _, example in SNIPPETS), names


def test_every_documented_run_says_whether_it_runs():
    """A ``$ pinmob`` block is fenced ```` ```console ````/```` ```text ```` (run) or ```` ```shell ```` (shown)."""
    unmarked = [f"{b.name} (```{b.language})" for b in BLOCKS if b.language not in (*RUN, SHOWN)]
    assert not unmarked, f"fence these ```console/```text (run) or ```shell (not run, say why): {unmarked}"
    shown = [(b.page, b.examples[0].name) for b in BLOCKS if b.language == SHOWN]
    assert len(shown) == len(SHOWN_ONLY), f"new ```shell blocks (run them if they can run, else list them): {shown}"
    assert all(page == p and name.startswith(start) for (page, name), (p, start) in zip(shown, SHOWN_ONLY)), shown


@pytest.mark.parametrize("block", RUNS, ids=[b.name for b in RUNS])
def test_docs_example_prints_what_the_docs_show(block, tmp_path):
    for folder in ("tests", "examples"):
        (tmp_path / folder).symlink_to(ROOT / folder)
    (tmp_path / "docs" / "img").mkdir(parents=True)
    for number, code in enumerate(block.setup, 1):
        done = run(Example(f"snippet {number}", None, code, []), tmp_path)
        assert done.returncode == 0, f"{block.name}: the page's snippet {number} failed:\n{done.stdout}"
    for example in block.examples:
        out = run_line(example, tmp_path)
        lines = out.stdout.splitlines()
        shown = "\n".join(lines)
        assert matches(example.expected, lines), f"{block.name}: {example.name} printed:\n{shown}"
        error = any(line.startswith("pinmob: error:") for line in lines)
        status = 2 if error else 0
        assert out.returncode == status, f"{block.name}: {example.name}: exit status {out.returncode}\n{shown}"


@pytest.mark.parametrize(("name", "example"), SNIPPETS, ids=[name for name, _ in SNIPPETS])
def test_docs_snippet_prints_what_the_docs_show(name, example, tmp_path):
    for folder in ("tests", "examples"):
        (tmp_path / folder).symlink_to(ROOT / folder)
    out = run(example, tmp_path)
    lines = out.stdout.splitlines()
    shown = "\n".join(lines)
    assert out.returncode == 0 and matches(example.expected, lines), f"{name} printed:\n{shown}"
