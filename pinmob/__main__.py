"""``python -m pinmob``: the command line (:func:`pinmob.cli.main`)."""

from pinmob.cli import main

raise SystemExit(main())
