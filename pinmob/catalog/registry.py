"""The catalogue of built-in models and the command that writes them (``python -m pinmob.catalog``)."""

from __future__ import annotations

import argparse
import shutil
import sys
import tempfile
from collections.abc import Callable
from pathlib import Path
from typing import Any

from pinmob.builder import is_generated
from pinmob.exceptions import PinmobError

from ..builder import MechanismBuilder
from .freshness import KEPT, RULE, file_difference

Definition = tuple[MechanismBuilder, dict[str, dict[str, Any]], float | None]

#: stem of the files -> function building (builder, configurations, length_scale)
CATALOG: dict[str, Callable[[], Definition]] = {}


def register(stem: str) -> Callable[[Callable[[], Definition]], Callable[[], Definition]]:
    """Decorator: add a model definition to :data:`CATALOG` under the file stem ``stem``."""

    def deco(fn: Callable[[], Definition]) -> Callable[[], Definition]:
        CATALOG[stem] = fn
        return fn

    return deco


def write_all(directory: str | Path) -> list[Path]:
    """Write every catalogued model into ``directory``; returns the TOML paths.

    Each model is checked first (every named configuration closes; see
    :meth:`MechanismBuilder.write`).
    """
    out = []
    for stem, fn in CATALOG.items():
        builder, confs, length = fn()
        out.append(builder.write(directory, stem, confs, length))
    return out


def generated_names() -> set[str]:
    """Names of the files :func:`write_all` writes."""
    return {f"{stem}.{ext}" for stem in CATALOG for ext in ("toml", "urdf")}


def checkout_models() -> Path | None:
    """``models/`` of the source checkout this pinmob runs from, or None (e.g. a regular install)."""
    root = Path(__file__).resolve().parents[2]
    models = root / "models"
    if (root / "pyproject.toml").is_file() and (models / "__init__.py").is_file():
        return models
    return None


def check_target(target: Path) -> list[Path]:
    """Refuse a target that is a file or holds files the catalogue did not write; returns its stale outputs.

    Accepted: a missing or empty folder, or one holding only earlier builder
    output (files starting with the builder's marker) and ``README.md``,
    ``__init__.py``. Stale outputs are builder files no catalogue entry writes.
    """
    if target.exists() and not target.is_dir():
        raise PinmobError(f"target {str(target)!r} is a file, not a folder")
    if not target.exists():
        return []
    foreign = sorted(p.name for p in target.iterdir() if p.name not in KEPT and not is_generated(p))
    if foreign:
        shown = ", ".join(foreign[:8]) + (f", ... ({len(foreign) - 8} more)" if len(foreign) > 8 else "")
        raise PinmobError(
            f"refusing to write into {str(target)!r}: it holds files pinmob.catalog did not write ({shown}); "
            "give a new or empty folder, a folder of earlier output, or the checkout's models/"
        )
    return sorted(p for p in target.iterdir() if p.name not in KEPT and p.name not in generated_names())


def main(argv: list[str] | None = None) -> int:
    """``python -m pinmob.catalog [TARGET]``: write every built-in model; exit 2 with one line on an error.

    Every model is built and checked first; then each file is written unless the target already holds an
    equivalent one (:mod:`pinmob.catalog.freshness`: the same up to round-off, angles modulo 2 pi), so a
    regeneration on another machine changes no file whose content did not change.
    """
    default = checkout_models()
    parser = argparse.ArgumentParser(
        prog="python -m pinmob.catalog",
        description="Write every built-in model (URDF + mechanism file) with the builder.",
    )
    parser.add_argument(
        "target",
        nargs="?",
        help="folder to write into (default: models/ of the source checkout"
        + (f", here {default})" if default else "; none found: pinmob is not run from a checkout)"),
    )
    args = parser.parse_args(argv)
    try:
        target = Path(args.target) if args.target is not None else default
        if target is None:
            raise PinmobError(
                "no target folder given and pinmob does not run from a source checkout (no models/ beside "
                "pyproject.toml); give the folder to write into"
            )
        stale = check_target(target)
        with tempfile.TemporaryDirectory() as tmp:  # every model built and checked before any file is replaced
            write_all(tmp)
            target.mkdir(parents=True, exist_ok=True)
            unchanged = 0
            for path in sorted(Path(tmp).iterdir()):
                dest = target / path.name
                if dest.is_file() and file_difference(dest, path) is None:
                    unchanged += 1  # equivalent: keep it, so that a regeneration elsewhere leaves no diff
                    continue
                shutil.copyfile(path, dest)
                print(f"wrote {dest}")
        if unchanged:
            print(f"{unchanged} file(s) in {target} unchanged: equivalent to the new output ({RULE})")
        for path in stale:
            path.unlink()
            print(f"removed stale {path} (written by an earlier catalogue, no entry writes it now)")
    except PinmobError as exc:
        print(f"pinmob.catalog: error: {' '.join(str(exc).split())}", file=sys.stderr)
        return 2
    return 0
