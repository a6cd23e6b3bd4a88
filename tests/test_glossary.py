"""``pinmob glossary [TERM]``: the glossary a pip user has, the same text as ``docs/glossary.md``.

Run with the installed entry point: under ``.ci/run`` (a regular ``pip install``) the text comes from the
installed package, so these tests also check that the wheel ships the page.
"""

from __future__ import annotations

import re
import subprocess
from pathlib import Path

import pytest
from test_readme import pinmob_command

from pinmob import glossary
from pinmob.exceptions import GlossaryError

PAGE = Path(__file__).resolve().parent.parent / "docs" / "glossary.md"


def pinmob(*args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run([*pinmob_command(), *args], capture_output=True, text=True, timeout=120)


def test_pinmob_glossary_prints_the_docs_page():
    out = pinmob("glossary")
    assert out.returncode == 0 and out.stderr == ""
    assert out.stdout == PAGE.read_text(encoding="utf-8")


def test_pinmob_glossary_term_prints_its_entries_under_their_sections():
    out = pinmob("glossary", "TWIST RANK")
    page = PAGE.read_text(encoding="utf-8")
    start = page.index("- **twist rank**")
    entry = page[start : page.index("\n- ", start)]  # the page's item, up to the next one
    assert out.returncode == 0
    assert out.stdout == f"Limbs:\n{entry}\n"


def test_an_unknown_term_is_one_line_with_the_closest_ones():
    out = pinmob("glossary", "twistrank")
    assert out.returncode == 2 and out.stdout == ""
    assert out.stderr.startswith("pinmob: error: no term 'twistrank' in the glossary (did you mean 'twist rank'")
    assert out.stderr.count("\n") == 1 and "terms: " in out.stderr


def test_every_item_of_the_page_is_an_entry_with_a_term():
    """The parser takes every list item of the page (one bold term at least each), in its section."""
    page = PAGE.read_text(encoding="utf-8")
    items = re.findall(r"^- ", page, re.MULTILINE)
    found = glossary.entries()
    assert len(found) == len(items) >= 40
    assert all(e.terms for e in found)
    assert {e.section for e in found} == set(re.findall(r"^## (.*)$", page, re.MULTILINE))


def test_lookup_rule():
    page = "# G\n\n## One\n\n- **alpha**: first,\n  continued.\n- **beta gamma**, **delta**: second.\n\nprose\n"
    assert [e.text for e in glossary.lookup("ALPHA", page)] == ["- **alpha**: first,\n  continued."]
    assert [e.terms for e in glossary.lookup("delta", page)] == [("beta gamma", "delta")]
    assert [e.section for e in glossary.lookup("gamma", page)] == ["One"]
    with pytest.raises(GlossaryError, match=r"no term 'alpah' in the glossary \(did you mean 'alpha'\?\)"):
        glossary.lookup("alpah", page)
    with pytest.raises(GlossaryError):
        glossary.lookup(" ", page)
