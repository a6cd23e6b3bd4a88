"""The single-sample solver's iterations at a platform pose in one compiled call (a scan's single-sample path).

- :mod:`~pinmob.assembly.compiled_solve.compiled_pose_solve`: :func:`compiled_pose_solver`, where the mechanism
  allows it (numba installed, no closure besides the limb tips), and :class:`CompiledPoseSolve`;
- :mod:`~pinmob.assembly.compiled_solve.pose_solve_kernel`: the compiled loop (importing it imports numba: loaded
  by :class:`CompiledPoseSolve` only), on :mod:`~pinmob.assembly.compiled_solve.se3_log` (``log6`` and ``Jlog6``)
  and :mod:`~pinmob.assembly.compiled_solve.block_svd` (the Jacobian's SVD a block a limb).
"""

from pinmob.assembly.compiled_solve.compiled_pose_solve import CompiledPoseSolve, compiled_pose_solver

__all__ = ["CompiledPoseSolve", "compiled_pose_solver"]
