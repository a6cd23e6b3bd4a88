"""``python -m pinmob.catalog``: write every built-in model (:func:`pinmob.catalog.registry.main`)."""

from .registry import main

raise SystemExit(main())
