"""The keys of a pinmob mechanism file (TOML), their types, and the checks that name a bad key.

Every table of the file has a spec ``{key: Kind}``; :func:`check_table` rejects
unknown keys and values of the wrong type with a :class:`MechanismFileError`
naming the file, the key path (e.g. ``limbs[0].tip``), the value and the valid keys.
TOML booleans are not numbers here (``dof = true`` is an error).

:func:`toml_string` and :func:`toml_key` write a string and a key as TOML 1.0 reads them back (the
builder's files and ``pinmob fix`` write through them); :func:`unicode_text` refuses a str that no UTF-8 file
can hold (a lone surrogate); both refuse such text through it.
"""

from __future__ import annotations

import math
import re
from collections.abc import Callable, Iterator, Mapping
from contextlib import contextmanager
from enum import Enum
from pathlib import Path
from typing import Any

import numpy as np

from pinmob.exceptions import ConfigurationError, MechanismFileError, PinmobError
from pinmob.name_matching import choices, did_you_mean


def file_error(path: Path, msg: str) -> MechanismFileError:
    """``MechanismFileError("<path>: <msg>")``: an error in a mechanism file, naming the file."""
    return MechanismFileError(f"{path}: {msg}")


@contextmanager
def errors_at(path: Path) -> Iterator[None]:
    """Name ``path`` in any :class:`PinmobError` raised inside (a :class:`MechanismFileError` names it already)."""
    try:
        yield
    except MechanismFileError:
        raise
    except PinmobError as exc:
        raise type(exc)(f"{path}: {exc}") from None


class Kind(Enum):
    """TOML value types a key of a mechanism file accepts (the value is the phrase used in messages)."""

    STRING = "a string"
    NUMBER = "a number"
    INTEGER = "an integer"
    TABLE = "a table"
    TABLES = "an array of tables"
    STRINGS = "an array of strings"
    NUMBERS = "an array of numbers"


def _is_number(value: object) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool)


def finite_number(value: object) -> bool:
    """A number (not a boolean) that is finite as a float: TOML integers past 1.8e308 are not."""
    try:
        return _is_number(value) and math.isfinite(float(value))  # type: ignore[arg-type]
    except OverflowError:
        return False


KIND_CHECKS: dict[Kind, Callable[[Any], bool]] = {
    Kind.STRING: lambda v: isinstance(v, str),
    Kind.NUMBER: _is_number,
    Kind.INTEGER: lambda v: isinstance(v, int) and not isinstance(v, bool),
    Kind.TABLE: lambda v: isinstance(v, Mapping),
    Kind.TABLES: lambda v: isinstance(v, list) and all(isinstance(x, Mapping) for x in v),
    Kind.STRINGS: lambda v: isinstance(v, list) and all(isinstance(x, str) for x in v),
    Kind.NUMBERS: lambda v: isinstance(v, list) and all(_is_number(x) for x in v),
}

#: every key of a mechanism file and its type, per table
TOP_KEYS = {
    "name": Kind.STRING,
    "description": Kind.STRING,
    "urdf": Kind.STRING,
    "platform": Kind.STRING,
    "length_scale": Kind.NUMBER,
    "limbs": Kind.TABLES,
    "configurations": Kind.TABLE,
    "closures": Kind.TABLES,
    "actuated": Kind.STRINGS,
    "generic_rank": Kind.INTEGER,
}
CLOSURE_KEYS = {
    "name": Kind.STRING,
    "frames": Kind.STRINGS,
    "type": Kind.STRING,
    "axis": Kind.NUMBERS,
    "axis_b": Kind.NUMBERS,
}
LIMB_KEYS = {"name": Kind.STRING, "tip": Kind.STRING, "actuated": Kind.STRINGS}
CONFIG_KEYS = {
    "joints": Kind.TABLE,
    "pose": Kind.TABLE,
    "seed": Kind.TABLE,
    "approach": Kind.TABLE,
    "expected": Kind.TABLE,
}
POSE_KEYS = {"xyz": Kind.NUMBERS, "rpy": Kind.NUMBERS}
EXPECTED_KEYS = {"dof": Kind.INTEGER, "motion_type": Kind.STRING, "source": Kind.STRING}


def _toml_type(value: object) -> str:
    """TOML's name for the type of a parsed value (``boolean``, ``integer``, ``table``, ...)."""
    for types, name in ((bool, "boolean"), (int, "integer"), (float, "float"), (str, "string"), (list, "array")):
        if isinstance(value, types):
            return name
    return "table" if isinstance(value, Mapping) else type(value).__name__.replace("datetime", "date-time")


#: a bare TOML key (TOML 1.0): ASCII letters, digits, ``_`` and ``-``; any other key is quoted
BARE_KEY = re.compile(r"[A-Za-z0-9_-]+")
#: escapes of a TOML basic string, by code point: the control characters U+0000-U+001F and U+007F as ``\uXXXX``,
#: or by TOML's short form where it has one; the quote and the backslash
_ESCAPES = {c: f"\\u{c:04X}" for c in [*range(0x20), 0x7F]} | {
    ord(c): "\\" + short
    for c, short in (("\b", "b"), ("\t", "t"), ("\n", "n"), ("\f", "f"), ("\r", "r"), ('"', '"'), ("\\", "\\"))
}


#: a lone surrogate, U+D800-U+DFFF: a Python str can hold one (``chr(0xD800)``, a file name decoded with
#: ``surrogateescape``), Unicode text and UTF-8 cannot
_SURROGATE = re.compile("[\ud800-\udfff]")


def unicode_text(what: str, text: str, hint: str = "give text without U+D800-U+DFFF") -> str:
    """``text`` if UTF-8 can hold it; a lone surrogate in it is a :class:`ConfigurationError` naming ``what``.

    ``what`` says which text it is (``configuration name``); the message gives the surrogate, its place and ``hint``.
    """
    bad = _SURROGATE.search(text)
    if bad is not None:
        raise ConfigurationError(
            f"{what} {text!r} holds the lone surrogate {bad.group()!r} (character {bad.start() + 1}), which is no "
            "Unicode character: a file (UTF-8) cannot hold it; " + hint
        )
    return text


def toml_string(text: str) -> str:
    r"""``text`` as a TOML basic string, which a TOML parser reads back as ``text``.

    Escaped: ``"``, ``\`` and the control characters U+0000-U+001F and U+007F (``\b \t \n \f \r``, the others
    ``\uXXXX``); every other character is written as it is (UTF-8 in the file), e.g. ``"café"``.

    Raises:
        ConfigurationError: ``text`` holds a lone surrogate (:func:`unicode_text`), which TOML cannot hold.
    """
    return '"' + unicode_text("TOML string", text).translate(_ESCAPES) + '"'


def toml_key(key: str) -> str:
    """``key`` bare when TOML allows it (ASCII letters, digits, ``_``, ``-``), else quoted: ``é`` -> ``"é"``.

    Raises:
        ConfigurationError: ``key`` holds a lone surrogate (:func:`toml_string`).
    """
    return key if BARE_KEY.fullmatch(key) else toml_string(key)


def toml_text(value: object, limit: int = 80) -> str:
    """A parsed value written back as TOML (``true``, ``"text"``, ``[1, 2]``, ``{ "é" = 1 }``), cut at ``limit``.

    Strings and keys as :func:`toml_string` and :func:`toml_key` write them: a value not cut reads back
    (``tomllib.loads("v = " + text)``) as ``value``.
    """
    if isinstance(value, bool):
        text = "true" if value else "false"
    elif isinstance(value, str):
        text = toml_string(value)
    elif isinstance(value, float) and not math.isfinite(value):
        text = "nan" if math.isnan(value) else ("inf" if value > 0 else "-inf")
    elif isinstance(value, list):
        text = "[" + ", ".join(toml_text(v, limit) for v in value) + "]"
    elif isinstance(value, Mapping):
        text = "{ " + ", ".join(f"{toml_key(k)} = {toml_text(v, limit)}" for k, v in value.items()) + " }"
    else:  # numbers; dates and times as Python prints them, which TOML reads (a space for the T)
        text = str(value)
    return text if len(text) <= limit else text[: limit - 3] + "..."


def check_table(path: Path, where: str, table: Any, spec: Mapping[str, Kind]) -> Mapping[str, Any]:
    """Check that ``table`` is a table whose keys are in ``spec``, each of the type ``spec`` gives.

    Args:
        path: the mechanism file (named in messages).
        where: key path of the table (``""`` for the top level), e.g. ``limbs[0]``.
        table: the value found there.
        spec: the valid keys and the kind of value each takes.

    Raises:
        MechanismFileError: naming the file, the key path, the bad value or the valid keys.
    """
    label = where or "the top level"
    if not isinstance(table, Mapping):
        raise file_error(path, f"{label} must be a table, got {_toml_type(table)} {toml_text(table)}")
    unknown = set(table) - set(spec)
    if unknown:
        raise file_error(path, f"unknown key(s) {choices(unknown)} in {label}; valid keys: {choices(spec)}")
    for key, value in table.items():
        kind = spec[key]
        if kind is Kind.TABLES and isinstance(value, list):
            for i, item in enumerate(value):
                if not isinstance(item, Mapping):
                    raise file_error(
                        path, f"{_key(where, key)}[{i}] must be a table, got {_toml_type(item)} {toml_text(item)}"
                    )
        if not KIND_CHECKS[kind](value):
            shown = toml_text(value)
            raise file_error(path, f"{_key(where, key)} must be {kind.value}, got {_toml_type(value)} {shown}")
    return table


def _key(where: str, key: str) -> str:
    return f"{where}.{key}" if where else key


def joint_values(path: Path, where: str, table: Mapping[str, Any], joint_names: set[str]) -> dict[str, float]:
    """Joint values by name from a TOML table: known joints, finite numbers (errors name the key path)."""
    out = {}
    for k, v in table.items():
        if k not in joint_names:
            raise file_error(
                path,
                f"{where} names unknown joint {k!r}{did_you_mean(k, joint_names)}; "
                f"valid joints: {choices(joint_names)}",
            )
        if not finite_number(v):
            raise file_error(
                path, f"{where}.{k} must be a finite number [m or rad], got {_toml_type(v)} {toml_text(v)}"
            )
        out[k] = float(v)
    return out


def vector3(path: Path, where: str, value: list[float]) -> np.ndarray:
    """A 3-vector of finite numbers from a TOML array (errors name the key path)."""
    if len(value) != 3:
        raise file_error(path, f"{where} must be a list of 3 numbers, got {toml_text(value)}")
    if not all(finite_number(v) for v in value):
        raise file_error(path, f"{where} must be finite, got {toml_text(value)}")
    return np.array(value, float)
