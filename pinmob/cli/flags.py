"""The library's Python parameters as the command line's options, in the errors the command line prints.

The library words its errors with its Python parameters (``closure_tol=2e-05 would accept it``, ``rtol must be
...``) and says which ones a message names (:attr:`pinmob.exceptions.PinmobError.parameters`); the command line
prints them as the options a user of the command line types: ``name=value`` becomes ``--flag value (Python:
name=value)`` (``--flag (Python: name=True)`` for a switch), and ``name`` as the subject of ``must`` or in
parentheses becomes ``--flag``.
"""

from __future__ import annotations

import re
from functools import partial

from pinmob.exceptions import PinmobError

#: Python parameter -> the option of the command line that gives it
FLAGS = {
    "rtol": "--rtol",
    "closure_tol": "--closure-tol",
    "restarts": "--restarts",
    "relax": "--relax",
    "paper": "--paper-view",
    "finite_order": "--finite-order",
    "actuator_search": "--search-actuators",
    "joints": "--joints",
    "scheduler": "--scheduler",
    "samples": "--samples",
}


def worded_for_cli(exc: PinmobError) -> str:
    """The message of ``exc`` with each Python parameter it names worded as its command-line option."""
    message = str(exc)
    for parameter in exc.parameters:
        flag = FLAGS.get(parameter)
        if flag is not None:
            message = _mention(parameter).sub(partial(_worded, flag=flag), message)
    return message


def _mention(parameter: str) -> re.Pattern[str]:
    """``name=value``, ``name must`` or ``(name)``: where a message names the parameter."""
    name = re.escape(parameter)
    return re.compile(rf"(?<![\w.-])(?P<p>{name})=(?P<v>[^\s,;)]+)|(?<![\w.-]){name}(?= must\b)|(?<=\(){name}(?=\))")


def _worded(match: re.Match[str], flag: str) -> str:
    if match["v"] is None:
        return flag
    if match["v"] == "True":
        return f"{flag} (Python: {match[0]})"
    return f"{flag} {match['v']} (Python: {match[0]})"
