"""Command line: ``pinmob models``, ``analyze``, ``show``, ``scan``, ``sweep``, ``glossary`` and ``fix``.

The commands only parse, call the library and format. Errors are printed as
one line on stderr (``pinmob: error: ...``) with exit status 2, never with a
traceback; warnings as ``pinmob: warning: ...`` lines. Steps that last more
than two seconds show a progress bar on stderr when it is a terminal
(:mod:`pinmob.cli.progress_bar`). :func:`main` leaves the interpreter's warning
filters and format as it found them.
"""

from __future__ import annotations

import argparse
import contextlib
import gc
import os
import sys
import warnings
from collections.abc import Callable, Iterator, Sequence
from typing import TextIO

from pinmob.cli.flags import worded_for_cli
from pinmob.cli.parser import build_parser, parser_for
from pinmob.cli.progress_bar import terminal_bars
from pinmob.exceptions import PinmobError
from pinmob.progress import reporting


def _models(args: argparse.Namespace) -> int:
    from pinmob.cli import models

    return models.run(args)


def _analyze(args: argparse.Namespace) -> int:
    from pinmob.cli import analyze

    return analyze.run(args)


def _show(args: argparse.Namespace) -> int:
    from pinmob.cli import show

    return show.run(args)


def _scan(args: argparse.Namespace) -> int:
    from pinmob.cli import scan

    return scan.run(args)


def _sweep(args: argparse.Namespace) -> int:
    from pinmob.cli import sweep

    return sweep.run(args)


def _fix(args: argparse.Namespace) -> int:
    from pinmob.cli import fix

    return fix.run(args)


def _glossary(args: argparse.Namespace) -> int:
    from pinmob.cli import glossary_command as glossary

    return glossary.run(args)


#: The commands; each imports its module when it runs (``pinmob analyze`` loads neither the viewer nor the scans nor Dask).
COMMANDS: dict[str, Callable[[argparse.Namespace], int]] = {
    "models": _models,
    "analyze": _analyze,
    "show": _show,
    "scan": _scan,
    "sweep": _sweep,
    "glossary": _glossary,
    "fix": _fix,
}


def _show_warning(
    message: Warning | str,
    category: type[Warning],
    filename: str,
    lineno: int,
    file: TextIO | None = None,
    line: str | None = None,
) -> None:
    print(f"pinmob: warning: {message}", file=sys.stderr if file is None else file)


def console() -> int:
    """The ``pinmob`` console script and ``python -m pinmob``: :func:`main` on ``sys.argv``, its imports frozen.

    ``gc.freeze()`` moves every object alive after the command line's imports (the interpreter's, numpy's,
    Pinocchio's and pinmob's: some 27,000) out of the collector's reach, so that its full passes during the command
    walk only what came after (the command's own imports, numba's among them, and what it makes): a 21 x 21
    ``pinmob scan`` spent 74-111 ms in the collector, 41-44 ms with them frozen. A process that calls :func:`main`
    itself (a test, a script) keeps its own collector settings.
    """
    gc.freeze()
    return main()


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the command line on ``argv`` (default ``sys.argv[1:]``); returns the exit status."""
    words = sys.argv[1:] if argv is None else list(argv)
    with _stderr_or_null():
        args = parser_for(words).parse_args(words)  # the named command's arguments only, built once
        with warnings.catch_warnings():
            warnings.simplefilter("ignore" if getattr(args, "json", False) else "default")
            warnings.filterwarnings("ignore", category=ResourceWarning)  # Dask's sockets: not the user's business
            warnings.showwarning = _show_warning
            return _run(args)


def _interrupted() -> int:
    """Say so and give status 130, as Ctrl-C, SIGTERM and SIGHUP do.

    CPython marks the process as ended by Ctrl-C when an interrupt went through the evaluation of a string (``exec``
    or ``eval``: a dataclass made during a lazy import), caught or not, and ends it by SIGINT after this status
    (-2, not 130: 1 of 32 interrupts at different times of a scan). Evaluating a string clears that mark.
    """
    print("pinmob: interrupted", file=sys.stderr)
    exec("")  # the mark's reset (run_eval_code_obj)
    return 130


def _caused_by_interrupt(exc: BaseException) -> bool:
    """True when a KeyboardInterrupt is among the causes of ``exc`` (its ``__cause__`` or ``__context__``, theirs...).

    numba's compiled code interrupted while it calls back into Python (unpickling a kernel's constants on its
    first call) carries on, and the interrupt comes out wrapped in a SystemError a level: six deep in a scan
    sent SIGTERM while its batch analysis loaded.
    """
    seen: set[int] = set()
    cause: BaseException | None = exc
    while cause is not None and id(cause) not in seen:
        if isinstance(cause, KeyboardInterrupt):
            return True
        seen.add(id(cause))
        cause = cause.__cause__ or cause.__context__
    return False


@contextlib.contextmanager
def _stderr_or_null() -> Iterator[None]:
    """Within the block, ``sys.stderr`` is a stream, /dev/null when the process was started with it closed.

    ``pinmob ... 2>&-``: Python then sets it to None, and the messages and bars meant for it are dropped.
    """
    if sys.stderr is not None:
        yield
        return
    with open(os.devnull, "w") as null:
        sys.stderr = null
        try:
            yield
        finally:
            sys.stderr = None  # as it was found


def _run(args: argparse.Namespace) -> int:
    try:
        with reporting(terminal_bars()):  # steps over two seconds show a bar on stderr, on a terminal only
            status = COMMANDS[args.command](args)
        sys.stdout.flush()  # a closed pipe shows here, not at interpreter exit
        return status
    except PinmobError as exc:
        print(f"pinmob: error: {' '.join(worded_for_cli(exc).split())}", file=sys.stderr)
        return 2
    except BrokenPipeError:
        # the reader went away (``pinmob ... | head -1``): stop quietly, as Unix tools do on SIGPIPE
        try:
            devnull = os.open(os.devnull, os.O_WRONLY)
            os.dup2(devnull, sys.stdout.fileno())  # nothing left to flush at exit
            os.close(devnull)
        except (OSError, ValueError):  # stdout is not a file (e.g. captured in tests)
            pass
        return 128 + 13
    except KeyboardInterrupt:
        return _interrupted()
    except SystemError as exc:  # an interrupt inside a library's C code, which went on (numba loading a kernel)
        if _caused_by_interrupt(exc):
            return _interrupted()
        raise
    except OSError as exc:  # the machine said no (a full disk, a file that cannot be written): one line
        where = f": {exc.filename}" if exc.filename else ""
        print(f"pinmob: error: {exc.strerror or exc}{where}", file=sys.stderr)
        return 2
    except MemoryError:
        print("pinmob: error: out of memory; ask for fewer samples, steps or restarts", file=sys.stderr)
        return 2


__all__ = ["COMMANDS", "build_parser", "main"]
