"""How far a configuration misses closing: its worst residuals in a few words, and the tolerance that would accept it.

CAD geometry closes to about a micron, not to round-off: a file whose loops miss by that much is analysed
with a looser closure tolerance (Python ``closure_tol``, the command line's ``--closure-tol``). A refusal says which value
would accept the miss, computed from the actual residual relative to what the tolerance is relative to
(position / L, rotation [rad]: :func:`~pinmob.assembly.residual.worst_residual`), and lists only the
worst residuals. A miss larger than :data:`CAD_GAP_MAX` is not a modelling round-off: no tolerance is
suggested for it.
"""

from __future__ import annotations

import math
from collections.abc import Mapping

from pinmob.model import CLOSURE_TOL

#: Residuals per name: (position [m], rotation [rad]), as :data:`pinmob.assembly.residual.Residuals`.
Residuals = Mapping[str, tuple[float, float]]

#: Largest miss (position / L, rotation [rad]) for which a looser tolerance is suggested: CAD geometry misses
#: by about a micron on parts of centimetres (1e-5 to 1e-4); beyond, the loops do not close.
CAD_GAP_MAX = 1e-3
#: Residuals a refusal lists (the worst first).
SHOWN = 3
#: Margin of the suggested tolerance over the miss (then rounded up to one significant digit).
MARGIN = 1.05


def _measure(residual: tuple[float, float], length: float) -> float:
    """``max(|p| / L, |r|)`` of one (position, rotation) residual."""
    return max(residual[0] / length, residual[1])


def worst_first(residuals: Residuals, length: float) -> list[tuple[str, tuple[float, float]]]:
    """The residuals ordered from the worst (largest ``max(|p| / L, |r|)``), ties in their order.

    Compared as printed (3 figures): misses equal there keep the residuals' order, not round-off's.
    """
    return sorted(residuals.items(), key=lambda item: -float(f"{_measure(item[1], length):.2e}"))


def format_worst(residuals: Residuals, length: float, tol: float, shown: int = SHOWN) -> str:
    """The worst residuals and the tolerance on one line.

    ``a: 1.0e-06 m, 0.0e+00 rad; b: ...; c: ... (4 of 15 above the tolerance 1e-06 x L = 8.8e-08 m, 1e-06 rad)``:
    the ``shown`` worst above ``tol`` (the ``shown`` largest when none is), the count only when some are left out.
    """
    ordered = worst_first(residuals, length)
    above = [item for item in ordered if _measure(item[1], length) > tol]
    listed = (above or ordered)[:shown]
    text = "; ".join(f"{k}: {p:.2e} m, {r:.2e} rad" for k, (p, r) in listed)
    count = f"{len(above)} of {len(ordered)} above the tolerance" if len(listed) < len(ordered) else "tolerance"
    return f"{text} ({count} {tol:g} x L = {tol * length:.2e} m, {tol:g} rad)"


def accepting_tol(miss: float) -> float | None:
    """The closure tolerance to suggest for a miss (position / L or rad), None above :data:`CAD_GAP_MAX`.

    ``MARGIN x miss`` rounded up to one significant digit (1.42e-6 -> 2e-6), at least the default.
    """
    if not math.isfinite(miss) or miss > CAD_GAP_MAX:
        return None
    value = max(miss * MARGIN, CLOSURE_TOL)
    exponent = math.floor(math.log10(value))
    digit = math.ceil(round(value / 10.0**exponent, 9))
    return float(f"{digit}e{exponent}")


def closes_to(residuals: Residuals, length: float) -> str:
    """``1.04e-06 m (2.1e-05 x L)`` or ``3.0e-06 rad``: the worst residual, in what decides it."""
    if not residuals:
        return "0 m"
    p, r = worst_first(residuals, length)[0][1]
    return f"{p:.3g} m ({p / length:.2g} x L)" if p / length >= r else f"{r:.3g} rad"


def tolerance_hint(residuals: Residuals, length: float) -> str:
    """``; it closes to 1.04e-06 m (2.1e-05 x L): closure_tol=3e-05 would accept it``.

    The empty string when the miss exceeds :data:`CAD_GAP_MAX` (no tolerance should accept it). An error whose
    message holds it names ``closure_tol`` (:meth:`~pinmob.exceptions.PinmobError.naming`): the command line
    words it ``--closure-tol 3e-05 (Python: closure_tol=3e-05)``.
    """
    miss = max((_measure(res, length) for res in residuals.values()), default=0.0)
    tol = accepting_tol(miss)
    if tol is None:
        return ""
    return f"; it closes to {closes_to(residuals, length)}: closure_tol={tol:g} would accept it"
