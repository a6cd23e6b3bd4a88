"""Every page a message or a page points to exists: ``docs/...`` named in pinmob's source, and the relative links of
the README and ``docs/*.md``, each with its ``#section`` when it names one (GitHub's heading anchors)."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
PAGES = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
#: a docs path in source text, with its optional anchor (``docs/closed-chains.md#formats``)
SOURCE_REF = re.compile(r"\bdocs/[\w./-]*\w(?:#[\w-]+)?")
#: a Markdown link's target, ``[text](target)``
LINK = re.compile(r"\]\(([^)\s]+)\)")
FENCE = re.compile(r"^```.*?^```$", re.MULTILINE | re.DOTALL)


def anchors(page: Path) -> set[str]:
    """GitHub's anchors of a Markdown page's headings (outside code blocks): lower case, punctuation other than
    ``-`` and ``_`` dropped, spaces made ``-``; a repeated heading gets ``-1``, ``-2``, ..."""
    found: set[str] = set()
    for line in FENCE.sub("", page.read_text()).splitlines():
        heading = re.match(r"^#{1,6} +(.*?) *#*$", line)
        if heading:
            slug = re.sub(r"[^\w\- ]", "", heading.group(1).lower()).replace(" ", "-")
            k, unique = 0, slug
            while unique in found:
                k += 1
                unique = f"{slug}-{k}"
            found.add(unique)
    return found


def missing(target: str, base: Path, page: Path | None = None) -> str | None:
    """Why ``target`` (a path relative to ``base``, with an optional ``#anchor``; ``#anchor`` alone: a section of
    ``page``) does not resolve, else None."""
    path, _, anchor = target.partition("#")
    file = (base / path).resolve() if path else page
    if file is None or not file.exists():
        return f"{target}: no file {file.relative_to(ROOT) if file and file.is_relative_to(ROOT) else file}"
    if anchor and file.suffix == ".md" and anchor not in anchors(file):
        return f"{target}: {file.name} has no section #{anchor}"
    return None


def source_refs() -> list[tuple[str, str]]:
    """(file:line, reference) of every ``docs/...`` path in pinmob's source."""
    refs = []
    for source in sorted((ROOT / "pinmob").rglob("*.py")):
        for number, line in enumerate(source.read_text().splitlines(), 1):
            refs += [(f"{source.relative_to(ROOT)}:{number}", m.group(0)) for m in SOURCE_REF.finditer(line)]
    return refs


def test_the_source_points_only_to_docs_that_exist():
    refs = source_refs()
    assert len(refs) >= 3, refs  # the CLI's help names the scans' and the finite-mobility pages
    bad = [f"{where}: {why}" for where, ref in refs if (why := missing(ref, ROOT))]
    assert not bad, bad


@pytest.mark.parametrize("page", PAGES, ids=[p.name for p in PAGES])
def test_the_pages_link_only_to_what_exists(page):
    text = FENCE.sub("", page.read_text())
    targets = [t for t in LINK.findall(text) if not re.match(r"^[a-z]+:", t)]  # not https:, mailto:
    bad = [why for t in targets if (why := missing(t, page.parent, page))]
    assert not bad, bad


def test_the_rule_finds_what_is_missing(tmp_path):
    """The checks catch a missing page, a missing section, and accept GitHub's anchor of a heading."""
    page = tmp_path / "page.md"
    page.write_text("# Closed chains: Extended URDF, MJCF\n\n```toml\n# not a heading\n```\n## Formats\n## Formats\n")
    assert anchors(page) == {"closed-chains-extended-urdf-mjcf", "formats", "formats-1"}
    assert missing("page.md#formats", tmp_path) is None
    assert "no section #not-a-heading" in (missing("page.md#not-a-heading", tmp_path) or "")
    assert "no file" in (missing("formats.md", tmp_path) or "")
    assert missing("#formats-1", tmp_path, page) is None and missing("#formats-2", tmp_path, page)
    assert SOURCE_REF.findall("see docs/formats.md), or docs/closed-chains.md#formats.") == [
        "docs/formats.md",
        "docs/closed-chains.md#formats",
    ]
