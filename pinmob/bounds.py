"""Bounds on what an option or a file can cost: scan samples, animation steps, restarts, joints, file size.

A typing slip (``-n 1e8``, ``--steps 100000``, ``--restarts 1000000``) used to
run for minutes or exhaust the memory before anything was printed. Each bound
is generous for real use and can be raised through its environment variable;
:func:`check_bound` refuses a value over it with one line naming the option,
the bound and the variable.
"""

from __future__ import annotations

import os

from pinmob.exceptions import ArgumentError, ConfigurationError

#: what -> (default bound, the environment variable that raises it)
BOUNDS: dict[str, tuple[int, str]] = {
    "samples": (1_000_000, "PINMOB_MAX_SAMPLES"),
    "steps": (2_000, "PINMOB_MAX_STEPS"),
    "restarts": (10_000, "PINMOB_MAX_RESTARTS"),
    # Pinocchio's Data for n joints takes about n^3 / 20000 MB (200: 0.6 GB, 400: 4 GB); robots have tens
    "joints": (200, "PINMOB_MAX_JOINTS"),
    # of a mechanism file (TOML, YAML, URDF, MJCF and its includes): under 300 kB on this machine
    "bytes": (4_000_000, "PINMOB_MAX_FILE_BYTES"),
}


def bound(what: str) -> int:
    """The bound on ``what`` (a key of :data:`BOUNDS`): its environment variable if set, else the default."""
    default, variable = BOUNDS[what]
    text = os.environ.get(variable, "")
    if not text:
        return default
    try:
        value = int(text)
    except ValueError:
        value = 0
    if value <= 0:
        raise ConfigurationError(f"{variable} must be a positive whole number, got {text[:40]!r}")
    return value


def check_bound(what: str, value: int, option: str, parameter: str | None = None) -> int:
    """``value`` if it is within the bound on ``what``; else a :class:`ConfigurationError` naming ``option``.

    ``parameter``: the Python parameter that was given ``value``, written in ``option`` as ``(name)``; the error
    is then an :class:`ArgumentError` naming it (the command line words it as its option).

    Raises:
        ConfigurationError: ``value`` over the bound (the message says how to raise it).
    """
    limit = bound(what)
    if value > limit:
        message = (
            f"{option}: {value:,} {what}, over the bound of {limit:,}; ask for fewer, or set {BOUNDS[what][1]} "
            "to raise the bound"
        )
        raise ConfigurationError(message) if parameter is None else ArgumentError(message, parameter, value)
    return value
