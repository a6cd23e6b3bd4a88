"""The report section protocol: :class:`ReportPart`, what one analysis adds to a report, and its registry.

A new analysis is its module plus one :func:`register_part` call (``docs/architecture.md``, "Adding an
analysis"): :class:`~pinmob.analysis.report.Report` computes each registered part when first read and shows it
in ``str(report)`` (and so in the notebook's HTML), ``to_dict()`` and ``brief()``; :func:`pinmob.analyze` takes
its keywords; ``pinmob analyze`` adds its options (``pinmob/cli/parser.py``), passes them on
(``pinmob/cli/analyze.py``) and words them in reports and errors (``pinmob/cli/flags.py``); ``pinmob glossary``
shows the entries it brings.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import Any, Protocol

from pinmob.analysis.chain import FrameMobility, MechanismMobility
from pinmob.analysis.configuration import Configuration
from pinmob.analysis.mobility import Mobility
from pinmob.analysis.singularity import Singularity
from pinmob.exceptions import ArgumentError


@dataclass(frozen=True)
class Options:
    """What the analysis was asked for besides the configuration (see :func:`pinmob.analyze`).

    ``asked``: the values of the registered parts' keywords (:class:`PartOption`), e.g. ``{"paper": True,
    "finite": False, "finite_order": 4, ...}``; :meth:`value` reads one.
    """

    frames: tuple[str, ...] = ()
    outputs: tuple[str, ...] | None = None
    actuated: tuple[str, ...] | None = None
    generic_rank: int | None = None
    relaxed: tuple[str, ...] = ()
    rtol_asked: float | None = None
    asked: Mapping[str, Any] = field(default_factory=dict)

    def value(self, keyword: str) -> Any:
        """The value of a registered part's keyword of :func:`pinmob.analyze` (its default when not given)."""
        if keyword in self.asked:
            return self.asked[keyword]
        return next((o.default for p in REPORT_PARTS.values() for o in p.options if o.keyword == keyword), None)


class ReportLike(Protocol):
    """What a part's functions may read of the report they are part of (:class:`pinmob.analysis.report.Report`)."""

    @property
    def state(self) -> Configuration:
        """The configuration analysed."""

    @property
    def rtol(self) -> float:
        """The rank tolerance."""

    @property
    def options(self) -> Options:
        """What was asked for: the parts' keywords by ``options.value(keyword)``."""

    @property
    def mobility(self) -> Mobility | None:
        """The platform's mobility (None without a platform frame)."""

    @property
    def has_limbs(self) -> bool:
        """The mechanism has limbs."""

    @property
    def mechanism_mobility(self) -> MechanismMobility:
        """The whole closed chain's mobility (closure rank, redundancy, actuation)."""

    @property
    def platform_frame(self) -> FrameMobility | None:
        """The platform frame's motion on the whole closed chain."""

    @property
    def singularity(self) -> Singularity | None:
        """The singularity classes (None where not analysed)."""

    def part(self, name: str) -> Any:
        """Another registered part."""


@dataclass(frozen=True)
class PartOption:
    """A keyword of :func:`pinmob.analyze` that asks for a part, and its option of ``pinmob analyze``.

    Attributes:
        keyword: the keyword of :func:`pinmob.analyze` (and the destination of the command line's option); the part's
            ``compute`` reads its value with ``report.options.value(keyword)``.
        option: the option's name without its leading dashes (``"paper-view"``); None: a keyword of Python only.
        help: the option's help (``--help``).
        metavar: None: the option is a switch (True when given); else it takes a value, shown as ``metavar``.
        type: the value's type on the command line (``int``, ``float``, ``str``; with ``metavar``).
        default: the keyword's value when not given.
        implies: the keyword of another switch this option also sets on the command line (``--finite-order K``
            asks for the finite analysis).
    """

    keyword: str
    option: str | None = None
    help: str = ""
    metavar: str | None = None
    type: Callable[[str], Any] = int
    default: Any = None
    implies: str | None = None


def _text(report: ReportLike, value: Any) -> str | None:
    return str(value)


@dataclass(frozen=True)
class ReportPart:
    """One optional part of a :class:`~pinmob.analysis.report.Report`: all a new analysis adds to it, declared once.

    A part is its analysis module plus one :func:`register_part` call: the report computes it when first read
    (``report.part(name)``), prints it as a section of ``str(report)`` (so the notebook's HTML shows it), adds
    its entries to ``to_dict()`` and its word to ``brief()``; :func:`pinmob.analyze` takes its keywords and
    ``pinmob analyze`` its options (worded in reports and errors as the options, ``pinmob.cli.flags``).

    Attributes:
        name: the part's name (``report.part(name)``; the built-in ones are also attributes, ``report.paper``).
        title: the title of its section (the notebook's heading).
        compute: ``compute(report)``, the part (any value), or None when it is not asked for or does not apply;
            it reads its keywords with ``report.options.value(keyword)``. Import heavy modules inside it: they
            then load only when the part is asked for.
        options: the keywords (and command-line options) that ask for it; none: computed for every report (it
            returns None where it has nothing to say).
        text: ``text(report, part)``, its section's text (default ``str(part)``; None: no section).
        entries: ``entries(report, part)``, the entries it adds to ``to_dict()`` (default ``{name:
            part.to_dict()}``, or the part itself when it has no ``to_dict``).
        brief: ``brief(report, part)``, its words in ``brief()``'s line, after a ``;`` (default: none).
        terms: the glossary terms its text uses (``pinmob glossary TERM`` finds each; tests check).
        json_before: the key of ``to_dict()`` its entries go before (None: at the end; the seed paper's view is
            before ``singularity``, as the document had it before the protocol).
        json_null: ``to_dict()`` has its name as ``null`` when the part is None (the minimal closures' key, which
            the document always has); False: no entry then.
        text_before: the title of the section of ``str(report)`` its section goes before when the report has that
            section (None, or no such section: after the sections before it; the minimal closures go before
            ``rank notes``).
        glossary: its own glossary entries (Markdown list items, ``- **term**: ...``) when its words are not in
            ``docs/glossary.md``: ``pinmob glossary`` shows them under "Registered report parts".
        gap: a blank line before its section.
    """

    name: str
    title: str
    compute: Callable[[ReportLike], Any]
    options: tuple[PartOption, ...] = ()
    text: Callable[[ReportLike, Any], str | None] = _text
    entries: Callable[[ReportLike, Any], dict[str, Any]] | None = None
    brief: Callable[[ReportLike, Any], str] | None = None
    terms: tuple[str, ...] = ()
    json_before: str | None = None
    json_null: bool = False
    text_before: str | None = None
    glossary: str = ""
    gap: bool = True

    def document(self, report: ReportLike, value: Any) -> dict[str, Any]:
        """The entries ``value`` (this part of ``report``) adds to ``report.to_dict()``; None: ``{name: None}`` or none.

        None is a part not asked for or not applicable: its name as ``null`` with :attr:`json_null`, else no entry.
        """
        if value is None:
            return {self.name: None} if self.json_null else {}
        if self.entries is not None:
            return self.entries(report, value)
        return {self.name: value.to_dict() if hasattr(value, "to_dict") else value}


#: the registered parts by name, in the order of their sections and entries
REPORT_PARTS: dict[str, ReportPart] = {}


def register_part(part: ReportPart) -> ReportPart:
    """Add ``part`` to every report from now on (after the parts registered before it); returns it.

    Raises:
        ArgumentError: its name, or one of its keywords or options, is already another registered part's.
    """
    taken = {o.keyword for p in REPORT_PARTS.values() for o in p.options}
    taken |= {o.option for p in REPORT_PARTS.values() for o in p.options if o.option}
    clash = [w for o in part.options for w in (o.keyword, o.option) if w in taken]
    if part.name in REPORT_PARTS or clash:
        raise ArgumentError(
            f"report part {part.name!r} is registered already, or its keywords are another part's: "
            f"{', '.join(clash) or part.name}",
            "part",
            part.name,
        )
    REPORT_PARTS[part.name] = part
    return part


def unregister_part(name: str) -> None:
    """Remove the part ``name`` from the reports made from now on (tests register and remove their own)."""
    REPORT_PARTS.pop(name, None)


def part_keywords() -> dict[str, PartOption]:
    """Every registered part's keywords of :func:`pinmob.analyze`, by keyword."""
    return {o.keyword: o for p in REPORT_PARTS.values() for o in p.options}


__all__ = [
    "REPORT_PARTS",
    "Options",
    "PartOption",
    "ReportLike",
    "ReportPart",
    "part_keywords",
    "register_part",
    "unregister_part",
]
