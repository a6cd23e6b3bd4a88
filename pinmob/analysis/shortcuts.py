"""One part of the answer from a mechanism and a configuration: shortcuts over :class:`Configuration`.

Each builds the :class:`~pinmob.analysis.configuration.Configuration` (with the
same argument checks as :func:`pinmob.analyze`) and returns one part of the
report, with the same rank tolerance (raised for a configuration that closes only to CAD accuracy:
:meth:`~pinmob.analysis.configuration.Configuration.rank_rtol`). :func:`pinmob.analyze` gives them all at once, sharing one
configuration; these are for code that needs one part, with its own errors
(e.g. :func:`analyze_singularity` refuses a mechanism without limbs, where the
report says "not analysed"). :func:`pinmob.frame_mobility`, :func:`pinmob.actuator_sets` and
:func:`pinmob.closure_jacobian_twists` take the same arguments and live beside what they compute, in
:mod:`pinmob.analysis.chain`.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

from numpy.typing import ArrayLike

from pinmob.analysis.chain.mechanism_mobility import MechanismMobility, mechanism_mobility
from pinmob.analysis.configuration import Configuration, as_configuration
from pinmob.analysis.mobility import Mobility
from pinmob.analysis.singularity.classification import singularity
from pinmob.analysis.singularity.result import Singularity
from pinmob.assembly import CLOSURE_TOL
from pinmob.model import Mechanism
from pinmob.screw import RTOL, check_rtol

Where = Mechanism | Configuration
At = ArrayLike | str | Configuration | None


def analyze_mechanism(
    mech: Where,
    q: At = None,
    *,
    actuated: Sequence[str] | None = None,
    frames: Sequence[str] | None = None,
    outputs: Sequence[str] | None = None,
    configuration: str | None = None,
    rtol: float = RTOL,
    closure_tol: float = CLOSURE_TOL,
) -> MechanismMobility:
    """The whole closed chain's mobility (``pinmob.analyze(...).mechanism_mobility``).

    See :func:`pinmob.analysis.chain.mechanism_mobility.mechanism_mobility`.
    """
    conf = as_configuration(mech, q, configuration=configuration, closure_tol=closure_tol)
    return mechanism_mobility(conf, conf.rank_rtol(check_rtol(rtol)), actuated=actuated, frames=frames, outputs=outputs)


def analyze_singularity(
    mech: Where,
    q: At = None,
    *,
    configuration: str | None = None,
    generic_rank: int | None = None,
    rtol: float = RTOL,
    closure_tol: float = CLOSURE_TOL,
) -> Singularity:
    """Singularity classes and distances (``pinmob.analyze(...).singularity``).

    Raises:
        ConfigurationError: the mechanism has no limbs or no platform frame, or a closure couples limbs.
    """
    conf = as_configuration(mech, q, configuration=configuration, closure_tol=closure_tol)
    return singularity(conf, conf.rank_rtol(check_rtol(rtol)), generic_rank)


def paper_view(
    mech: Where,
    q: At = None,
    approach: ArrayLike | Mapping[str, float] | None = None,
    *,
    configuration: str | None = None,
    rtol: float = RTOL,
    closure_tol: float = CLOSURE_TOL,
) -> Mobility:
    """The seed paper's view: each limb's generic wrenches carried to the configuration (``analyze(..., paper=True).paper``).

    See :func:`pinmob.analysis.paper.paper_mobility`.
    """
    conf = as_configuration(mech, q, configuration=configuration, closure_tol=closure_tol)
    from pinmob.analysis.paper import paper_mobility  # imported when first asked for

    return paper_mobility(conf, conf.rank_rtol(check_rtol(rtol)), approach)  # type: ignore[arg-type]
