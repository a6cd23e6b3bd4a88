"""The command line's progress bars: tqdm on stderr, only on a terminal, only for steps longer than two seconds."""

from __future__ import annotations

import sys

from pinmob.progress import Bar

#: seconds a step runs before its bar appears
DELAY = 2.0


def terminal_bar(description: str, total: int | None) -> Bar:
    """A tqdm bar on stderr for one step (:func:`pinmob.progress.step`); none when stderr is not a terminal."""
    from tqdm import tqdm

    bar: Bar = tqdm(total=total, desc=f"pinmob: {description}", delay=DELAY, disable=None, leave=False, file=sys.stderr)
    return bar
