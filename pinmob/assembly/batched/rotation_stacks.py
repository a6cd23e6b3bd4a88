"""Stacks of rotations for the numpy path of :mod:`pinmob.assembly.batched.batch_solver`: (B, 3, 3) at once.

Pinocchio's rpy matrices and world angular velocity per rpy rate of (B, 3) angles, the angles of (B, 3, 3) rotations
(``pin.rpy.matrixToRpy`` of each), their rotation vectors (``pin.log3`` of each) and the cross-product matrices of
(B, 3) vectors.
"""

from __future__ import annotations

import functools
from collections.abc import Callable

import numpy as np
import pinocchio as pin

from pinmob.model import numba_available
from pinmob.screw import Array


def rpy_matrices(rpy: Array) -> Array:
    """(B, 3, 3) ``Rz(yaw) Ry(pitch) Rx(roll)`` (Pinocchio's rpy) of (B, 3) angles."""
    (cr, cp, cy), (sr, sp, sy) = np.cos(rpy).T, np.sin(rpy).T
    out = np.empty((len(rpy), 3, 3))
    out[:, 0, 0], out[:, 0, 1], out[:, 0, 2] = cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr
    out[:, 1, 0], out[:, 1, 1], out[:, 1, 2] = sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr
    out[:, 2, 0], out[:, 2, 1], out[:, 2, 2] = -sp, cp * sr, cp * cr
    return out


def rpy_rates(rpy: Array) -> Array:
    """(B, 3, 3) world angular velocity per rpy rate (Pinocchio's ``computeRpyJacobian(rpy, WORLD)``)."""
    _, cp, cy = np.cos(rpy).T
    _, sp, sy = np.sin(rpy).T
    out = np.zeros((len(rpy), 3, 3))
    out[:, 0, 0], out[:, 0, 1] = cy * cp, -sy
    out[:, 1, 0], out[:, 1, 1] = sy * cp, cy
    out[:, 2, 0], out[:, 2, 2] = -sp, 1.0
    return out


def matrices_rpy(rotations: Array) -> Array:
    """(B, 3) ``pin.rpy.matrixToRpy`` of each rotation ``rotations[b, :3, :3]`` ((B, 3, 3), or (B, 4, 4) placements).

    Compiled where numba is installed (:func:`pinmob.assembly.batched.rpy_kernel.matrix_rpy`: the same operations, the same
    angles to the last bit), else Pinocchio's call on each.
    """
    out = np.empty((len(rotations), 3))
    kernel = _rpy_kernel()
    if kernel is not None:
        kernel(np.ascontiguousarray(rotations, float), out)
    else:
        for b, r in enumerate(rotations):
            out[b] = pin.rpy.matrixToRpy(r[:3, :3])
    return out


@functools.cache
def _rpy_kernel() -> Callable[[Array, Array], None] | None:
    """:func:`pinmob.assembly.batched.rpy_kernel.matrix_rpy` where numba is installed (looked for once), else None."""
    if not numba_available():
        return None
    from pinmob.assembly.batched.rpy_kernel import matrix_rpy

    return matrix_rpy


def log3_stack(r: Array) -> Array:
    """(B, 3) rotation vectors of (B, 3, 3) rotations: ``pin.log3`` of each, right up to pi.

    A closed form from the antisymmetric part alone lost the axis near pi (1e6 instead of 2.5 at pi - 1e-10).
    """
    return np.array([pin.log3(m) for m in r]).reshape(len(r), 3)


def skew_stack(v: Array) -> Array:
    """(B, 3, 3) cross-product matrices of (B, 3) vectors."""
    out = np.zeros((len(v), 3, 3))
    out[:, 0, 1], out[:, 0, 2], out[:, 1, 2] = -v[:, 2], v[:, 1], -v[:, 0]
    out[:, 1, 0], out[:, 2, 0], out[:, 2, 1] = v[:, 2], -v[:, 1], v[:, 0]
    return out
