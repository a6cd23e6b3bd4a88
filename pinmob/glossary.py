"""The glossary of the words pinmob's reports use, shipped in the package: ``pinmob glossary [TERM]``.

The text is ``docs/glossary.md`` of pinmob's sources (``pinmob/glossary.md`` links to it, and the
installed package holds a copy), so a ``pip install pinmob`` has it too. Each entry is a list item of
the page, ``- **term**: ...``; :func:`lookup` finds the entries whose bold terms contain a word.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from importlib import resources

from pinmob.exceptions import GlossaryError
from pinmob.name_matching import choices, did_you_mean

#: a term an entry explains: the page's bold text (``**constraint rank**``)
_BOLD = re.compile(r"\*\*(.+?)\*\*")


@dataclass(frozen=True)
class Entry:
    """One entry of the glossary: the section it is in, the terms it explains (bold) and its text (Markdown)."""

    section: str
    terms: tuple[str, ...]
    text: str


def text() -> str:
    """The whole glossary, as Markdown."""
    return resources.files("pinmob").joinpath("glossary.md").read_text(encoding="utf-8")


def entries(page: str | None = None) -> list[Entry]:
    """The entries of the glossary (``page``: another text of the same form), in the page's order."""
    found: list[Entry] = []
    section = ""
    item: list[str] = []

    def close() -> None:
        if item:
            body = "\n".join(item)
            found.append(Entry(section, tuple(_BOLD.findall(body)), body))
            item.clear()

    for line in (text() if page is None else page).splitlines():
        if line.startswith("#"):
            close()
            section = line.lstrip("#").strip()
        elif line.startswith("- "):
            close()
            item.append(line)
        elif item and line.startswith("  "):
            item.append(line)
        else:
            close()
    close()
    return found


def lookup(term: str, page: str | None = None) -> list[Entry]:
    """The entries that explain ``term``: those with a bold term containing it, ignoring case.

    Raises:
        GlossaryError: no entry explains it; the message suggests the closest terms and lists them all.
    """
    every = entries(page)
    wanted = term.strip().casefold()
    hits = [e for e in every if wanted and any(wanted in t.casefold() for t in e.terms)]
    if not hits:
        terms = [t for e in every for t in e.terms]
        raise GlossaryError(f"no term {term!r} in the glossary{did_you_mean(term, terms)}; terms: {choices(terms)}")
    return hits


__all__ = ["Entry", "entries", "lookup", "text"]
