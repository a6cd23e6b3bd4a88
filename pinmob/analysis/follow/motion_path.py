"""Following a free motion a finite amount, every step a closed configuration.

A free motion found by :func:`pinmob.analyze` is a first-order (instantaneous)
statement. To show it, :func:`follow_motion` walks along it. The motion's
screw stays fixed in the world; at each closed configuration q it

1. takes the free twist space ``F`` (6, m) at q (``analyze``, once per q) and
   projects the intended twist ``t`` onto it in the dimensionless metric
   ``W = diag(1/L, 1/L, 1/L, 1, 1, 1)``: ``t_F = F (F^T W^2 F)^-1 F^T W^2 t``;
2. predicts the joint step ``dq`` that moves the platform by ``t_F ds`` and
   keeps every closure (limb tips and the loops inside limbs, e.g. a Delta's
   parallelograms) to first order: the least-squares solution of
   ``[K; W J_p] dq = [0; W t_F ds]`` (K: :func:`pinmob.assembly.residual.stacked_error`
   of ``mech.all_closures``, J_p: platform frame Jacobian, world-aligned);
3. re-closes every loop: :func:`pinmob.assembly.assemble.assemble_pose` at the target
   ``M exp(ds t_F)`` (warm start: the prediction); where the target is off the
   motion's manifold (curved motions), :func:`pinmob.assembly.assemble.project` (all
   closures) from the prediction;
4. checks the achieved platform displacement ``d`` (twist at the platform
   origin taking the old pose to the new one) against the step asked for,
   ``t_F ds``: its share along it, ``<W d, W t_F> / (|W t_F|^2 ds)``, must be at
   least ``MIN_PROGRESS``, and its angle to ``t_F`` in the W metric at most
   ``max_deviation`` [rad] (no sideways jump while re-closing). The reference is
   ``t_F``, not ``t``: a curved motion (a Bennett coupler's screw, the parasitic
   motions of a 3-PRS) turns its free twist away from the screw it started
   with, whatever the step size, and is followed as long as ``t`` keeps a
   share ``MIN_SHARE`` of it. A step that fails 3 or 4 is halved, up to
   ``MAX_HALVINGS`` times.

It stops, and says why, when the motion leaves the free space (``|W t_F| <
MIN_SHARE |W t|``), or no step down to ``ds / 2^MAX_HALVINGS`` re-closes along
the motion: where not even the first step succeeds, the mobility found at q
is only instantaneous in that direction. Each direction's result is measured
(:class:`Displacement`). No meshcat here; :mod:`pinmob.viewer.scene` turns paths into
animation clips.

:func:`follow_rates` follows a direction of joint rates the same way (the finite-mobility
analysis traces internal motions, motion branches and motions with the actuators held with it,
from its Configuration: nothing about it is checked again); the steps themselves are in
:mod:`pinmob.analysis.follow.path_follower`.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from pinmob.analysis.configuration import Configuration
from pinmob.analysis.follow import STEPS
from pinmob.analysis.follow.displacement import Displacement, measure_displacement
from pinmob.analysis.follow.path_follower import MAX_HALVINGS, MIN_PROGRESS, MIN_SHARE, Follower, RateFollower
from pinmob.analysis.motion import Motion
from pinmob.assembly import CLOSURE_TOL, check_closed, check_closure_tol
from pinmob.bounds import check_bound
from pinmob.exceptions import ConfigurationError
from pinmob.frozen import ReadOnlyArrays
from pinmob.model import Mechanism
from pinmob.screw import RTOL, MotionKind

Array = np.ndarray

#: default amplitude of translations, as a fraction of the length scale L
TRANSLATION_AMPLITUDE = 0.2
#: default amplitude of rotations and screws [rad]
ROTATION_AMPLITUDE = 0.35
#: default largest angle [rad] between a step's platform displacement and the intended motion (W metric)
MAX_DEVIATION = 0.05
#: Largest step [L for translations, rad otherwise]: a larger one, halved MAX_HALVINGS times, could still
#: miss a real motion (21 m in 2 steps made the 3-PUU's translations "only instantaneous")
MAX_STEP = 0.5

__all__ = ["MAX_DEVIATION", "MAX_HALVINGS", "MIN_PROGRESS", "MIN_SHARE", "MotionPath", "follow_motion", "follow_rates"]


@dataclass(frozen=True)
class MotionPath(ReadOnlyArrays):
    """A free motion followed forwards and backwards from q.

    Attributes:
        label: the motion's label (``T1 x``, ``R1 z``...).
        forward: closed configurations q, q_1, ..., q_n along +t.
        backward: closed configurations q, q_-1, ..., q_-m along -t.
        reached: (forward, backward) distance covered along the motion [m for T, rad for R/H].
        amplitude: distance asked for in each direction [m or rad].
        notes: why a direction stopped early (empty when both reached the amplitude).
        displacement: (forward, backward) measured displacement of the platform at each end.
        finite: the finite-mobility verdict on the motion (:mod:`pinmob.analysis.finite.finite_mobility`): True (finite),
            False (only instantaneous: blocked at some order, or only a combination of branches),
            None (not analysed, or cannot decide).
        verdict: that verdict in words (empty when not analysed).
    """

    label: str
    forward: tuple[Array, ...]
    backward: tuple[Array, ...]
    reached: tuple[float, float]
    amplitude: float
    notes: tuple[str, ...] = ()
    displacement: tuple[Displacement, Displacement] = (Displacement(0, 0, 0), Displacement(0, 0, 0))
    finite: bool | None = None
    verdict: str = ""

    @property
    def complete(self) -> bool:
        """True when the motion was followed the full amplitude both ways."""
        return not self.notes

    def frames(self) -> list[Array]:
        """Animation frames: q -> +amplitude -> q -> -amplitude -> q (at least two frames)."""
        f, b = list(self.forward), list(self.backward)
        seq = f + f[-2::-1] + b[1:] + b[-2::-1]
        return seq if len(seq) > 1 else seq * 2

    def to_dict(self) -> dict[str, Any]:
        """The path as plain JSON: label, amplitude, distances reached, notes, displacements, finite verdict."""
        return {
            "label": self.label,
            "amplitude": self.amplitude,
            "reached": list(self.reached),
            "displacement": [d.to_dict() for d in self.displacement],
            "notes": list(self.notes),
            "finite": self.finite,
            "verdict": self.verdict,
        }


def default_amplitude(motion: Motion, length: float) -> float:
    """Distance shown for a motion: ``0.2 L`` [m] for translations, 0.35 rad otherwise."""
    return TRANSLATION_AMPLITUDE * length if motion.kind is MotionKind.TRANSLATION else ROTATION_AMPLITUDE


def _measure(motion: Motion) -> slice:
    """Part of a twist that measures distance: v for translations, w otherwise."""
    return slice(0, 3) if motion.kind is MotionKind.TRANSLATION else slice(3, 6)


def follow_motion(
    mech: Mechanism,
    q: Array | Configuration,
    motion: Motion,
    *,
    amplitude: float | None = None,
    steps: int = STEPS,
    rtol: float = RTOL,
    closure_tol: float = CLOSURE_TOL,
    max_deviation: float = MAX_DEVIATION,
    halvings: int = MAX_HALVINGS,
    either: bool = False,
) -> MotionPath:
    """Follow ``motion`` from the closed configuration q, both ways, by continuation.

    Args:
        mech: the mechanism.
        q: (nq,) closed configuration where ``motion`` was found, or a closed :class:`Configuration` of ``mech``
            (checked where it was made: not checked again, ``closure_tol`` is its own).
        motion: one of ``analyze(mech, q).motions``.
        amplitude: distance in each direction [m for T, rad for R and H];
            default :func:`default_amplitude`.
        steps: continuation steps per direction (each may be halved, see the module).
        rtol: rank tolerance of the mobility analysis at each step.
        closure_tol: closure tolerance of every frame (position / L, rotation [rad]).
        max_deviation: largest angle [rad] between a step's platform displacement
            and the intended motion (W metric); a step beyond it is halved or refused.
        halvings: how many times a failed step is halved before the motion stops.
        either: follow backwards only when forwards stops short of the amplitude (for the farthest reach
            either way, ``max(path.reached)``, which is then the same; the backward path is then ``(q,)``).

    Returns:
        the path; every configuration in it closes within ``closure_tol``.

    Raises:
        ConfigurationError: ``steps`` < 1, a non-positive amplitude or max_deviation, an unchecked Configuration.
        ArgumentError: ``closure_tol`` out of range.
        ClosureError: q itself does not close.
    """
    if steps < 1:
        raise ConfigurationError(f"steps must be at least 1, got {steps}")
    check_bound("steps", steps, "the animation (steps)", "steps")
    amp = default_amplitude(motion, mech.length_scale) if amplitude is None else float(amplitude)
    if not np.isfinite(amp) or amp <= 0:
        raise ConfigurationError(
            f"amplitude must be a positive number (m for translations, rad otherwise), got {amplitude!r}"
        )
    if not np.isfinite(max_deviation) or max_deviation <= 0:
        raise ConfigurationError(f"max_deviation must be a positive angle [rad], got {max_deviation!r}")
    unit_name = "m" if motion.kind is MotionKind.TRANSLATION else "rad"
    limit = MAX_STEP * (mech.length_scale if motion.kind is MotionKind.TRANSLATION else 1.0)
    if amp / steps > limit:  # halved MAX_HALVINGS times, such a step could call a real motion instantaneous
        raise ConfigurationError(
            f"amplitude {amp:g} {unit_name} in {steps} steps makes steps of {amp / steps:.3g} {unit_name}, over "
            f"{limit:.3g} {unit_name} ({MAX_STEP:g} L for translations, {MAX_STEP:g} rad otherwise); lower the "
            f"amplitude or use at least {min(np.ceil(amp / limit), 1e18):.0f} steps"
        )
    origin = _origin(mech, q, closure_tol, "the configuration to animate")
    unit = motion.twist / np.linalg.norm(motion.twist[_measure(motion)])
    follower = Follower(mech, motion, rtol, origin.closure_tol, max_deviation, halvings)
    return _both_ways(follower, origin, unit, unit, amp, steps, motion.label, unit_name, either)


def follow_rates(
    mech: Mechanism,
    q: Array | Configuration,
    rates: Array,
    *,
    label: str = "motion",
    amplitude: float = 0.05,
    steps: int = 2,
    held: tuple[int, ...] = (),
    rtol: float = RTOL,
    closure_tol: float = CLOSURE_TOL,
    max_deviation: float = MAX_DEVIATION,
    halvings: int = MAX_HALVINGS,
    either: bool = False,
) -> MotionPath:
    """Follow a direction of joint rates from the closed configuration q, both ways, every step closed.

    Args:
        mech: the mechanism.
        q: (nq,) closed configuration, or a closed :class:`Configuration` of ``mech`` (as for :func:`follow_motion`).
        rates: (nv,) joint rates, dimensionless (translation rates per L).
        label: the path's label.
        amplitude: distance in each direction, in the dimensionless joint metric [rad, or m / L].
        steps: continuation steps per direction.
        held: velocity indices of joints kept at their values (e.g. locked actuators).
        rtol: rank tolerance of the closed chain's rates at each step.
        closure_tol: closure tolerance of every frame.
        max_deviation: largest angle [rad] between a step's joint displacement and the direction.
        halvings: how many times a failed step is halved before the direction stops.
        either: follow backwards only when forwards stops short of the amplitude (:func:`follow_motion`).

    Returns:
        the path (``reached`` in the dimensionless joint metric); every configuration in it closes.
    """
    origin = _origin(mech, q, closure_tol, "the configuration to follow from")
    unit = np.asarray(rates, float) / np.linalg.norm(rates)
    follower = RateFollower(mech, held, rtol, origin.closure_tol, max_deviation, halvings)
    return _both_ways(follower, origin, unit, np.zeros(6), amplitude, steps, label, "(joint metric)", either)


def _origin(mech: Mechanism, q: Array | Configuration, closure_tol: float, what: str) -> Configuration:
    """The closed configuration a path starts from: a Configuration as it is (checked where it was made), else q's."""
    if isinstance(q, Configuration):
        if q.mechanism is not mech or not np.isfinite(q.closure_tol):
            raise ConfigurationError(
                f"{what} must be a closed Configuration of {mech.name!r} (not Configuration.unchecked), got {q!r}"
            )
        return q
    q = mech.check_q(q)
    closure_tol = check_closure_tol(closure_tol)  # once: every step's Configuration trusts it
    check_closed(mech, q, closure_tol, what=what)
    return Configuration.from_checked(mech, q, closure_tol)


def _both_ways(
    follower: Follower,
    origin: Configuration,
    unit: Array,
    twist: Array,
    amp: float,
    steps: int,
    label: str,
    unit_name: str,
    either: bool = False,
) -> MotionPath:
    """The path from ``origin`` along ``unit`` and ``-unit``, each end's platform displacement measured against ``twist``.

    With ``either``, ``-unit`` is not followed when ``unit`` reaches ``amp`` (its path is then ``(q,)``). Both
    directions share what is computed at q (``origin``'s memo).
    """
    q, start = origin.q, follower.pose(origin.q)
    branches, reasons, moved = [], [], []
    reached: list[float] = []
    for sign in (1.0, -1.0):
        if either and sign < 0 and reached[0] == amp:
            path, covered, why = [q], 0.0, ""
        else:
            path, covered, why = follower.branch(origin, sign * unit, amp, amp / steps)
        branches.append(tuple(path))
        reached.append(covered)
        reasons.append(why)
        moved.append(
            measure_displacement(start, follower.pose(path[-1]), sign * twist, follower.mech.length_scale, follower.tol)
        )
    notes = _notes(label, reasons, reached, amp, unit_name)
    return MotionPath(label, branches[0], branches[1], (reached[0], reached[1]), amp, notes, (moved[0], moved[1]))


def _notes(label: str, reasons: list[str], reached: list[float], amp: float, unit: str) -> tuple[str, ...]:
    """One note per direction that stopped early; one for both when neither moved, for the same reason."""
    hint = "; the mobility found there is only instantaneous in this direction"
    if reasons[0] and reasons[0] == reasons[1] and reached == [0.0, 0.0]:
        return (f"{label}: cannot be followed either way from here: {reasons[0]}{hint}",)
    notes = []
    for word, why, done in zip(("forwards", "backwards"), reasons, reached, strict=True):
        if why:
            extra = hint if done == 0.0 else ""
            notes.append(f"{label}: stopped {word} after {done:.3g} {unit} of {amp:.3g}: {why}{extra}")
    return tuple(notes)
