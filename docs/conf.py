"""Sphinx configuration of pinmob's documentation: the Markdown pages of docs/ (MyST) and the API from docstrings.

Built by ``.ci/run`` with warnings as errors: ``sphinx-build -W --keep-going -b html docs <folder>``.
"""

import pinmob
from sphinx.util.inspect import TypeAliasForwardRef

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

# signatures name numpy's type aliases instead of expanding them (ArrayLike is a dozen lines of numpy internals):
# the modules annotate with strings (from __future__ import annotations), which autodoc maps by these names
autodoc_type_aliases = {
    "ArrayLike": "ArrayLike",
    "NDArray": "NDArray",
    "Array": "Array",
    "Mask": "Mask",
    "At": "ArrayLike | str | Configuration | None",  # the configuration argument of the shortcuts
}


# Sphinx 9 prints an alias inside a union or a tuple by its repr, "TypeAliasForwardRef('ArrayLike')": its name
TypeAliasForwardRef.__repr__ = lambda self: self.name  # type: ignore[method-assign]
