"""The whole closed chain: every joint, every loop, not only the platform.

:mod:`~pinmob.analysis.chain.closed_chain` (:class:`ClosedChain`, the loop-closure Jacobian and its null
space, with :mod:`~pinmob.analysis.chain.joint_centres`), :mod:`~pinmob.analysis.chain.mechanism_mobility`
(:class:`MechanismMobility`, :class:`FrameMobility`), :mod:`~pinmob.analysis.chain.redundancy` (which closure
rows are implied by others), :mod:`~pinmob.analysis.chain.actuation` and
:mod:`~pinmob.analysis.chain.locking` (what the actuators hold), :mod:`~pinmob.analysis.chain.joint_rates`
(the joint rates of a motion).
"""

from pinmob.analysis.chain.closed_chain import ClosedChain
from pinmob.analysis.chain.mechanism_mobility import FrameMobility, MechanismMobility

__all__ = ["ClosedChain", "FrameMobility", "MechanismMobility"]
