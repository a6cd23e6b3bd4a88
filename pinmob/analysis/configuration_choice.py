"""The configuration a user asks for: by name (any case), by joint values, or the mechanism's first.

:func:`chosen_configuration` is what ``pinmob analyze`` and ``pinmob show`` (and :func:`pinmob.analyze`) analyse;
:func:`joint_configuration` closes the loops around joint values given by name.
"""

from __future__ import annotations

from collections.abc import Mapping

from pinmob.analysis.configuration import Configuration
from pinmob.assembly import CLOSURE_TOL, check_closure_tol, close_joint_values, named_vector
from pinmob.model import Mechanism


def joint_configuration(
    mech: Mechanism,
    values: Mapping[str, float],
    base: str | None = None,
    *,
    closure_tol: float = CLOSURE_TOL,
    name: str | None = None,
) -> Configuration:
    """A closed configuration with the given joint values; the other joints start from a named configuration.

    The other joints start from ``base`` (a name of ``mech.configurations``; default: the mechanism's first
    named configuration, else Pinocchio's neutral); when the values given do not close the loops as they are,
    the other joints are solved with the given ones held (:func:`~pinmob.assembly.named_assembly.close_joint_values`).

    Args:
        mech: the mechanism.
        values: joint values by joint name [m or rad].
        base: the named configuration the other joints start from.
        closure_tol: closure tolerance (position / L and rotation [rad]).
        name: name reported with the results (default: none).

    Raises:
        FrameError: an unknown joint (the message lists them).
        UnknownConfigurationError: ``base`` names no configuration of ``mech``.
        ArgumentError: ``closure_tol`` out of range.
        ClosureError: the loops cannot be closed with these values.
    """
    tol = check_closure_tol(closure_tol)
    if base is None and mech.configurations:
        base = next(iter(mech.configurations))
    start = None if base is None else named_vector(mech, mech.configuration_name(base), tol)[0]
    q, solved = close_joint_values(mech, values, start, tol)
    source = "joint values given" + (", the other joints solved to close the loops" if solved else "")
    return Configuration.from_checked(mech, q, tol, name=name, source=source)


def chosen_configuration(
    mech: Mechanism,
    config: str | None = None,
    joints: Mapping[str, float] | None = None,
    *,
    closure_tol: float = CLOSURE_TOL,
    name: str | None = None,
) -> Configuration | None:
    """The configuration asked for by name or by joint values: what ``pinmob analyze`` and ``pinmob show`` analyse.

    With ``joints``: :func:`joint_configuration` (the other joints start from ``config``); else the named
    configuration ``config`` (matched ignoring case where that is unambiguous), else the mechanism's first that
    is not only a start (:attr:`~pinmob.model.named.NamedConfiguration.start`). None when the mechanism names
    none and no joint values are given (a closed one is to be found, from its starts first).

    Raises:
        UnknownConfigurationError: ``config`` names no configuration of ``mech``.
        ArgumentError: ``closure_tol`` out of range.
        ClosureError: the configuration does not close.
    """
    if joints is not None:
        return joint_configuration(mech, joints, config, closure_tol=closure_tol, name=name)
    if config is None:
        config = next((n for n, c in mech.configurations.items() if not c.start), None)
        if config is None:
            return None
    conf = Configuration(mech, config, closure_tol=closure_tol)
    return conf if name is None else conf.with_name(name)
