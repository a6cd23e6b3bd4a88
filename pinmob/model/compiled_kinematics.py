"""Frame placements and Jacobians of a ``pin.Model`` for a stack of configurations, compiled when it can be.

Pinocchio has no batched kinematics: from Python each ``computeJointJacobians`` pays its own call overhead. A
:class:`FrameKinematics` built by :func:`frame_kinematics` computes the placements of some frames and their
Jacobians for B configurations in one call:

* ``engine == "compiled"``: :func:`pinmob.model.kinematics_kernel.frames_kernel` (numba, the optional ``fast``
  extra) running tables generated here from the model: its joints as elementary joints (revolute and prismatic
  on any axis, unbounded revolute about x, y or z, spherical, free, planar, translation; a universal joint is two revolute ones,
  a composite joint its parts), their placements, and the frames' joints and placements;
* ``engine == "pinocchio"``: Pinocchio's own calls per configuration (``computeJointJacobians``,
  ``updateFramePlacements``, ``getFrameJacobian``), the fallback when numba is not installed or a joint has
  another type (helical, mimic, ZYX spherical, ellipsoid, unbounded revolute on another axis...; :attr:`FrameKinematics.reason` says which), and the
  reference the compiled engine is tested against (``tests/test_compiled_kinematics.py``: equal to 1e-12).
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from functools import cached_property
from typing import TYPE_CHECKING, Any

import numpy as np
import pinocchio as pin

from pinmob.exceptions import ConfigurationError
from pinmob.screw import Array

if TYPE_CHECKING:
    from pinmob.model.mechanism import Mechanism

#: The engines, and the references of a frame Jacobian by Pinocchio's name.
ENGINES = ("compiled", "pinocchio")
#: The environment variable that chooses the engine where the caller does not (tests run scans both ways with it).
ENGINE_VARIABLE = "PINMOB_KINEMATICS"
REFERENCES = {pin.LOCAL: 0, pin.LOCAL_WORLD_ALIGNED: 1, pin.WORLD: 2}

# elementary joint kinds: the codes of pinmob.model.kinematics_kernel (not imported here: it imports numba)
_REVOLUTE, _PRISMATIC, _UNBOUNDED, _SPHERICAL, _FREE, _PLANAR, _TRANSLATION = range(7)
_INTEGRABLE = (_REVOLUTE, _PRISMATIC, _UNBOUNDED, _SPHERICAL, _TRANSLATION)  # kinematics_kernel.INTEGRABLE
_AXES = {"X": (1.0, 0.0, 0.0), "Y": (0.0, 1.0, 0.0), "Z": (0.0, 0.0, 1.0)}
_SIMPLE = {"JointModelSpherical": _SPHERICAL, "JointModelFreeFlyer": _FREE, "JointModelPlanar": _PLANAR,
           "JointModelTranslation": _TRANSLATION}  # fmt: skip
_ALIGNED = {"JointModelR": _REVOLUTE, "JointModelP": _PRISMATIC, "JointModelRUB": _UNBOUNDED}
# (Pinocchio's Python bindings do not expose the axis of a JointModelRevoluteUnboundedUnaligned: not compiled)
_UNALIGNED = {"JointModelRevoluteUnaligned": _REVOLUTE, "JointModelPrismaticUnaligned": _PRISMATIC}


class UnsupportedJoint(Exception):
    """A joint type the compiled engine does not write (Pinocchio computes that model)."""


def numba_available() -> bool:
    """Numba can be imported (the ``fast`` extra): the kinematics, the batch analysis, the predictor compile."""
    try:
        import numba  # noqa: F401
    except ImportError:
        return False
    return True


def _elementary(joint: Any, placement: pin.SE3) -> list[tuple[int, Array, int, int, pin.SE3]]:
    """(kind, axis, idx_q, idx_v, placement in the previous one) of the elementary joints making ``joint``."""
    name = joint.shortname()
    none = np.zeros(3)
    if name in _SIMPLE:
        return [(_SIMPLE[name], none, joint.idx_q, joint.idx_v, placement)]
    for prefix, kind in _ALIGNED.items():
        if name[len(prefix) :] in _AXES and name.startswith(prefix):
            return [(kind, np.array(_AXES[name[len(prefix) :]]), joint.idx_q, joint.idx_v, placement)]
    if name in _UNALIGNED:
        axis = np.asarray(joint.extract().axis, float)
        return [(_UNALIGNED[name], axis / np.linalg.norm(axis), joint.idx_q, joint.idx_v, placement)]
    if name == "JointModelUniversal":
        u = joint.extract()
        a1, a2 = np.asarray(u.axis1, float), np.asarray(u.axis2, float)
        return [(_REVOLUTE, a1 / np.linalg.norm(a1), joint.idx_q, joint.idx_v, placement),
                (_REVOLUTE, a2 / np.linalg.norm(a2), joint.idx_q + 1, joint.idx_v + 1, pin.SE3.Identity())]  # fmt: skip
    if name == "JointModelComposite":
        composite = joint.extract()
        parts = []
        for k, (sub, inner) in enumerate(zip(composite.joints, composite.jointPlacements)):
            parts += _elementary(sub, placement * inner if k == 0 else inner)
        return parts
    raise UnsupportedJoint(name)


class FrameKinematics:
    """Placements and Jacobians of the frames ``frames`` of ``model`` for stacks of configurations (module docstring).

    Attributes:
        model: the Pinocchio model.
        frames: the frame indices, in the order of the results.
        engine: ``compiled`` or ``pinocchio``.
        reason: why the engine is Pinocchio (empty for the compiled one).
    """

    def __init__(self, model: pin.Model, frames: Sequence[int], engine: str, reason: str = "") -> None:
        self.model, self.frames, self.engine, self.reason = model, tuple(int(f) for f in frames), engine, reason
        #: The compiled engine's tables (:func:`pinmob.model.kinematics_kernel.frames_kernel`'s arguments after the
        #: configurations); empty for Pinocchio's engine.
        self.tables: tuple[Array, ...] = self._build_tables() if engine == "compiled" else ()
        #: Every joint's ``pin.integrate`` is compiled too (:func:`pinmob.model.kinematics_kernel.integrate_kernel`:
        #: no free-flyer or planar joint), so a compiled loop can move its configurations itself.
        self.integrable = bool(self.tables) and set(self.tables[1].tolist()) <= set(_INTEGRABLE)

    @cached_property
    def _data(self) -> pin.Data:
        """Pinocchio's engine's ``pin.Data``, made when first used.

        The compiled engine needs none, and a 6-UPS's takes 0.5 ms to make.
        """
        return pin.Data(self.model)  # as model.createData(), without its copy

    def _build_tables(self) -> tuple[Array, ...]:
        model = self.model
        rows: list[tuple[int, int, Array, int, int, pin.SE3]] = []
        last = {0: -1}  # joint -> its last elementary joint
        for j in range(1, model.njoints):
            parent = last[model.parents[j]]
            for kind, axis, iq, iv, placement in _elementary(model.joints[j], model.jointPlacements[j]):
                rows.append((parent, kind, axis, iq, iv, placement))
                parent = len(rows) - 1
            last[j] = parent
        frames = [model.frames[f] for f in self.frames]
        return (
            np.array([r[0] for r in rows], np.int64),
            np.array([r[1] for r in rows], np.int64),
            np.array([r[2] for r in rows], float).reshape(-1, 3),
            np.array([r[3] for r in rows], np.int64),
            np.array([r[4] for r in rows], np.int64),
            np.array([r[5].rotation for r in rows], float).reshape(-1, 3, 3),
            np.array([r[5].translation for r in rows], float).reshape(-1, 3),
            np.array([last[f.parentJoint] for f in frames], np.int64),
            np.array([f.placement.rotation for f in frames], float).reshape(-1, 3, 3),
            np.array([f.placement.translation for f in frames], float).reshape(-1, 3),
        )

    def placements(self, qs: Array) -> tuple[Array, Array]:
        """Rotations (B, F, 3, 3) and translations (B, F, 3) of the frames at the configurations ``qs`` (B, nq).

        A single configuration (nq,) gives (F, 3, 3) and (F, 3).
        """
        rot, pos, _ = self._run(qs, None)
        return rot, pos

    def jacobians(
        self, qs: Array, reference: Any = pin.LOCAL, out: tuple[Array, Array, Array] | None = None
    ) -> tuple[Array, Array, Array]:
        """:meth:`placements` and the frames' Jacobians (B, F, 6, nv) in ``reference`` (as ``pin.getFrameJacobian``).

        ``reference``: ``pin.LOCAL``, ``pin.LOCAL_WORLD_ALIGNED`` or ``pin.WORLD``. ``out``: arrays of those
        shapes (C-ordered floats) to fill and return instead of new ones (a loop that calls it again and again
        spares the allocation, which costs more than the kinematics for large stacks).
        """
        if reference not in REFERENCES:
            raise ConfigurationError(f"unknown Jacobian reference {reference!r}; valid: {list(REFERENCES)}")
        rot, pos, jac = self._run(qs, reference, out)
        assert jac is not None
        return rot, pos, jac

    def world_jacobians(self, qs: Array) -> tuple[Array, Array, Array]:
        """World joint Jacobians (B, 6, nv) and the frames' rotations and translations at (B, nq) configurations.

        The Jacobian is Pinocchio's ``data.J`` after ``computeJointJacobians``: every joint's twist at the world
        origin, in world axes.
        """
        q = np.ascontiguousarray(qs, dtype=float).reshape(-1, self.model.nq)
        b, f, nv = len(q), len(self.frames), self.model.nv
        full, rot, pos = np.empty((b, 6, nv)), np.empty((b, f, 3, 3)), np.empty((b, f, 3))
        if self.engine == "compiled":
            from pinmob.model.kinematics_kernel import frames_kernel

            frames_kernel(q, *self.tables, 0, False, rot, pos, np.empty((0, 0, 6, nv)), full)
            return full, rot, pos
        model, data = self.model, self._data
        for k in range(b):
            full[k] = pin.computeJointJacobians(model, data, q[k])
            for i, fid in enumerate(self.frames):
                placement = pin.updateFramePlacement(model, data, fid)
                rot[k, i], pos[k, i] = placement.rotation, placement.translation
        return full, rot, pos

    def _run(
        self, qs: Array, reference: Any, out: tuple[Array, Array, Array] | None = None
    ) -> tuple[Array, Array, Array | None]:
        q = np.ascontiguousarray(qs, dtype=float)
        single = q.ndim == 1
        q = q.reshape(-1, self.model.nq)
        b, f, nv = len(q), len(self.frames), self.model.nv
        jac: Array | None
        if out is not None:
            rot, pos, jac = out
            shapes = [a.shape for a in out] == [(b, f, 3, 3), (b, f, 3), (b, f, 6, nv)]
            if single or not shapes or not all(a.dtype == np.float64 and a.flags.c_contiguous for a in out):
                raise ConfigurationError(
                    f"out must be C-ordered float arrays of shapes {(b, f, 3, 3)}, {(b, f, 3)}, {(b, f, 6, nv)}"
                )
        else:
            rot, pos = np.empty((b, f, 3, 3)), np.empty((b, f, 3))
            jac = np.empty((b, f, 6, nv)) if reference is not None else None
        if self.engine == "compiled":
            from pinmob.model.kinematics_kernel import frames_kernel

            out_j = jac if jac is not None else np.empty((0, 0, 6, nv))
            code = REFERENCES[reference] if reference is not None else 0
            frames_kernel(q, *self.tables, code, jac is not None, rot, pos, out_j, np.empty((0, 6, nv)))
        else:
            model, data = self.model, self._data
            for k in range(b):
                if jac is None:
                    pin.framesForwardKinematics(model, data, q[k])
                else:
                    pin.computeJointJacobians(model, data, q[k])
                    pin.updateFramePlacements(model, data)
                for i, fid in enumerate(self.frames):
                    rot[k, i], pos[k, i] = data.oMf[fid].rotation, data.oMf[fid].translation
                    if jac is not None:
                        jac[k, i] = np.reshape(pin.getFrameJacobian(model, data, fid, reference), (6, nv))
        if single:
            return rot[0], pos[0], (jac[0] if jac is not None else None)
        return rot, pos, jac


def frame_kinematics(model: pin.Model, frames: Sequence[int], engine: str | None = None) -> FrameKinematics:
    """The kinematics of ``frames``: compiled when numba is installed and every joint is supported, else Pinocchio.

    ``engine``: ``compiled`` (a :class:`ConfigurationError` when numba is absent or a joint unsupported),
    ``pinocchio``, or None: the environment variable ``PINMOB_KINEMATICS`` (``compiled`` or ``pinocchio``) when
    set, else the compiled one when it can be.
    """
    if engine is None:
        engine = os.environ.get(ENGINE_VARIABLE, "").strip() or None
        if engine is not None and engine not in ENGINES:
            raise ConfigurationError(
                f"{ENGINE_VARIABLE}={engine!r} is not a kinematics engine; valid: {', '.join(ENGINES)}"
            )
    elif engine not in ENGINES:
        raise ConfigurationError(f"unknown kinematics engine {engine!r}; valid: {', '.join(ENGINES)}")
    if engine == "pinocchio":
        return FrameKinematics(model, frames, "pinocchio", "asked for")
    reason = "" if numba_available() else "numba is not installed (pip install 'pinmob[fast]')"
    if not reason:
        try:
            for j in range(1, model.njoints):
                _elementary(model.joints[j], model.jointPlacements[j])
        except UnsupportedJoint as err:
            reason = f"joint {model.names[j]!r} is a {err} (not compiled)"
    if reason and engine == "compiled":
        raise ConfigurationError(f"the compiled kinematics cannot run: {reason}")
    return FrameKinematics(model, frames, "pinocchio" if reason else "compiled", reason)


def mechanism_kinematics(mech: Mechanism, frames: Sequence[int]) -> FrameKinematics:
    """:func:`frame_kinematics` of ``mech``'s ``frames`` with the engine of the environment, made once per mechanism.

    Cached per frames and ``PINMOB_KINEMATICS`` (not pickled with the mechanism): the batched predictor's problems
    and the compiled single-sample solve of the same frames share one (a 6-UPS's tables take 0.35 ms to build).
    """
    engine = os.environ.get(ENGINE_VARIABLE)
    key = ("frame kinematics", tuple(int(f) for f in frames), engine)
    return mech.memo(key, lambda: frame_kinematics(mech.model, frames), transient=True)
