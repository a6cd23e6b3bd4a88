"""Minimal closures: per closure, the closure of pinmob's vocabulary with exactly its independent equations.

A closure with redundant equations (``rows - rank K > 0``, :mod:`pinmob.analysis.chain.redundancy`) makes the
closure Jacobian ``K`` rank-deficient: a simulator's constraint solver then meets a singular Delassus matrix.
The proposal keeps ``K``'s row space and drops its dependent rows, closure by closure in the order of
``mech.all_closures`` (limb tips welded to the platform first):

- with ``R`` the rows kept so far and ``K_c`` closure c's rows, c needs ``n_c = rank [R; K_c] - rank R``
  equations; ``n_c = rows_c``: c is kept as it is; ``n_c = 0``: c adds nothing and is dropped;
- otherwise c is replaced by the first closure of the vocabulary (:data:`ORDER`) with ``n_c`` rows, on c's
  frames, whose equations are among c's (its wrench rows lie in the span of c's, checked on the two frames
  alone) and whose rows ``J`` span the same space with R: ``rank [R; J] = rank R + n_c`` and
  ``rank [R; K_c; J] = rank [R; K_c]``. Axes tried: c's own, then every joint axis (in frame a), then frame
  a's x, y, z; a universal or perpendicular closure forbids the couple along each of them (``u x u_b``).

The new closure Jacobian then has full row rank ``rank K`` and the same null space: the mechanism DoF, the
idle motions and every frame's motions stay the same at this configuration (to first order: the fixed
mechanism is re-analysed at each named configuration by :func:`~pinmob.analysis.fixed_closures.check_fixed`).
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Any

import numpy as np
import pinocchio as pin

from pinmob.analysis.chain.closed_chain import closed_chain, closed_chain_columns
from pinmob.analysis.configuration import Configuration
from pinmob.assembly import closure_error, compute_kinematics, normal_rows
from pinmob.model import CLOSURE_ROWS, Closure, ClosureType
from pinmob.screw import Array, clean, decide_rank

#: The vocabulary tried, in this order (the first that fits is proposed).
ORDER = (
    ClosureType.REVOLUTE,
    ClosureType.CYLINDRICAL,
    ClosureType.UNIVERSAL,
    ClosureType.BALL,
    ClosureType.ORIENTATION,
    ClosureType.PLANAR_WELD,
    ClosureType.PLANAR,
    ClosureType.INLINE,
    ClosureType.PARALLEL_AXES,
    ClosureType.INPLANE,
    ClosureType.PERPENDICULAR,
)

#: The last line of the text: how to get the corrected mechanism (the command line words it as its command).
FIX_HINT = "the corrected mechanism: `pinmob.fix_closures(mech)`"

#: How the proposal is chosen, said in the JSON document.
MINIMAL_RULE = (
    "closures in order (limb tips first); each keeps the rank it adds to those before it, with the first closure "
    "of the vocabulary whose equations are among its own and span the same rows"
)


@dataclass(frozen=True)
class MinimalClosure:
    """The proposal for one closure.

    Attributes:
        name: the closure (``limb X`` for a limb tip welded to the platform).
        type: its type.
        rows: its equations.
        needed: the equations it must keep (the rank it adds to the closures before it).
        proposed: the closure with exactly ``needed`` equations (None: drop it, or none of the vocabulary fits).
        found: a proposal was found (False: keep it as it is, none of the vocabulary has exactly its equations).
    """

    name: str
    type: str
    rows: int
    needed: int
    proposed: Closure | None
    found: bool = True

    @property
    def changed(self) -> bool:
        """The closure loses equations."""
        return self.needed < self.rows and self.found

    def text(self) -> str:
        """One line: ``B: 6d (6 equations) -> planar_weld, axis [0, 0, 1] in frame 'a' (3)``."""
        head = f"{self.name}: {self.type} ({self.rows} equation{'s' if self.rows != 1 else ''})"
        if not self.changed:
            if self.found:
                return f"{head}: keep"
            if self.type in ("joint", "tendon"):
                return f"{head}: keep ({self.rows - self.needed} implied by the rest; a coupling is not changed)"
            return f"{head}: keep (no closure of the vocabulary has exactly its {self.needed} independent equations)"
        if self.proposed is None:
            return f"{head} -> remove it (every equation is implied by the closures before it)"
        return f"{head} -> {describe(self.proposed)} ({self.needed})"

    def to_dict(self) -> dict[str, Any]:
        """One entry of ``minimal_closures.closures`` in the JSON document."""
        p = self.proposed
        return {
            "name": self.name,
            "type": self.type,
            "rows": self.rows,
            "needed": self.needed,
            "found": self.found,
            "proposed": None
            if p is None or not self.changed
            else {
                "type": str(p.type),
                "frames": [p.frame_a, p.frame_b],
                "axis": None if p.axis is None else [float(x) for x in p.axis],
                "axis_b": None if p.axis_b is None else [float(x) for x in p.axis_b],
                "rows": p.rows,
            },
        }


def describe(c: Closure) -> str:
    """A closure in words: its type and axes (``planar_weld, axis [0, 0, 1] in frame 'a'``)."""
    out = str(c.type)
    if c.axis is not None:
        out += f", axis {_vector(c.axis)} in frame {c.frame_a!r}"
    if c.axis_b is not None:
        out += f", axis_b {_vector(c.axis_b)} in frame {c.frame_b!r}"
    return out


def _vector(v: Array) -> str:
    return "[" + ", ".join(f"{0.0 if abs(x) < 1e-12 else x:.4g}" for x in v) + "]"


@dataclass(frozen=True)
class MinimalClosures:
    """The minimal closures of a mechanism at a configuration (see the module docstring).

    Attributes:
        closures: one :class:`MinimalClosure` per closure, in the order of ``mech.all_closures``.
        rows: the closure equations now; ``rank``: their rank (the rows the proposal keeps when all are found).
    """

    closures: tuple[MinimalClosure, ...]
    rows: int
    rank: int

    @property
    def complete(self) -> bool:
        """Every closure got a proposal: the proposed equations have full row rank."""
        return all(c.found for c in self.closures)

    @property
    def proposed_rows(self) -> int:
        """The closure equations after the proposal."""
        return sum(c.needed if c.changed else c.rows for c in self.closures)

    @property
    def changes(self) -> tuple[MinimalClosure, ...]:
        """The closures that lose equations."""
        return tuple(c for c in self.closures if c.changed)

    def to_dict(self) -> dict[str, Any]:
        """``minimal_closures`` in the JSON document."""
        return {
            "rows": self.rows,
            "rank": self.rank,
            "proposed_rows": self.proposed_rows,
            "complete": self.complete,
            "rule": MINIMAL_RULE,
            "closures": [c.to_dict() for c in self.closures],
        }

    def lines(self) -> list[str]:
        """The proposal in words, a line each, without the last line's hint (``pinmob fix`` prints these)."""
        lines = [
            f"minimal closures: {self.rows} closure equations of rank {self.rank} -> {self.proposed_rows} "
            + ("(full row rank)" if self.proposed_rows == self.rank else "(some redundancy remains)")
        ]
        return lines + ["  " + c.text() for c in self.closures if c.changed or not c.found]

    def __str__(self) -> str:
        return "\n".join([*self.lines(), f"  {FIX_HINT}"])


def minimal_closures(conf: Configuration, rtol: float) -> MinimalClosures | None:
    """The :class:`MinimalClosures` at ``conf``; None when no closure equation is redundant (cached per tolerance).

    Args:
        conf: the closed configuration.
        rtol: the relative tolerance of K's rank decision (as for the mechanism mobility).
    """
    return conf.memo(("minimal closures", rtol), lambda: _compute(conf, rtol))


def _compute(conf: Configuration, rtol: float) -> MinimalClosures | None:
    chain = closed_chain(conf, rtol)
    rows, rank = int(chain.k_hat.shape[0]), chain.decision.rank
    if rows == rank:
        return None
    mech = conf.mechanism
    model, data, col = mech.model, conf.data, closed_chain_columns(conf)
    top = max(1.0, float(chain.decision.singular_values[0]) if chain.decision.singular_values.size else 0.0)

    def rank_of(m: Array) -> int:
        return decide_rank(m, rtol, reference=top).rank if m.size else 0

    def k_rows(c: Closure) -> Array:
        _, jac, lin = closure_error(model, data, c)
        return np.where(lin, 1.0 / mech.length_scale, 1.0)[:, None] * jac * col

    axes = _axes(conf)
    kept = np.zeros((0, model.nv))
    out = []
    start = before = 0
    for c in mech.all_closures:
        own = chain.k_hat[start : start + c.rows]
        start += c.rows
        need = rank_of(np.vstack([kept, own])) - before  # before: the rank of kept, carried below
        if need == c.rows or c.is_coupling:
            out.append(MinimalClosure(c.name, str(c.type), c.rows, need, c, found=need == c.rows))
            kept, before = np.vstack([kept, own]), before + need
            continue
        if need == 0:
            out.append(MinimalClosure(c.name, str(c.type), c.rows, 0, None))
            continue
        span = before + need  # the rank of kept and c's own rows
        wrench = _wrench_rows(conf, c)
        own_rank = _wrench_rank(wrench)
        found, found_rows = None, own
        for cand in _candidates(conf, c, need, axes):
            if _wrench_rank(np.vstack([wrench, _wrench_rows(conf, cand)])) > own_rank:
                continue  # not among c's equations
            rows_j = k_rows(cand)
            if rank_of(np.vstack([kept, rows_j])) == span and rank_of(np.vstack([kept, own, rows_j])) == span:
                found, found_rows = cand, rows_j
                break
        out.append(
            MinimalClosure(c.name, str(c.type), c.rows, need, c if found is None else found, found=found is not None)
        )
        kept, before = np.vstack([kept, found_rows]), span
    return MinimalClosures(tuple(out), rows, rank)


def _axes(conf: Configuration) -> Array:
    """(n, 3) unit axes in world coordinates: every joint's (turn or slide), then the world's x, y, z."""
    jac = conf.world_jacobian
    out: list[Array] = []
    for col in jac.T:
        w, v = col[3:], col[:3]
        a = w if np.linalg.norm(w) > 1e-12 else v
        if np.linalg.norm(a) > 1e-12:
            out.append(a / np.linalg.norm(a))
    return np.array(out + list(np.eye(3)))


def _snapped(a: Array) -> Array:
    """A unit axis with its round-off components (below 1e-12) made 0: ``[0, 0, 1]``, not ``[-7e-30, 0, 1]``."""
    b = clean(a, tol=1e-12)
    return b / np.linalg.norm(b)


def _unique(axes: list[Array]) -> list[Array]:
    out: list[Array] = []
    for a in axes:
        if not any(abs(float(a @ b)) > 1 - 1e-9 for b in out):
            out.append(a)
    return out


def _candidates(conf: Configuration, c: Closure, need: int, world_axes: Array) -> list[Closure]:
    """The closures of :data:`ORDER` with ``need`` rows on c's frames, with every axis tried."""
    ra = np.array(conf.frame_placement(c.frame_a_id).rotation)
    rb = np.array(conf.frame_placement(c.frame_b_id).rotation)
    ra_b = ra.T @ rb  # b's axes in frame a
    own = [np.asarray(c.axis, float)] if c.axis is not None else []
    if c.axis_b is not None:
        own.append(ra.T @ rb @ np.asarray(c.axis_b, float))
    axes = _unique([_snapped(a) for a in own + [ra.T @ a for a in world_axes]])
    out = []
    for t in ORDER:
        if CLOSURE_ROWS[t] != need:
            continue
        base = replace(c, type=t, axis=None, axis_b=None)
        if t in (ClosureType.BALL, ClosureType.ORIENTATION):
            out.append(base)
        elif t in (ClosureType.UNIVERSAL, ClosureType.PERPENDICULAR):
            if c.axis is not None and c.axis_b is not None:  # its own two axes (a universal's)
                out.append(replace(base, axis=c.axis, axis_b=c.axis_b))
            for w in axes:  # the couple along w forbidden: u normal to w, u_b = w x u (so u x u_b = w)
                u = _snapped(normal_rows(w)[0])
                out.append(replace(base, axis=u, axis_b=_snapped(ra_b.T @ np.cross(w, u))))
        else:
            out.extend(replace(base, axis=a) for a in axes)
    return out


def _wrench_rows(conf: Configuration, c: Closure) -> Array:
    """(k, 6) closure c's rows as wrenches on b's relative twist (in frame b), on c's two frames alone.

    A model of two frames: a fixed where a stands, b on a free-flyer where b stands; c's Jacobian there.
    """
    model = pin.Model()
    oma, omb = conf.frame_placement(c.frame_a_id), conf.frame_placement(c.frame_b_id)
    fa = model.addFrame(pin.Frame("a", 0, 0, pin.SE3(oma), pin.FrameType.OP_FRAME))
    joint = model.addJoint(0, pin.JointModelFreeFlyer(), pin.SE3(omb), "b")
    fb = model.addFrame(pin.Frame("b", joint, 0, pin.SE3.Identity(), pin.FrameType.OP_FRAME))
    data = pin.Data(model)
    compute_kinematics(model, data, pin.neutral(model))
    _, jac, lin = closure_error(model, data, replace(c, frame_a_id=fa, frame_b_id=fb))
    return np.where(lin, 1.0 / conf.mechanism.length_scale, 1.0)[:, None] * jac


def _wrench_rank(rows: Array) -> int:
    return decide_rank(rows, 1e-9, at_least=1.0).rank
