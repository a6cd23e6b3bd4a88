"""Pinocchio's ``rpy.matrixToRpy`` of a stack of rotations, compiled (numba, the optional ``fast`` extra).

Pinocchio takes Eigen's ``eulerAngles(2, 1, 0)`` (Graphics Gems IV: the yaw from ``atan2(R10, R00)`` moved into
[0, pi], the pitch from the first column's last entry and the norm of the last row's other two, the roll from the
yaw's sine and cosine) reversed, then moves the pitch into [-pi/2, pi/2]. :func:`matrix_rpy` does the same
operations in the same order on each rotation of a stack: the same angles to the last bit
(``tests/test_scan_batch.py`` compares them on rotations near the gimbal lock and at multiples of pi/2 too).
Importing this module imports numba.
"""

from __future__ import annotations

import numpy as np

from pinmob.jit_cache import njit
from pinmob.screw import Array


@njit
def matrix_rpy(rotations: Array, out: Array) -> None:
    """(roll, pitch, yaw) of each rotation ``rotations[b, :3, :3]`` (a (B, 3, 3) or (B, 4, 4) stack) into ``out`` (B, 3)."""
    pi = np.pi
    for b in range(rotations.shape[0]):
        r = rotations[b]
        yaw = np.arctan2(r[1, 0], r[0, 0])
        c2 = np.sqrt(r[2, 2] * r[2, 2] + r[2, 1] * r[2, 1])
        if yaw < 0.0:  # Eigen keeps the first angle in [0, pi]
            yaw += pi
            pitch = np.arctan2(-r[2, 0], -c2)
        else:
            pitch = np.arctan2(-r[2, 0], c2)
        s1, c1 = np.sin(yaw), np.cos(yaw)
        roll = np.arctan2(s1 * r[0, 2] - c1 * r[1, 2], c1 * r[1, 1] - s1 * r[0, 1])
        if pitch < -pi / 2:
            pitch += 2 * pi
        if pitch > pi / 2:  # Pinocchio's range: the pitch in [-pi/2, pi/2], the other two turned by pi
            pitch = pi - pitch
            roll = roll + pi if roll < 0.0 else roll - pi
            yaw -= pi
        out[b, 0], out[b, 1], out[b, 2] = roll, pitch, yaw
