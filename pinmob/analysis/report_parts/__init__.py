"""The parts of a report beyond the platform, the chain and the singularity, each one registration.

:mod:`~pinmob.analysis.report_parts.report_part` is the protocol (:class:`ReportPart`, :class:`PartOption`,
:func:`register_part`), :mod:`~pinmob.analysis.report_parts.built_in_parts` registers pinmob's own parts.
"""

from __future__ import annotations

from pinmob.analysis.report_parts import built_in_parts as _built_in  # noqa: F401  (registers the built-in parts)
from pinmob.analysis.report_parts.report_part import (
    REPORT_PARTS,
    Options,
    PartOption,
    ReportPart,
    part_keywords,
    register_part,
    unregister_part,
)

__all__ = ["REPORT_PARTS", "Options", "PartOption", "ReportPart", "part_keywords", "register_part", "unregister_part"]
