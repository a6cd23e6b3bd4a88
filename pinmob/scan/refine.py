"""One-dimensional refinement of a distance to singularity between scan samples.

A scan samples a distance ``f(t) >= 0`` at integer parameters ``t``; a
singularity is a zero of ``f``, which samples rarely hit. Given a bracket
``a <= b <= c`` with ``f(b) <= f(a), f(c)`` (``f = inf`` where the target
cannot be assembled), :func:`minimise` shrinks it around the minimum:

* a golden-section step (the bracket shrinks by 0.618 per evaluation at worst),
  or a bisection towards an end that cannot be assembled;
* accelerated by a model of the two ways a singular value vanishes along a line:
  a transversal crossing, ``f ~ k |t - t*|`` (a *V*; :func:`v_zero`), and a
  fold at the edge of the reachable set, ``f ~ sqrt(k (t* - t))`` beyond which
  nothing assembles (:func:`fold_root`).

Pure numpy; :mod:`pinmob.scan` supplies ``f`` (assemble at ``t``, warm-started,
and analyse).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

#: Golden-section fraction ``(3 - sqrt 5) / 2``.
GOLDEN = (3.0 - math.sqrt(5.0)) / 2.0

#: Fraction of the way to the predicted fold taken by a first step (short of it: trials beyond it cannot be
#: assembled); each step that lands short leaves a tenth of the remaining fraction, an overshoot resets it.
FOLD_STEP = 0.9

#: Evaluations that assembled without halving the best value after which :func:`minimise` stops (assembly
#: accuracy reached, or a dip that is not a zero); trials that cannot be assembled narrow the bracket and do not count.
STALL = 5


@dataclass(frozen=True)
class Minimum:
    """Outcome of :func:`minimise`: the best parameter, its value and the evaluations spent."""

    t: float
    value: float
    evaluations: int


def v_vertex(a: float, b: float, c: float, fa: float, fb: float, fc: float) -> tuple[float, float] | None:
    """Vertex ``(t*, m)`` of the V ``m + k |t - t*|`` through three points, ``a < b < c``, ``fb <= fa, fc``.

    The slope k is the steeper of the two secants through b (the two points
    on one side of the vertex lie on one branch); the other branch passes
    through the third point with slope -k. None when both secants are flat.
    """
    kl, kr = (fa - fb) / (b - a), (fc - fb) / (c - b)
    k = max(kl, kr)
    if not k > 0:
        return None
    if kl >= kr:  # a, b on the falling branch; vertex to the right of b
        t = (fb - fc + k * (b + c)) / (2 * k)
        return t, fb - k * (t - b)
    t = (fa - fb + k * (a + b)) / (2 * k)  # b, c on the rising branch; vertex to the left of b
    return t, fb - k * (b - t)


def v_zero(a: float, b: float, c: float, fa: float, fb: float, fc: float) -> float | None:
    """Zero of the steeper secant through b, on the far side of b: the crossing of a V ``k |t - t*|``.

    Exact for a V (the two points on the steeper side lie on one branch); a
    secant step on ``|f|`` otherwise. None when both secants are flat.
    """
    kl, kr = (fa - fb) / (b - a), (fc - fb) / (c - b)
    if not max(kl, kr) > 0:
        return None
    return b + fb / kl if kl >= kr else b - fb / kr


def fold_root(a: float, b: float, fa: float, fb: float) -> float | None:
    """Where ``f^2``, extrapolated linearly through ``(a, fa^2)`` and ``(b, fb^2)``, vanishes (beyond b).

    At a fold ``f = sqrt(k (t* - t))``, so ``f^2`` is linear in t and this is
    ``t*`` exactly. None when ``f`` does not decrease from a to b.
    """
    drop = fa * fa - fb * fb
    if not drop > 0:
        return None
    return b + fb * fb * (b - a) / drop


def minimise(
    f: Callable[[float], float],
    a: float,
    b: float,
    c: float,
    fa: float,
    fb: float,
    fc: float,
    *,
    stop: float,
    xtol: float,
    max_eval: int = 60,
) -> Minimum:
    """Minimum of ``f`` in the bracket ``a <= b <= c`` (``f(b) <= f(a), f(c)``; a side may be inf).

    Each step tries the model of the bracket (the zero of a V, :func:`v_zero`,
    when the three values are finite; ``FOLD_STEP``, then 0.99, 0.999, ... of
    the way to the fold, :func:`fold_root`, when one end is inf) and falls back on a golden-section
    step when the model point is outside the bracket or at b, or when the
    previous model step neither halved the bracket nor the best value.

    Args:
        f: the function, ``inf`` where it cannot be evaluated.
        a: left end of the bracket.
        b: a point inside it, ``f(b) <= min(f(a), f(c))``.
        c: right end of the bracket.
        fa: ``f(a)``.
        fb: ``f(b)``.
        fc: ``f(c)``.
        stop: stop once ``f(b) <= stop``.
        xtol: stop once ``c - a <= xtol``.
        max_eval: most evaluations of f; it also stops after ``STALL`` finite evaluations
            that did not halve the best value (an inf one narrows the bracket: not counted).
    """
    evals, slow, mark, stalled, reach = 0, False, fb, 0, FOLD_STEP
    while evals < max_eval and fb > stop and c - a > xtol and stalled < STALL:
        guess = None if slow else _model_point(a, b, c, fa, fb, fc, reach)
        model = guess is not None and a < guess < c and abs(guess - b) > 0.5 * xtol
        x = guess if guess is not None and model else _fallback(a, b, c, fa, fc)
        width, before = c - a, fb
        fx = f(x)
        evals += 1
        if fx < fb:
            if x > b:
                a, fa = b, fb
            else:
                c, fc = b, fb
            b, fb = x, fx
        elif x > b:
            c, fc = x, fx
        else:
            a, fa = x, fx
        slow = model and c - a > 0.5 * width and fb > 0.5 * before
        if model and math.isinf(fa) != math.isinf(fc):  # a fold step: trust the model more after each success
            reach = 1.0 - 0.1 * (1.0 - reach) if fx < before else FOLD_STEP
        if fb < 0.5 * mark:
            mark, stalled = fb, 0
        elif math.isfinite(fx):  # a trial that cannot be assembled still narrows the bracket: not a stall
            stalled += 1
    return Minimum(b, fb, evals)


def _model_point(a: float, b: float, c: float, fa: float, fb: float, fc: float, reach: float) -> float | None:
    if math.isfinite(fa) and math.isfinite(fc) and a < b < c:
        return v_zero(a, b, c, fa, fb, fc)
    root = None
    if math.isinf(fc) and math.isfinite(fa) and a < b:
        root = fold_root(a, b, fa, fb)
    elif math.isinf(fa) and math.isfinite(fc) and b < c:
        root = fold_root(c, b, fc, fb)
    return None if root is None else b + reach * (root - b)


def _fallback(a: float, b: float, c: float, fa: float, fc: float) -> float:
    """Golden-section point in the larger side of the bracket; midway towards an unassembled (inf) end."""
    if math.isinf(fc) and not math.isinf(fa) and c > b:
        return 0.5 * (b + c)
    if math.isinf(fa) and not math.isinf(fc) and b > a:
        return 0.5 * (a + b)
    return b + GOLDEN * (c - b) if c - b >= b - a else b - GOLDEN * (b - a)


def vertex_below(k: int, d: float, dl: float, dr: float, level: float) -> bool:
    """The V through the three samples (:func:`v_vertex`) predicts a minimum below ``level``."""
    vertex = v_vertex(k - 1, k, k + 1, dl, d, dr)
    return vertex is not None and vertex[1] < level
