"""The synopsis of ``docs/usage.md`` lists every option of every command, and nothing the parser lacks.

It had drifted: ``--amplitude``, ``--steps``, ``--port`` and ``--no-plots`` were missing. An option counts as
listed when one of its spellings is (``-n`` for ``--samples``); every ``-x``/``--xyz`` of the synopsis must be
one of the command's options.
"""

from __future__ import annotations

import argparse
import re
from pathlib import Path

import pytest

from pinmob.cli.parser import build_parser

USAGE = Path(__file__).resolve().parent.parent / "docs" / "usage.md"
#: an option in the synopsis: ``-n``, ``--closure-tol`` (not the ``-`` of a number or of ``a=-1``)
OPTION = re.compile(r"(?<![\w=.-])(--?[a-z][a-z-]*)")


#: the synopsis's widest line: its lines of up to 115 columns were cut in the documentation site's code block at
#: 1280 px; 88 columns fit there and in a terminal
WIDTH = 88


def synopsis_lines() -> list[str]:
    """The lines of the synopsis block of usage.md."""
    text = USAGE.read_text(encoding="utf-8")
    block = re.search(r"^## Synopsis\n.*?^```text\n(.*?)^```$", text, re.MULTILINE | re.DOTALL)
    assert block, "docs/usage.md has no ## Synopsis with a ```text block"
    return block.group(1).splitlines()


def synopsis() -> dict[str, str]:
    """Per command (``""`` for ``pinmob`` itself), the text of its lines in the synopsis block of usage.md."""
    found: dict[str, str] = {}
    command = None
    for line in synopsis_lines():
        if line.startswith("pinmob "):
            word = line.split()[1]
            command = "" if word.startswith("-") else word
            found[command] = found.get(command, "") + " " + line.removeprefix(f"pinmob {command}")
        elif line.startswith(" ") and command is not None:
            found[command] += " " + line
        else:
            command = None  # ``python -m pinmob ...``: the same
    return found


def parsers() -> dict[str, argparse.ArgumentParser]:
    parser = build_parser()
    sub = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    return {"": parser, **sub.choices}


def options(parser: argparse.ArgumentParser) -> list[tuple[str, ...]]:
    """The spellings of each option of ``parser``, ``--help`` left out."""
    return [tuple(a.option_strings) for a in parser._actions if a.option_strings and a.dest != "help"]


def test_the_synopsis_wraps():
    wide = [line for line in synopsis_lines() if len(line) > WIDTH]
    assert not wide, f"synopsis lines wider than {WIDTH} columns: {wide}"


def test_every_command_is_in_the_synopsis():
    assert sorted(synopsis()) == sorted(parsers())


@pytest.mark.parametrize("command", sorted(parsers()), ids=lambda c: c or "pinmob")
def test_the_synopsis_lists_the_options_of(command):
    text = synopsis()[command]
    listed = set(OPTION.findall(text))
    spellings = options(parsers()[command])
    missing = [s for s in spellings if not listed & set(s)]
    unknown = sorted(listed - {o for s in spellings for o in s})
    assert not missing and not unknown, f"pinmob {command}: missing {missing}, not options {unknown}"


def test_the_rule_reads_options_not_numbers():
    assert OPTION.findall(" [--rtol 1e-6] [-n N] [--joints a=-0.1,b=0.2] [--steps 12] x-y") == [
        "--rtol",
        "-n",
        "--joints",
        "--steps",
    ]


@pytest.mark.parametrize("command", sorted(c for c in parsers() if c), ids=str)
def test_a_parser_of_one_command_parses_and_helps_as_the_whole(command):
    """``build_parser(command)`` (what ``pinmob COMMAND ...`` builds) gives that command's help, its options and the
    top-level help of the parser of every command; the other commands are listed, without their options."""
    from pinmob.cli.parser import parsed_command

    assert parsed_command([command, "--help"]) == command
    assert parsed_command(["--version", command, "x"]) == command
    assert parsed_command(["--", command]) is None and parsed_command(["--help"]) is None
    whole = build_parser()
    one = build_parser(command)
    sub = next(a for a in one._actions if isinstance(a, argparse._SubParsersAction))
    assert one.format_help() == whole.format_help()
    assert sub.choices[command].format_help() == parsers()[command].format_help()
    assert options(sub.choices[command]) == options(parsers()[command])
    assert all(not options(p) for c, p in sub.choices.items() if c != command)
