"""A Report in a notebook: ``str(report)``'s sections as HTML (:meth:`pinmob.analysis.report.Report._repr_html_`).

The HTML has no wording of its own beyond headings: a table of the answer (the mechanism, the DoF and
motion type, the singularity class, the whole mechanism's DoF), a table of the platform's free motions
(:meth:`~pinmob.analysis.motion.Motion.words`, the words each motion's line of the text is written
from), then each :class:`Section` of ``str(report)``, its text as printed, under its title.
Every string is escaped: names come from the mechanism's files.
"""

from __future__ import annotations

import html
from collections.abc import Sequence
from dataclasses import dataclass

from pinmob.analysis.chain.mechanism_mobility import MechanismMobility
from pinmob.analysis.mobility import Mobility
from pinmob.analysis.singularity.result import Singularity


@dataclass(frozen=True)
class Section:
    """One part of ``str(report)``: its title (the HTML heading), its text, and whether a blank line precedes it."""

    title: str
    text: str
    gap: bool = False


def joined(sections: Sequence[Section]) -> str:
    """The text of ``sections`` as ``str(report)`` prints it (a blank line before each ``gap`` section)."""
    lines: list[str] = []
    for s in sections:
        lines += ["", s.text] if s.gap else [s.text]
    return "\n".join(lines)


def _e(text: object) -> str:
    return html.escape(str(text), quote=True)


_LEFT = ' style="text-align: left; padding: 1px 12px 1px 0"'


def _table(rows: Sequence[Sequence[str]], header: Sequence[str] | None = None) -> str:
    """A table: ``header`` as its column headers; without one, each row's first cell is that row's header."""
    lines = [] if header is None else ["<tr>" + "".join(f"<th{_LEFT}>{_e(h)}</th>" for h in header) + "</tr>"]
    for row in rows:
        plain = header is not None
        first = f"<td{_LEFT}>{_e(row[0])}</td>" if plain else f'<th scope="row"{_LEFT}>{_e(row[0])}</th>'
        lines.append(f"<tr>{first}" + "".join(f"<td{_LEFT}>{_e(c)}</td>" for c in row[1:]) + "</tr>")
    return '<table class="pinmob-table">' + "".join(lines) + "</table>"


def report_html(
    mechanism: str,
    configuration: str | None,
    mobility: Mobility | None,
    singularity: Singularity | None,
    chain: MechanismMobility,
    sections: Sequence[Section],
) -> str:
    """The HTML of a report: its answer and the platform's motions as tables, then its sections as printed.

    Args:
        mechanism: the mechanism's name.
        configuration: the configuration's name (None when unnamed).
        mobility: the platform mobility (None without limbs).
        singularity: the singularity classes (None where not analysed).
        chain: the whole closed chain's mobility.
        sections: ``str(report)`` in its parts (:meth:`pinmob.analysis.report.Report.sections`).
    """
    facts = [("mechanism", mechanism), ("configuration", configuration or "(unnamed)")]
    if mobility is not None:
        facts.append(("platform", f"{mobility.dof} DoF, {mobility.motion_type}"))
    else:  # no limbs: each output frame's DoF (its motions are in the mechanism's section)
        facts += [(f"frame {f.frame!r}", f"{f.dof} DoF, {f.motion_type}") for f in chain.frames]
    if singularity is not None:
        facts.append(("singularity", singularity.label))
    facts.append(("mechanism DoF", str(chain.mechanism_dof)))
    parts = ['<div class="pinmob-report">', _table(facts)]
    if mobility is not None and mobility.motions:
        origin, length = mobility.platform_origin, mobility.length_scale
        parts.append("<p><strong>free motions of the platform</strong> (world coordinates)</p>")
        header = ("motion", "kind", "direction", "axis through [m]", "pitch [m/rad]")
        parts.append(_table([m.words(origin, length) for m in mobility.motions], header))
    for s in sections:
        parts.append(
            f'<details open><summary><strong>{_e(s.title)}</strong></summary><pre style="white-space: pre-wrap">'
            f"{_e(s.text)}</pre></details>"
        )
    parts.append("</div>")
    return "\n".join(parts)
