"""Layout helpers for sketching mechanisms: directions, points on circles, rotations.

All angles in radians, lengths in metres (or any one unit used throughout).
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np
from numpy.typing import ArrayLike

from pinmob.exceptions import ConfigurationError

#: tolerance of :func:`check_rotation` on ``|R^T R - I|`` and ``|det R - 1|``
ROTATION_TOL = 1e-9


def radial(theta: float) -> tuple[np.ndarray, np.ndarray]:
    """Radial unit vector ``e = (cos theta, sin theta, 0)`` and tangent ``t = z x e``.

    Args:
        theta: angle about the world z axis [rad].
    """
    e = np.array([np.cos(theta), np.sin(theta), 0.0])
    return e, np.array([-e[1], e[0], 0.0])


def cross(a: ArrayLike, b: ArrayLike) -> np.ndarray:
    """Cross product ``a x b`` of two 3-vectors as floats, shape (3,).

    The numbers of ``np.cross`` (the same products and differences, in double precision) at a fraction of its
    cost on a single pair, which is what the builder and the catalog take.
    """
    a0, a1, a2 = (float(x) for x in np.ravel(a))
    b0, b1, b2 = (float(x) for x in np.ravel(b))
    return np.array([a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0])


def polar(radius: float, theta: float, z: float = 0.0) -> np.ndarray:
    """Point ``radius * e(theta) + z * z_hat`` [m], shape (3,)."""
    return radius * radial(theta)[0] + np.array([0.0, 0.0, z])


def symmetric_angles(n: int, offset: float = 0.0) -> list[float]:
    """``n`` angles ``offset + 2 pi k / n`` [rad], k = 0..n-1 (limbs spread evenly about z)."""
    return [offset + 2.0 * np.pi * k / n for k in range(n)]


def azimuth(v: ArrayLike) -> float:
    """Angle [rad] of the xy projection of ``v`` about z: ``atan2(v_y, v_x)``."""
    a = np.asarray(v, float)
    return float(np.arctan2(a[1], a[0]))


def rotation(axis: Sequence[float], angle: float) -> np.ndarray:
    """Rotation matrix (3, 3) of ``angle`` [rad] about ``axis`` (Rodrigues' formula).

    ``R = I + sin(a) [u]x + (1 - cos(a)) [u]x^2`` with ``u = axis / |axis|``.
    """
    u = np.asarray(axis, float)
    u = u / np.linalg.norm(u)
    k = np.array([[0.0, -u[2], u[1]], [u[2], 0.0, -u[0]], [-u[1], u[0], 0.0]])
    return np.eye(3) + np.sin(angle) * k + (1.0 - np.cos(angle)) * k @ k


def rpy(rot: ArrayLike) -> tuple[float, float, float]:
    """URDF roll, pitch, yaw [rad] of a rotation matrix: ``R = Rz(yaw) Ry(pitch) Rx(roll)``.

    Roll and yaw are in (-pi, pi], pitch in [-pi/2, pi/2]. Entries of R within
    1e-12 of 0 are taken as 0 first, so that a half turn whose zero entries
    come out as +1e-17 on one machine and -1e-17 on another gives roll pi on
    both (not -pi on one). At gimbal lock (``|cos pitch| <= 1e-9``) the yaw is
    set to 0 and the roll takes the whole rotation about the vertical.
    """
    r = np.asarray(rot, float)
    r = np.where(np.abs(r) <= 1e-12, 0.0, r)  # also turns -0.0 into 0.0
    pitch = float(np.arcsin(-np.clip(r[2, 0], -1, 1)))
    if abs(np.cos(pitch)) > 1e-9:
        roll = float(np.arctan2(r[2, 1], r[2, 2]))
        yaw = float(np.arctan2(r[1, 0], r[0, 0]))
    else:
        roll, yaw = float(np.arctan2(-r[1, 2], r[1, 1])), 0.0
    half_turn = lambda x: np.pi if x == -np.pi else x  # noqa: E731  (atan2's -pi is the same angle as pi)
    return half_turn(roll), pitch, half_turn(yaw)


def check_rotation(what: str, rot: ArrayLike) -> np.ndarray:
    """``rot`` as a (3, 3) float array if it is a proper rotation, else a :class:`ConfigurationError`.

    A rotation has ``R^T R = I`` and ``det R = +1`` (within :data:`ROTATION_TOL`).
    """
    try:
        r = np.asarray(rot, float)
    except (TypeError, ValueError):
        raise ConfigurationError(f"{what}: rotation must be a 3x3 matrix of numbers, got {rot!r}") from None
    if r.shape != (3, 3) or not np.isfinite(r).all():
        raise ConfigurationError(f"{what}: rotation must be a finite 3x3 matrix, got shape {r.shape}")
    off = float(np.abs(r.T @ r - np.eye(3)).max())
    det = float(np.linalg.det(r))
    if off > ROTATION_TOL or abs(det - 1.0) > ROTATION_TOL:
        raise ConfigurationError(
            f"{what}: not a rotation matrix (|R^T R - I| = {off:.2e}, det R = {det:.6g}; a rotation has "
            "orthonormal columns and det +1)"
        )
    return r


def unit(what: str, vector: ArrayLike) -> np.ndarray:
    """``vector / |vector|`` for a finite non-zero 3-vector, else a :class:`ConfigurationError`."""
    try:
        a = np.asarray(vector, float)
    except (TypeError, ValueError):
        raise ConfigurationError(f"{what} must be a non-zero 3-vector, got {vector!r}") from None
    if a.shape != (3,) or not np.isfinite(a).all():
        raise ConfigurationError(f"{what} must be a non-zero 3-vector, got {vector!r}")
    length = math.sqrt(a.dot(a))  # np.linalg.norm's sum and root, without its dispatch
    if length < 1e-12:
        raise ConfigurationError(f"{what} must be a non-zero 3-vector, got {vector!r}")
    return a / length


def point(what: str, value: ArrayLike) -> tuple[float, float, float]:
    """A finite 3-vector as a tuple of floats [m], else a :class:`ConfigurationError`."""
    try:
        p = np.asarray(value, float)
    except (TypeError, ValueError):
        raise ConfigurationError(f"{what} must be a 3-vector of numbers, got {value!r}") from None
    if p.shape != (3,) or not np.isfinite(p).all():
        raise ConfigurationError(f"{what} must be a finite 3-vector, got {value!r}")
    return float(p[0]), float(p[1]), float(p[2])
