"""Actuation: with the actuated joints locked, which closed-chain motions remain, and valid actuator sets.

With the actuated joints locked, the motions left (``locked_dof``, idle ones
included) are all idle when the actuation is valid; actuated rates that are not
independent on the closed chain over-determine it. Idle motions move no output
frame, no joint centre and no closure point
(:func:`pinmob.analysis.chain.closed_chain.output_motions`).

A floating base (a free-flyer joint at the root of the tree carrying other joints: a legged robot's
pelvis) moves in its own 6 DoF whatever the motors do; the actuation is judged with it held
(:func:`held_indices`), and the verdict says so. An actuator on a tendon, a site, a slider-crank, a ball joint or
an orientation servo (MJCF) holds its moment arms at the configuration (:func:`~pinmob.model.tendon.tendon_rows`; a fixed tendon's
combination of joint rates), counted with the joints.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import pinocchio as pin
from numpy.typing import ArrayLike, NDArray

from pinmob.analysis.chain.closed_chain import ClosedChain, closed_chain, frame_rows, output_motions, rates_of
from pinmob.analysis.chain.joint_rates import canonical_rates, joint_rates
from pinmob.analysis.chain.locking import Locked, lock
from pinmob.analysis.configuration import Configuration, as_configuration
from pinmob.assembly import CLOSURE_TOL, joint_velocity_indices
from pinmob.blas import one_blas_thread
from pinmob.exceptions import ConfigurationError
from pinmob.model import Mechanism, Transmission
from pinmob.progress import step
from pinmob.screw import RTOL, Array, check_rtol, decide_rank

#: Largest number of actuator sets :func:`actuator_sets` tries (C(n, k) above it is refused).
SEARCH_LIMIT = 50_000


@dataclass(frozen=True)
class Actuation:
    """Validity of an actuator set at a configuration.

    Attributes:
        actuated: the actuated joints.
        valid: every motion left with them locked is idle, and they are independent.
        locked_dof: motions left with the actuated joints locked (idle ones included).
        idle_dof: idle motions among them.
        redundant_actuators: actuated rates implied by the others and the held floating bases (> 0:
            over-determined); a base's own rates that the closures already fix (a base pinned to the world)
            are not counted.
        frame_dof: DoF of each end frame with the actuators locked (0 = rigid).
        remaining: the non-idle motions left, each as joint rates by name
            (largest 1, rates below 1e-6 dropped).
        base: the floating bases held while judging (free-flyer joints at the root), by joint name.
        rate_singular_values: singular values of the held joints' rates on an orthonormal basis of the
            closed chain's dimensionless motions (``S N``, (held, m)): the matrix whose rank ``rank_a`` is decided
            (:func:`~pinmob.analysis.chain.locking.lock`); its tolerance is ``rtol * max(1, sigma_1)``.
        tendons: the actuators on tendons, sites, slider-cranks and ball joints, by name, held with the
            joints (:func:`~pinmob.model.tendon.tendon_rows`).
        tendon_kinds: what each of them drives (:attr:`~pinmob.model.tendon.Transmission.kind`).
        joint_actuators: the file's actuators on the actuated joints, ``(actuator, joint)`` (MJCF); a joint
            with two (MuJoCo's position and velocity servo pair) is actuated once: one coordinate driven.
    """

    actuated: tuple[str, ...]
    valid: bool
    locked_dof: int
    idle_dof: int
    redundant_actuators: int
    frame_dof: dict[str, int] = field(default_factory=dict)
    remaining: tuple[dict[str, float], ...] = ()
    base: tuple[str, ...] = ()
    rate_singular_values: tuple[float, ...] = ()
    tendons: tuple[str, ...] = ()
    tendon_kinds: tuple[str, ...] = ()
    joint_actuators: tuple[tuple[str, str], ...] = ()

    @property
    def count_text(self) -> str:
        """``3 actuated joint(s)``, with ``and 1 tendon actuator(s)`` (``site/tendon``...) when there are.

        A joint driven by several actuators is named with them: ``1 actuated joint(s) ('crank' by 2 actuators:
        crank_position, crank_velocity)``.
        """
        kinds = "/".join(sorted(set(self.tendon_kinds))) or "tendon"
        tendons = f" and {len(self.tendons)} {kinds} actuator(s)" if self.tendons else ""
        by_joint: dict[str, list[str]] = {}
        for actuator, joint in self.joint_actuators:
            by_joint.setdefault(joint, []).append(actuator)
        shared = [f"{j!r} by {len(a)} actuators: {', '.join(a)}" for j, a in by_joint.items() if len(a) > 1]
        return f"{len(self.actuated)} actuated joint(s)" + (f" ({'; '.join(shared)})" if shared else "") + tendons

    def to_dict(self) -> dict[str, Any]:
        """The ``actuation`` entry of ``pinmob analyze --json``."""
        return {
            "valid": self.valid,
            "locked_dof": self.locked_dof,
            "remaining": [dict(m) for m in self.remaining],
            "actuated": list(self.actuated),
            "idle_dof": self.idle_dof,
            "redundant_actuators": self.redundant_actuators,
            "overdetermined": self.redundant_actuators > 0,
            "frame_dof_locked": dict(self.frame_dof),
            "base_held": list(self.base),
            "actuated_tendons": list(self.tendons),
            "joint_actuators": dict(self.joint_actuators),
        }

    @property
    def base_note(self) -> str:
        """`` (floating base 'x' held: its own 6 DoF)`` when there is one, else ``""``."""
        if not self.base:
            return ""
        names = ", ".join(repr(b) for b in self.base)
        return f" (floating base {names} held: {6 * len(self.base)} DoF of the base's own)"


def floating_bases(mech: Mechanism) -> tuple[str, ...]:
    """The floating bases, by name: free-flyer joints at the root of the tree that carry other joints.

    A free body that carries no joint (a part pinned or welded into a loop) is a part of the
    mechanism, not a robot's base. Computed once per mechanism.
    """

    def compute() -> tuple[str, ...]:
        model = mech.model
        parents = model.parents.tolist()
        return tuple(
            model.names[j]
            for j in range(1, model.njoints)
            if parents[j] == 0 and model.joints[j].shortname() == "JointModelFreeFlyer" and len(model.subtrees[j]) > 1
        )

    return mech.memo("floating bases", compute)


def held_indices(mech: Mechanism, actuated: Sequence[str]) -> NDArray[np.intp]:
    """Velocity indices held while judging the actuation: the actuated joints', then each floating base's six.

    Computed once per mechanism and set of actuated joints (read-only).

    Raises:
        FrameError: an unknown joint (the message lists them).
        ConfigurationError: an actuated joint with more than one degree of freedom.
    """

    def compute() -> NDArray[np.intp]:
        model = mech.model
        base = [model.joints[model.getJointId(b)] for b in floating_bases(mech)]
        extra = [np.arange(j.idx_v, j.idx_v + 6) for j in base]
        out = np.concatenate([joint_velocity_indices(mech, list(actuated)), *extra]).astype(np.intp)
        out.flags.writeable = False
        return out

    return mech.memo(("held indices", tuple(actuated)), compute)


def rank_of(matrix: Array, rtol: float) -> int:
    """Rank of a matrix built from orthonormal bases (tolerance ``rtol * max(1, sigma_max)``)."""
    return decide_rank(matrix, rtol, at_least=1.0).rank if matrix.size else 0


def actuation(
    conf: Configuration,
    chain: ClosedChain,
    actuated: Sequence[str],
    split: Locked,
    frames: Sequence[str],
    rtol: float,
    tendons: Sequence[Transmission] = (),
    joint_actuators: Sequence[tuple[str, str]] = (),
) -> Actuation:
    """The :class:`Actuation` verdict from the locked split of the closed chain's motions (joints and tendons held).

    ``joint_actuators`` name the actuators of ``actuated`` (``(actuator, joint)``); a joint is counted once however
    many drive it.
    """
    mech = conf.mechanism
    n = chain.null
    m = n.shape[1]
    locked, idle = split.locked, split.idle
    # non-idle remaining motions: an orthonormal basis of `locked` orthogonal to `idle`
    rest = locked - idle @ (idle.T @ locked) if locked.size else locked
    # its singular values are 1 or 0 (a difference of nested orthonormal bases): 0.5 separates them
    basis = decide_rank(rest.T, 0.5, m, at_least=1.0).row_space.T if rest.size else np.zeros((m, 0))
    rates = canonical_rates(n @ basis)
    remaining = [joint_rates(mech, chain.col * rates[:, i]) for i in range(rates.shape[1])]
    frame_dof = {name: rank_of(frame_rows(conf, name) @ n @ locked, rtol) if locked.size else 0 for name in frames}
    base = floating_bases(mech)
    count = len(actuated) + len(tendons) + 6 * len(base)
    if base:  # a base the closures already hold in part (pinned to the world): those rates are no actuator's
        count -= 6 * len(base) - rank_of(rates_of(n, held_indices(mech, ())), rtol)
    return Actuation(
        tuple(actuated),
        split.valid(count),
        locked.shape[1],
        idle.shape[1],
        count - split.rank_a,
        frame_dof,
        tuple(remaining),
        base,
        tuple(split.singular_values.tolist()),
        tuple(t.name for t in tendons),
        tuple(t.kind for t in tendons),
        tuple(joint_actuators),
    )


def default_end_frames(mech: Mechanism) -> tuple[str, ...]:
    """The platform if any; else the leaf bodies of the tree that carry no closure frame (a coupling's do not count)."""
    if mech.has_platform:
        return (mech.platform,)
    model = mech.model
    has_child = {int(model.parents[j]) for j in range(1, model.njoints)}
    loops = (c for c in mech.all_closures if not c.is_coupling)  # a coupled fingertip is still a free end
    closing = {model.frames[i].parentJoint for c in loops for i in (c.frame_a_id, c.frame_b_id)}
    leaves = [j for j in range(1, model.njoints) if j not in has_child and j not in closing]
    out = []
    for j in leaves:
        bodies = [f.name for f in model.frames if f.parentJoint == j and f.type == pin.FrameType.BODY]
        out.append(bodies[0] if bodies else model.names[j])
    return tuple(out)


@one_blas_thread
def actuator_sets(
    mech: Mechanism | Configuration,
    q: ArrayLike | str | Configuration | None,
    size: int,
    *,
    candidates: Sequence[str] | None = None,
    outputs: Sequence[str] | None = None,
    rtol: float = RTOL,
    closure_tol: float = CLOSURE_TOL,
    limit: int = SEARCH_LIMIT,
) -> list[tuple[str, ...]]:
    """Every valid set of ``size`` actuated joints among ``candidates`` (default: all one-degree joints).

    A set is valid when its joints are independent on the closed chain and
    locking them leaves only idle motions (those that move no ``outputs``
    frame; the same split as the actuation verdict). Exhaustive: C(n, size)
    sets are tried, each with an SVD of (size, m) and, unless :func:`~pinmob.analysis.chain.locking.lock`
    skips it, of (size + outputs, m); more than ``limit`` sets is refused
    (name fewer candidates). ``outputs`` default to :func:`default_end_frames`; ``rtol`` is raised where the
    loops close only to CAD accuracy (:meth:`~pinmob.analysis.configuration.Configuration.rank_rtol`).

    Raises:
        ConfigurationError: size out of range or too many combinations.
    """
    conf = as_configuration(mech, q, closure_tol=closure_tol)
    rtol = conf.rank_rtol(check_rtol(rtol))
    mech = conf.mechanism
    outputs = tuple(default_end_frames(mech) if outputs is None else outputs)
    model = mech.model
    names = (
        list(candidates)
        if candidates is not None
        else [model.names[j] for j in range(1, model.njoints) if model.joints[j].nv == 1]
    )
    if isinstance(size, bool) or not isinstance(size, int) or not 0 < size <= len(names):
        raise ConfigurationError(f"actuator set size must be in 1..{len(names)} (the candidate joints), got {size!r}")
    count = math.comb(len(names), size)
    if count > limit:
        raise ConfigurationError(
            f"{count} sets of {size} among {len(names)} joints exceed the search limit {limit}; name fewer candidate joints"
        )
    chain = closed_chain(conf, rtol)
    n = chain.null
    rates = rates_of(n, joint_velocity_indices(mech, names))  # (len(names), m)
    out = output_motions(conf, outputs, n)
    valid = []
    with step(f"trying every set of {size} actuated joints of {mech.name}", total=count) as bar:
        for combo in itertools.combinations(range(len(names)), size):
            split = lock(rates[list(combo)], lambda: out, rtol, n.shape[1])
            if split.valid(size):
                valid.append(tuple(names[i] for i in combo))
            bar.update()
    return valid
