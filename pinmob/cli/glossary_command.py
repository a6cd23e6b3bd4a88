"""``pinmob glossary [TERM]``: the words the reports use, explained (the glossary shipped in the package)."""

from __future__ import annotations

import argparse

from pinmob import glossary
from pinmob.analysis import REPORT_PARTS


def page() -> str:
    """The glossary, and the entries the registered report parts bring (:attr:`~pinmob.analysis.report.ReportPart.glossary`)."""
    own = [p.glossary.strip("\n") for p in REPORT_PARTS.values() if p.glossary]
    text = glossary.text()
    return text if not own else text.rstrip("\n") + "\n\n## Registered report parts\n\n" + "\n".join(own) + "\n"


def run(args: argparse.Namespace) -> int:
    """Print the whole glossary, or the entries that explain ``args.term`` under their sections' titles."""
    if args.term is None:
        print(page(), end="")
        return 0
    section = None
    for entry in glossary.lookup(args.term, page()):
        if entry.section != section:
            print(f"{'' if section is None else chr(10)}{entry.section}:")
            section = entry.section
        print(entry.text)
    return 0
