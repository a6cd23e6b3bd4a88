"""Sphinx configuration of pinmob's documentation: the Markdown pages of docs/ (MyST) and the API from docstrings.

Built by ``.ci/run`` with warnings as errors: ``sphinx-build -W --keep-going -b html docs <folder>``.
"""

import pinmob

project = "pinmob"
author = "pinmob's developers"
release = version = pinmob.__version__

extensions = [
    "myst_parser",  # the pages are Markdown, read as GitHub shows them
    "sphinx.ext.autodoc",  # the API reference from the docstrings
    "sphinx.ext.napoleon",  # docstrings in Google style (Args:, Returns:, Raises:)
]
source_suffix = {".md": "markdown"}
root_doc = "index"
exclude_patterns = ["_build"]

# links between pages keep GitHub's form, page.md#heading-anchor: MyST makes the same anchors
myst_heading_anchors = 4

autodoc_member_order = "bysource"
autodoc_default_options = {"members": True, "show-inheritance": True}
napoleon_google_docstring = True
napoleon_numpy_docstring = False

html_theme = "furo"
html_title = f"pinmob {release}"
