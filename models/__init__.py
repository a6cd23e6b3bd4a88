"""Built-in pinmob models (installed as ``pinmob.models``); regenerate with ``python -m pinmob.catalog``."""
