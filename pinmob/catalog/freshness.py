"""Whether generated model files are up to date, up to round-off: one rule for the catalogue command and the tests.

Two versions of a generated file are *equivalent* when their texts are equal
with every number replaced by a marker, and their numbers are pairwise equal
within :data:`TOLERANCE` (absolute, in the file's units: m or rad), angles
modulo 2 pi: the revolute joint values of ``joints`` and ``seed`` tables
(joints of type ``revolute`` or ``continuous`` in the URDF beside the file) and
every ``rpy`` value (URDF origins, TOML poses).

Why 1e-9:

* far above round-off: the files carry 15 significant digits; regenerated with
  other BLAS kernels and without numpy's AVX-512/AVX2 code paths (what another
  machine does; ``OPENBLAS_CORETYPE`` and ``NPY_DISABLE_CPU_FEATURES``), the
  built-in models differed by at most 1e-14 (joint values of closed
  configurations found by the iterative closure solver, which stops at residuals
  of about 1e-12; geometry in the last printed digit), and an angle near pi can
  come out as its 2 pi twin (the Delta's rods-horizontal values once did);
* far below any physical meaning: a thousand times below the closure tolerance
  and the rank tolerance (both 1e-6, relative to the length scale L of 0.2-1 m
  for the built-in models), so two equivalent files give the same closed
  configurations, the same ranks and the same singularity classes.
"""

from __future__ import annotations

import re
import tomllib
from collections.abc import Collection, Iterator
from itertools import zip_longest
from pathlib import Path
from xml.etree import ElementTree

import numpy as np

#: largest difference [m or rad] between equivalent numbers (see the module docstring)
TOLERANCE = 1e-9
#: the rule in one phrase, for messages
RULE = "numbers within 1e-9, angles modulo 2 pi"
#: files of a models folder that the catalogue does not write but may sit beside its output
KEPT = {"README.md", "__init__.py", "__pycache__"}
#: the fix, ending every problem :func:`out_of_date` reports
HINT = "run python -m pinmob.catalog models"
#: a number as the builder writes it (also matches digits inside names, identically on both sides)
NUMBER = re.compile(r"-?\d+(?:\.\d+)?(?:[eE][-+]?\d+)?")
_RPY = re.compile(r'rpy="([^"]*)"|rpy = \[([^\]]*)\]')
_JOINT_TABLE = re.compile(r"^(?:joints|seed) = \{(.*)\}$", re.MULTILINE)
_PAIR = re.compile(r'(?:"([^"]*)"|([A-Za-z0-9_-]+)) = (' + NUMBER.pattern + ")")


def revolute_joints(urdf: Path) -> set[str]:
    """Names of the ``revolute`` and ``continuous`` joints of a URDF file (empty when it cannot be read)."""
    try:
        robot = ElementTree.parse(urdf).getroot()
    except (OSError, ElementTree.ParseError):
        return set()
    return {el.get("name", "") for el in robot.iter("joint") if el.get("type") in ("revolute", "continuous")}


def _angle_spans(text: str, revolute: Collection[str]) -> Iterator[tuple[int, int]]:
    """(start, end) of the stretches of ``text`` whose numbers are angles."""
    for m in _RPY.finditer(text):
        group = 1 if m.group(1) is not None else 2
        yield m.span(group)
    for table in _JOINT_TABLE.finditer(text):
        for pair in _PAIR.finditer(table.group(1)):
            if (pair.group(1) or pair.group(2)) in revolute:
                start = table.start(1)
                yield start + pair.start(3), start + pair.end(3)


def _numbers(text: str, revolute: Collection[str]) -> tuple[list[str], np.ndarray, np.ndarray, list[int]]:
    """The text around the numbers, the numbers, which of them are angles, and their line numbers."""
    spans = list(_angle_spans(text, revolute))
    matches = list(NUMBER.finditer(text))
    angle = np.array([any(a <= m.start() and m.end() <= b for a, b in spans) for m in matches], bool)
    lines = [text.count("\n", 0, m.start()) + 1 for m in matches]
    return NUMBER.split(text), np.array([float(m.group()) for m in matches]), angle, lines


def difference(old: str, new: str, revolute: Collection[str] = ()) -> str | None:
    """None when the texts ``old`` and ``new`` are equivalent (module docstring), else the first difference.

    Args:
        old: the version in the folder.
        new: the version just generated.
        revolute: names of the revolute joints, whose values in ``joints`` and ``seed`` tables are angles.

    Returns:
        e.g. ``"line 46: 5.56045105936617 in the file, 1.2 now"`` or ``"text differs (line 3)"``.
    """
    if old == new:
        return None
    (text_old, num_old, _, lines), (text_new, num_new, angle, _) = _numbers(old, revolute), _numbers(new, revolute)
    if text_old != text_new:
        pairs = enumerate(zip_longest(old.splitlines(), new.splitlines()), start=1)
        line = next((i for i, (a, b) in pairs if a != b), 1)
        return f"text differs (line {line})"
    delta = num_new - num_old
    delta[angle] = np.pi - np.mod(np.pi - delta[angle], 2 * np.pi)  # in (-pi, pi]: equal modulo 2 pi
    bad = np.flatnonzero(np.abs(delta) > TOLERANCE)
    if bad.size == 0:
        return None
    i = int(bad[0])
    return f"line {lines[i]}: {float(num_old[i])!r} in the file, {float(num_new[i])!r} now"


def file_difference(old: Path, new: Path) -> str | None:
    """:func:`difference` of two files; the revolute joints are read from the URDF named by ``new`` (a TOML)."""
    new_text = new.read_text()
    revolute: set[str] = set()
    if new.suffix == ".toml":
        try:
            urdf = tomllib.loads(new_text).get("urdf")
        except tomllib.TOMLDecodeError:
            urdf = None
        if isinstance(urdf, str):
            revolute = revolute_joints(new.parent / urdf)
    return difference(old.read_text(), new_text, revolute)


def out_of_date(models: Path, fresh: Path) -> list[str]:
    """Problems of the folder ``models`` against freshly generated files in ``fresh``, each ending with :data:`HINT`.

    The set of files must be the same (besides those in :data:`KEPT`), and each file equivalent to its fresh
    version (:func:`file_difference`).
    """
    problems = []
    have = {p.name for p in models.iterdir() if p.name not in KEPT}
    want = {p.name for p in fresh.iterdir()}
    for name in sorted(want - have):
        problems.append(f"models/{name} is missing: {HINT}")
    for name in sorted(have - want):
        problems.append(f"models/{name} is not written by the catalog (stale or stray): {HINT}")
    for name in sorted(have & want):
        diff = file_difference(models / name, fresh / name)
        if diff is not None:
            problems.append(f"models/{name} is out of date ({diff}): {HINT}")
    return problems
