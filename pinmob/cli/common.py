"""What the commands share: loading with ``--actuated``, joint values, hints for unknown names, output files, signals."""

from __future__ import annotations

import argparse
import contextlib
import re
import sys
import tomllib
from collections.abc import Iterator
from pathlib import Path

from pinmob.exceptions import ConfigurationError, UnknownConfigurationError
from pinmob.io import builtin_models
from pinmob.model import Mechanism, parse_joint_values
from pinmob.name_matching import choices


@contextlib.contextmanager
def with_elsewhere(mech: Mechanism) -> Iterator[None]:
    """Within the block, an unknown configuration's error also names the built-in models that have it (:func:`elsewhere`)."""
    try:
        yield
    except UnknownConfigurationError as exc:
        raise UnknownConfigurationError(f"{exc}{elsewhere(exc.name, mech)}", exc.name) from None


def joint_values_of(args: argparse.Namespace) -> dict[str, float] | None:
    """``--joints a=0.1,b=0.2`` as joint values by name (None without ``--joints``)."""
    return None if args.joints is None else parse_joint_values(args.joints, "--joints")


def load_for(args: argparse.Namespace) -> Mechanism:
    """The mechanism of ``args.mechanism``, with ``--actuated`` applied."""
    from pinmob.io import load
    from pinmob.model import with_actuated

    xacro_args: dict[str, str] = {}
    if getattr(args, "xacro_arg", None):  # the xacro reader loads for xacro arguments (or a xacro file) only
        from pinmob.io import parse_xacro_args

        xacro_args = parse_xacro_args(args.xacro_arg)
    mech = load(args.mechanism, xacro_args=xacro_args, package_dirs=getattr(args, "package_path", None) or [])
    given = Path(str(args.mechanism)).expanduser()
    if given.suffix.lower() == ".urdf" and mech.source is not None and mech.source.suffix.lower() in (".yaml", ".yml"):
        print(
            f"pinmob: read {given.name} with the Extended URDF sidecar beside it, {mech.source.name}", file=sys.stderr
        )
    if args.actuated is not None:
        names = [n.strip() for n in args.actuated.split(",") if n.strip()]
        if not names:
            raise ConfigurationError(f"--actuated {args.actuated!r}: name the actuated joints, e.g. --actuated a,b")
        mech = with_actuated(mech, names)
    return mech


def elsewhere(config: str, mech: Mechanism | None = None) -> str:
    """Hint naming the built-in models that do have a configuration called ``config``, and why not ``mech``.

    The why is the sentence of ``mech``'s description that names one of those models, if any (e.g. the
    3-PUU's links are too long for beta = 0, which needs the geometry of 3-PUU-flat).
    """
    owners = []
    for name, path in builtin_models().items():
        with path.open("rb") as fh:
            if config in tomllib.load(fh).get("configurations", {}):
                owners.append(name)
    if not owners:
        return ""
    why = ""
    if mech is not None:
        sentences = re.split(r"(?<=[.!?])\s+", mech.description)
        others = [o for o in owners if o not in mech.name]  # '3-PUU' in "3-PUU-flat" is the family, not a pointer
        named = [t for t in sentences if any(re.search(rf"(?<![\w-]){re.escape(o)}(?![\w-])", t) for o in others)]
        why = f". Why not in {mech.name!r}: {named[0]}" if named else ""
    return f"; built-in model(s) with a configuration {config!r}: {choices(owners)}{why}"


@contextlib.contextmanager
def signals_interrupt() -> Iterator[None]:
    """Within the block, SIGTERM and SIGHUP raise KeyboardInterrupt, as Ctrl-C does, so cleanups run."""
    import signal

    def interrupt(signum: int, frame: object) -> None:
        raise KeyboardInterrupt

    wanted = [signal.SIGTERM] + ([signal.SIGHUP] if hasattr(signal, "SIGHUP") else [])
    previous = {sig: signal.signal(sig, interrupt) for sig in wanted}
    try:
        yield
    finally:
        for sig, handler in previous.items():
            signal.signal(sig, handler)


def check_distinct(paths: dict[str, str | Path | None]) -> None:
    """Refuse two outputs that name the same file (one would overwrite the other); ``paths``: option -> path or None."""
    given = {option: Path(path).expanduser() for option, path in paths.items() if path}
    seen: dict[Path, str] = {}
    for option, path in given.items():
        key = path.resolve()
        if key in seen:
            raise ConfigurationError(
                f"{seen[key]} and {option} name the same file {str(path)!r}: one would overwrite the other; "
                "give each output its own file name"
            )
        seen[key] = option


def check_outputs(paths: dict[str, str | None], force: bool) -> None:
    """Refuse, before any work, outputs naming one file, or files that exist (unless ``force``) or cannot be outputs.

    An output cannot be a link, a folder or a device, nor lie in no folder (:func:`pinmob.output_files.check_target`).
    """
    from pinmob.output_files import check_target

    check_distinct(dict(paths))
    for option, path in paths.items():
        if path:
            check_target(option, Path(path).expanduser(), force)
