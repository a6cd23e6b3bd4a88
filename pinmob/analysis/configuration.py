"""The one state object: a closed configuration of a mechanism and what is computed from it.

A :class:`Configuration` validates its arguments once, closes a named
configuration (or checks a given vector) once, computes the kinematics once
(``computeJointJacobians`` and the frame placements, in a ``pin.Data`` it owns)
and caches what several analyses share (limb twists, the closure Jacobian and
its null space, ...) through :meth:`Configuration.memo`. Every analysis takes a
``Configuration``; its ``q`` is read-only.

The ``pin.Data`` objects come from a small pool per model
(:mod:`pinmob.model.data_pool`): a ``Configuration`` takes a spare one and gives
it back when it is collected, or earlier by :meth:`Configuration.park` (a
configuration kept with many others, as the generic states are: a 6-UPS's
``pin.Data`` weighs about 3 MB and takes about 1 ms to make), and takes one again
when its kinematics are next read.
"""

from __future__ import annotations

from collections.abc import Callable, Generator, Iterable
from typing import Any, TypeVar

import numpy as np
import pinocchio as pin
from numpy.typing import ArrayLike

from pinmob.assembly import (
    CLOSURE_TOL,
    Residuals,
    check_closed,
    check_closure_tol,
    compute_kinematics,
    frame_jacobian,
    named_vector,
    worst_residual,
)
from pinmob.exceptions import ConfigurationError
from pinmob.model import Mechanism, acquire, release_with
from pinmob.screw import Array

T = TypeVar("T")


#: The source of a :meth:`Configuration.unchecked` (its loops not checked).
UNCHECKED = "unchecked"

#: The rank tolerance is at least this times the configuration's closure residual (:meth:`Configuration.rank_rtol`).
RESIDUAL_FACTOR = 10.0


class Configuration:
    """A closed configuration ``q`` of ``mechanism``, validated, closed and with its kinematics computed.

    Made in one of three ways, which differ only in what they check:

    - ``Configuration(mechanism, q, closure_tol=...)``: the public door; checks ``closure_tol``, resolves and
      closes a configuration name (or checks a vector) and checks that the loops close.
    - :meth:`from_checked`: the same for a ``closure_tol`` a door of the library has checked already
      (:func:`pinmob.analyze` checks each argument once).
    - :meth:`unchecked`: the kinematics at any valid q, the loops not checked (open limbs' generic ranks,
      points between closed configurations); its ``closure_tol`` is ``inf`` and its source ``unchecked``.

    :meth:`with_name` copies one under another name; a pickled one is rebuilt the way it was made.

    Args:
        mechanism: the mechanism.
        q: configuration vector (nq,), or the name of one of ``mechanism.configurations``
            (joint values are checked, a platform pose is assembled).
        closure_tol: closure tolerance: largest residual allowed, position / L and rotation [rad].
        name: name reported with the results (default: the configuration's name when q is one).
        source: how q was obtained, for reports (default: ``given`` or ``named configuration 'x'``).

    Raises:
        ConfigurationError: q has the wrong shape, non-finite values, is not normalised, names no
            configuration, or ``closure_tol`` is out of range.
        ClosureError: q does not close within ``closure_tol`` (the error carries every residual).
    """

    def __init__(
        self,
        mechanism: Mechanism,
        q: ArrayLike | str,
        *,
        closure_tol: float = CLOSURE_TOL,
        name: str | None = None,
        source: str | None = None,
    ) -> None:
        self._close(mechanism, q, check_closure_tol(closure_tol), name, source)

    @classmethod
    def from_checked(
        cls,
        mechanism: Mechanism,
        q: ArrayLike | str,
        closure_tol: float,
        *,
        name: str | None = None,
        source: str | None = None,
    ) -> Configuration:
        """As the constructor, for a ``closure_tol`` its caller has checked already (:func:`check_closure_tol`).

        A door of the library (:func:`pinmob.analyze`) checks each argument once; what it builds trusts the value.
        """
        self = object.__new__(cls)
        self._close(mechanism, q, closure_tol, name, source)
        return self

    @classmethod
    def unchecked(cls, mechanism: Mechanism, q: ArrayLike) -> Configuration:
        """The kinematics at any valid q, the loops not checked (for the generic ranks of open limbs).

        Analyses of the mechanism need a closed configuration; use the constructor for those.
        """
        self = object.__new__(cls)
        self._set(mechanism, mechanism.check_q(q), np.inf, None, UNCHECKED)
        self._residuals = {}
        return self

    def _close(
        self, mechanism: Mechanism, q: ArrayLike | str, tol: float, name: str | None, source: str | None
    ) -> None:
        """The constructor's work once ``tol`` is checked: resolve a name, close, compute the kinematics."""
        if isinstance(q, str):
            q = mechanism.configuration_name(q)
            vec, _ = named_vector(mechanism, q, tol)  # its closure is checked below, with the kinematics
            name = q if name is None else name
            source = source or f"named configuration {q!r}"
        else:
            vec = mechanism.check_q(q)
        self._set(mechanism, vec, tol, name, source or "given")
        what = f"configuration {name!r}" if name else "configuration"
        self._residuals = check_closed(mechanism, vec, tol, what, data=self.data)

    def _set(self, mechanism: Mechanism, vec: Array, tol: float, name: str | None, source: str) -> None:
        """Every constructor's state: q read-only, an empty memo, the kinematics at q in a pooled ``pin.Data``."""
        vec.flags.writeable = False
        self._mechanism, self._q, self._name, self._tol, self._source = mechanism, vec, name, tol, source
        self._memo: dict[Any, Any] = {}
        self._data: pin.Data | None = None
        self._kinematics()

    def _kinematics(self) -> pin.Data:
        """A pooled ``pin.Data`` taken, with the kinematics at q computed in it (at construction, and after park)."""
        model = self._mechanism.model
        data = self._data = acquire(model)
        self._give_back = release_with(self, model, data)
        compute_kinematics(model, data, self._q)
        return data

    def park(self) -> None:
        """Give the ``pin.Data`` back to the pool now; the kinematics are computed again when next read.

        What the configuration cached (:meth:`memo`) stays, and the kinematics computed again are the same
        numbers. For a configuration kept with many others whose analyses are cached, such as the generic states
        (:func:`pinmob.analysis.generic.generic_states`). Park only a configuration that no other thread is
        reading: a ``pin`` object read from :attr:`data` before (an SE3 of :meth:`frame_placement`, a Jacobian
        of ``data.J``) is another configuration's once the pool lends the ``pin.Data`` again.
        """
        owner = self._owner
        if owner._data is not None:
            owner._data = None
            owner._give_back()

    # ------------------------------------------------------------------ state

    @property
    def mechanism(self) -> Mechanism:
        """The mechanism."""
        return self._mechanism

    @property
    def q(self) -> Array:
        """(nq,) the closed configuration (read-only)."""
        return self._q

    @property
    def name(self) -> str | None:
        """Name reported with the results (None for an unnamed configuration)."""
        return self._name

    @property
    def closure_tol(self) -> float:
        """The closure tolerance it was checked with (position / L and rotation [rad])."""
        return self._tol

    @property
    def source(self) -> str:
        """How q was obtained: ``given``, ``named configuration 'x'``, ``projection from neutral``, ..."""
        return self._source

    @property
    def residuals(self) -> Residuals:
        """Residual of every limb tip and closure: name -> (position [m], rotation [rad])."""
        return dict(self._residuals)

    @property
    def residual(self) -> float:
        """The largest residual, ``max(|p| / L, |r|)`` (dimensionless)."""
        return worst_residual(self._residuals, self._mechanism.length_scale)

    def rank_rtol(self, rtol: float) -> float:
        """The rank tolerance at this configuration: ``max(rtol, RESIDUAL_FACTOR * residual)``.

        Loops that close only to a residual r (CAD geometry closes to about a micron) leave singular
        values of order r in the closure and limb matrices that are not structural: they are not counted.
        """
        return max(rtol, RESIDUAL_FACTOR * self.residual)

    @property
    def data(self) -> pin.Data:
        """Pinocchio data with the kinematics at q (joint Jacobians, frame placements); do not modify."""
        owner = self._owner
        return owner._kinematics() if owner._data is None else owner._data

    @property
    def _owner(self) -> Configuration:
        """The configuration that holds the pooled ``pin.Data``: itself, or a copy's (:meth:`with_name`) original."""
        return self.__dict__.get("_parent", self)

    @property
    def world_jacobian(self) -> Array:
        """(6, nv) every joint screw ``[v; w]`` at the world origin, world axes (``data.J``; (6, 1) when nv = 1)."""
        return self.memo("world_jacobian", lambda: np.array(self.data.J).reshape(6, self._mechanism.model.nv))

    def frame_placement(self, frame: int) -> pin.SE3:
        """World placement of frame index ``frame``."""
        return self.data.oMf[frame]

    @property
    def platform_origin(self) -> Array:
        """(3,) world position of the platform frame [m] (zeros when the mechanism has none)."""
        mech = self._mechanism
        if not mech.has_platform:
            return np.zeros(3)
        return np.array(self.data.oMf[mech.platform_id].translation)

    def frame_jacobian(self, frame: int, reference: pin.ReferenceFrame = pin.LOCAL_WORLD_ALIGNED) -> Array:
        """(6, nv) Jacobian of frame index ``frame`` (cached per frame and reference)."""
        return self.memo(
            ("frame_jacobian", frame, reference),
            lambda: frame_jacobian(self._mechanism.model, self.data, frame, reference),
        )

    def memo(self, key: Any, compute: Callable[[], T]) -> T:
        """The value cached under ``key``, computed once by ``compute()`` (analyses share results this way)."""
        try:
            return self._memo[key]
        except KeyError:
            value = self._memo[key] = compute()
            return value

    # ------------------------------------------------------------------ copies

    def with_name(self, name: str | None) -> Configuration:
        """The same configuration reported under another name (shares the kinematics and caches)."""
        other = object.__new__(Configuration)
        other.__dict__.update(self.__dict__)
        other._name = name
        for own in ("_data", "_give_back"):  # the original owns the pooled Data; the copy reads it through _parent
            other.__dict__.pop(own, None)
        other.__dict__["_parent"] = self.__dict__.get("_parent", self)  # kept alive as long as the copy
        return other

    def __getstate__(self) -> dict[str, Any]:
        """Pickled without the kinematics and caches (recomputed on unpickling, by the constructor it was made with)."""
        return {
            "mechanism": self._mechanism,
            "q": np.array(self._q),
            "name": self._name,
            "tol": self._tol,
            "source": self._source,
        }

    def __setstate__(self, state: dict[str, Any]) -> None:
        mechanism, q, tol = state["mechanism"], state["q"], state["tol"]
        if np.isinf(tol):  # made by unchecked(): no closure tolerance
            self._set(mechanism, mechanism.check_q(q), tol, state["name"], state["source"])
            self._residuals = {}
        else:  # its closure_tol was checked when it was made
            self._close(mechanism, q, tol, state["name"], state["source"])

    def __repr__(self) -> str:
        where = f" {self._name!r}" if self._name else ""
        return f"Configuration({self._mechanism.name!r}{where}, residual {self.residual:.1e}, {self._source})"


def parked(states: Iterable[Configuration]) -> Generator[Configuration, None, None]:
    """Each configuration of ``states``, parked (:meth:`Configuration.park`) once the loop moves on from it or stops."""
    for conf in states:
        try:
            yield conf
        finally:
            conf.park()


def as_configuration(
    mech: Mechanism | Configuration,
    q: ArrayLike | str | Configuration | None = None,
    *,
    configuration: str | None = None,
    closure_tol: float = CLOSURE_TOL,
) -> Configuration:
    """A :class:`Configuration` from what an analysis was given.

    Args:
        mech: the mechanism, or a :class:`Configuration` (then ``q`` must be None).
        q: a configuration vector, a configuration name, or a :class:`Configuration`.
        configuration: name reported with the results (overrides the configuration's own).
        closure_tol: closure tolerance, for a vector or a name (checked there; a Configuration has its own).

    Raises:
        ConfigurationError: no configuration given, or a Configuration of another mechanism.
    """
    if isinstance(mech, Configuration):
        if q is not None:
            raise ConfigurationError("give either a Configuration or a mechanism and q, not both")
        conf = mech
    elif isinstance(q, Configuration):
        if q.mechanism is not mech:
            raise ConfigurationError(f"the Configuration belongs to {q.mechanism.name!r}, not to {mech.name!r}")
        conf = q
    elif q is None:
        raise ConfigurationError(
            f"no configuration given for {mech.name!r}: give q (a vector of {mech.model.nq} numbers or a "
            "configuration name) or a Configuration"
        )
    else:
        conf = Configuration(mech, q, closure_tol=closure_tol)
    if configuration is not None and configuration != conf.name:
        conf = conf.with_name(configuration)
    return conf
