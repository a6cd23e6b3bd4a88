"""``python -m pinmob``: the command line (:func:`pinmob.cli.console`)."""

from pinmob.cli import console

raise SystemExit(console())
