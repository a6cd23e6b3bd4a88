"""``pinmob glossary [TERM]``: the words the reports use, explained (the glossary shipped in the package)."""

from __future__ import annotations

import argparse

from pinmob import glossary


def run(args: argparse.Namespace) -> int:
    """Print the whole glossary, or the entries that explain ``args.term`` under their sections' titles."""
    if args.term is None:
        print(glossary.text(), end="")
        return 0
    section = None
    for entry in glossary.lookup(args.term):
        if entry.section != section:
            print(f"{'' if section is None else chr(10)}{entry.section}:")
            section = entry.section
        print(entry.text)
    return 0
