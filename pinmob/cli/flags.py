"""The library's Python parameters as the command line's options, in the errors and reports the command line prints.

The library words its errors with its Python parameters (``closure_tol=2e-05 would accept it``, ``rtol must be
...``) and says which ones a message names (:attr:`pinmob.exceptions.PinmobError.parameters`); the command line
prints them as the options a user of the command line types: ``name=value`` becomes ``--flag value (Python:
name=value)`` (``--flag (Python: name=True)`` for a switch), and ``name`` as the subject of ``must`` or in
parentheses becomes ``--flag``. A parameter in backticks is advice rather than the culprit: ```name``` becomes
``--flag``, ```name=value``` ``--flag value`` (``--flag`` for a switch), with no Python aside.

Reports are library output too (``str(report)`` in Python): their texts name parameters in backticks only
(``set `rtol` / `closure_tol```, ``see `paper=True```), and :func:`worded_report` words the parameters of
:data:`REPORT_PARAMETERS` and the report parts' keywords as options where the command line prints a report.
"""

from __future__ import annotations

import re
from collections.abc import Iterable
from functools import partial

from pinmob.analysis import FIX_HINT, part_keywords
from pinmob.exceptions import PinmobError

#: Python parameter -> the option of the command line that gives it (the report parts' keywords: :func:`flag`)
FLAGS = {
    "rtol": "--rtol",
    "closure_tol": "--closure-tol",
    "restarts": "--restarts",
    "relax": "--relax",
    "actuated": "--actuated",
    "frames": "--frame",
    "joints": "--joints",
    "scheduler": "--scheduler",
    "workers": "--workers",
    "samples": "--samples",
    "steps": "--steps",
    "axes": "--grid",  # pinmob.scan.grid_spec's axes
    "force": "--force",  # pinmob.output_files.check_target's and the sweep Store's
    "overwrite": "--force",  # pinmob.viewer.export_html's
    "target": "--out",  # the sweep Store's file (pinmob.sweeps.store.Store)
    "index": "--sample",  # the scan's sample drawn in 3D (pinmob.viewer.workspace.sample_configuration)
}

#: The parameters a report's text may name (in backticks), worded as options by :func:`worded_report`, besides the
#: registered report parts' keywords (:data:`pinmob.analysis.report.REPORT_PARTS`)
REPORT_PARAMETERS = ("rtol", "closure_tol", "actuated")


def flag(parameter: str) -> str | None:
    """The option of the command line that gives the Python ``parameter`` (a registered part's from its registration)."""
    if parameter in FLAGS:
        return FLAGS[parameter]
    option = part_keywords().get(parameter)
    return None if option is None or option.option is None else f"--{option.option}"


def worded_for_cli(exc: PinmobError) -> str:
    """The message of ``exc`` with each Python parameter it names worded as its command-line option."""
    return worded(str(exc), exc.parameters)


#: The report's phrases that name a Python call, and the command that does it on the command line
REPORT_CALLS = {FIX_HINT: "the corrected file: pinmob fix FILE --output OUT"}


def worded_report(text: str) -> str:
    """A report's text (``str(report)``, its brief line) with the parameters it names in backticks as options.

    The Python calls it names (:data:`REPORT_CALLS`) become their commands.
    """
    for call, command in REPORT_CALLS.items():
        text = text.replace(call, command)
    return worded(text, (*REPORT_PARAMETERS, *part_keywords()), marked_only=True)


def worded(text: str, parameters: Iterable[str], marked_only: bool = False) -> str:
    """``text`` with each of ``parameters`` that it names worded as its option (only in backticks: ``marked_only``)."""
    for parameter in parameters:
        option = flag(parameter)
        if option is not None:
            text = _mention(parameter, marked_only).sub(partial(_worded, flag=option), text)
    return text


def _mention(parameter: str, marked_only: bool) -> re.Pattern[str]:
    """```name``` or ```name=value```; unless ``marked_only`` also ``name=value``, ``name must`` or ``(name)``."""
    name = re.escape(parameter)
    marked = rf"`{name}(?:=(?P<m>[^`]+))?`"
    if marked_only:
        return re.compile(marked)
    return re.compile(
        rf"{marked}|(?<![\w.-])(?P<p>{name})=(?P<v>[^\s,;)]+)|(?<![\w.-]){name}(?= must\b)|(?<=\(){name}(?=\))"
    )


def _worded(match: re.Match[str], flag: str) -> str:
    if match[0].startswith("`"):
        return flag if match["m"] in (None, "True") else f"{flag} {match['m']}"
    if match.groupdict().get("v") is None:
        return flag
    if match["v"] == "True":
        return f"{flag} (Python: {match[0]})"
    return f"{flag} {match['v']} (Python: {match[0]})"
