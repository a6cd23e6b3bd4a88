"""Single-loop and planar linkages: the five-bar, Bennett's linkage and Sarrus' linkage."""

from __future__ import annotations

import numpy as np

from ..builder import MechanismBuilder, azimuth, rotation
from .registry import Definition, register
from .sources import BENNETT, GOSSELIN_ANGELES, HAND, VIRTUAL_CHAIN, expect


def _elbow(a: np.ndarray, e: np.ndarray, la: float, lb: float, side: float) -> np.ndarray:
    """Planar elbow point at distance la from a and lb from e, on the ``side`` (+1 left, -1 right) of a->e."""
    d = float(np.linalg.norm(e - a))
    x = (la**2 - lb**2 + d**2) / (2 * d)
    u = (e - a) / d
    return a + x * u + side * np.sqrt(max(0.0, la**2 - x**2)) * np.array([-u[1], u[0], 0.0])


@register("five_bar")
def _five_bar() -> Definition:
    half, arm, rod = 0.1, 0.2, 0.25
    a1, b1, end = np.array([-half, 0.0, 0.0]), np.array([half, 0.0, 0.0]), np.array([0.0, 0.3, 0.0])
    b = MechanismBuilder(
        "five-bar",
        f"Planar five-bar (2-RRR), plane z = 0, axes along z: base joints A1, B1 at (-+{half}, 0, 0) (actuated), "
        f"proximal links {arm} m, distal links {rod} m, joined at the end point E = (0, 0.3, 0) at the reference. "
        "The end point is a point, not a body: each distal link through it also turns, so no rigid frame of the "
        "five-bar moves in pure translation. To report the end point itself, the model carries it on a virtual "
        "P-P chain (limb V: prismatic along x, then along y; not part of the machine, unactuated): its carriage "
        "holds E and cannot turn. Limbs A and B are R-R-R, their third revolute at E pinning the distal link to the "
        "carriage (the five-bar's end-point joint). The virtual chain adds two links and two joints and removes no "
        "motion: Grubler-Kutzbach 3 (7 - 1) - 2 x 8 = 2, as for the five-bar alone, 3 (5 - 1) - 2 x 5 = 2. The "
        "platform (the carriage, i.e. the end point) moves in 2T.",
    )
    z, xy = [0.0, 0.0, 1.0], ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0))
    elbows = {"A": _elbow(a1, end, arm, rod, +1.0), "B": _elbow(b1, end, arm, rod, -1.0)}
    for name, base in (("A", a1), ("B", b1)):
        limb = b.limb(name)
        limb.revolute("r1", at=base, axis=z, actuated=True)
        limb.revolute("r2", at=elbows[name], axis=z)
        limb.revolute("r3", at=end, axis=z)
        limb.tip(at=end)
    virtual = b.limb("V")
    virtual.prismatic("x", at=end, axis=xy[0])
    virtual.prismatic("y", at=end, axis=xy[1])
    virtual.tip(at=end)

    def joints(e2: np.ndarray) -> dict[str, float]:
        """Joint values (relative to the reference) putting the end point at e2, by planar trigonometry.

        Each R-R-R limb turns its proximal link by phi1 and its distal link by phi2 (absolute angles);
        the carriage does not turn, so r1 = phi1, r2 = phi2 - phi1, r3 = -phi2.
        """
        out = {"V_x": float(e2[0] - end[0]), "V_y": float(e2[1] - end[1])}
        for name, base, side in (("A", a1, 1.0), ("B", b1, -1.0)):
            elbow = _elbow(base, e2, arm, rod, side)
            phi1 = azimuth(elbow - base) - azimuth(elbows[name] - base)
            phi2 = azimuth(e2 - elbow) - azimuth(end - elbows[name])
            out |= {f"{name}_r1": phi1, f"{name}_r2": phi2 - phi1, f"{name}_r3": -phi2}
        return {k: float(np.angle(np.exp(1j * v))) if k[0] != "V" else v for k, v in out.items()}

    phi = np.deg2rad(110.0)
    stretched = b1 + (arm + rod) * np.array([np.cos(phi), np.sin(phi), 0.0])
    gk = "Grubler-Kutzbach 3 (7 - 1) - 2 x 8 = 2 (five-bar alone: 3 (5 - 1) - 2 x 5 = 2)"
    confs = {
        "generic": {"joints": {}, "expected": expect(2, "2T", f"{gk}; the end point's 2T {HAND}; {VIRTUAL_CHAIN}")},
        "limb-B-stretched": {
            "joints": joints(stretched),
            "expected": expect(1, "1T", f"{HAND}; serial (type I) singularity of {GOSSELIN_ANGELES}"),
        },
    }
    return b, confs, None


def dh(theta: float, a: float, alpha: float) -> np.ndarray:
    """Denavit-Hartenberg transform Rz(theta) Tx(a) Rx(alpha), (4, 4)."""
    out = np.eye(4)
    out[:3, :3] = rotation([0, 0, 1], theta) @ rotation([1, 0, 0], alpha)
    out[:3, 3] = rotation([0, 0, 1], theta) @ [a, 0.0, 0.0]
    return out


def bennett_theta2(theta1: float, alpha1: float, alpha2: float) -> float:
    """Bennett's closure: tan(theta1/2) tan(theta2/2) = sin((alpha2 + alpha1)/2) / sin((alpha2 - alpha1)/2)."""
    return float(2 * np.arctan(np.sin((alpha2 + alpha1) / 2) / np.sin((alpha2 - alpha1) / 2) / np.tan(theta1 / 2)))


def bennett_frames(theta1: float, a1: float, alpha1: float, alpha2: float) -> list[np.ndarray]:
    """World frames (4, 4) of the four joints (z = joint axis) of a Bennett loop, frame 1 = identity.

    Frame i+1 = frame i Rz(theta_i) Tx(a_i) Rx(alpha_i) with (theta_i, a_i, alpha_i) =
    (theta1, a1, alpha1), (theta2, a2, alpha2), (-theta1, a1, alpha1), (-theta2, a2, alpha2), the last one
    closing the loop back to frame 1 (checked in the tests).
    """
    a2 = a1 * np.sin(alpha2) / np.sin(alpha1)
    theta2 = bennett_theta2(theta1, alpha1, alpha2)
    frames = [np.eye(4)]
    for theta, a, alpha in ((theta1, a1, alpha1), (theta2, a2, alpha2), (-theta1, a1, alpha1)):
        frames.append(frames[-1] @ dh(theta, a, alpha))
    return frames


@register("bennett")
def _bennett() -> Definition:
    a1, alpha1, alpha2, theta1 = 0.2, np.deg2rad(40.0), np.deg2rad(70.0), np.deg2rad(100.0)
    a2 = a1 * np.sin(alpha2) / np.sin(alpha1)
    frames = bennett_frames(theta1, a1, alpha1, alpha2)
    b = MechanismBuilder(
        "Bennett",
        f"Bennett's overconstrained spatial 4R linkage: opposite links equal, lengths a1 = {a1} m, a2 = {a2:.6g} m, "
        f"twists alpha1 = 40 deg, alpha2 = 70 deg, so that a1 / sin(alpha1) = a2 / sin(alpha2). The ground link is "
        "joints 4-1, the coupler (platform) joints 2-3; limb X is joint 1 then joint 2, limb Y joint 4 then joint 3. "
        "Reference: theta1 = 100 deg and theta2 from Bennett's closure equation "
        "tan(theta1/2) tan(theta2/2) = sin((alpha2 + alpha1)/2) / sin((alpha2 - alpha1)/2). Grubler-Kutzbach gives "
        "6 (4 - 4 - 1) + 4 = -2; the linkage moves with 1 DoF.",
    )
    origin = [f[:3, 3] for f in frames]
    axis = [f[:3, 2] for f in frames]
    tip = 0.5 * (origin[1] + origin[2])
    x = b.limb("X")
    x.revolute("j1", at=origin[0], axis=axis[0], actuated=True)
    x.revolute("j2", at=origin[1], axis=axis[1])
    x.tip(at=tip)
    y = b.limb("Y")
    y.revolute("j4", at=origin[3], axis=axis[3])
    y.revolute("j3", at=origin[2], axis=axis[2])
    y.tip(at=tip)
    theta1b = np.deg2rad(140.0)
    d1 = theta1b - theta1
    d2 = bennett_theta2(theta1b, alpha1, alpha2) - bennett_theta2(theta1, alpha1, alpha2)
    source = f"{BENNETT}; Grubler-Kutzbach gives -2"
    confs = {
        "generic": {"joints": {}, "expected": expect(1, "1H", source)},
        "theta1-140deg": {
            "joints": {"X_j1": round(d1, 12), "X_j2": round(d2, 12), "Y_j4": round(d2, 12), "Y_j3": round(d1, 12)},
            "expected": expect(1, "1H", source),
        },
    }
    return b, confs, None


@register("sarrus")
def _sarrus() -> Definition:
    off, bend, h = 0.1, 0.08, 0.2
    b = MechanismBuilder(
        "Sarrus",
        f"Sarrus linkage: two limbs of three parallel revolutes each (6R loop), limb A with axes along x in the plane "
        f"y = -{off}..., limb B with axes along y; hinges at the base (z = 0), the knee ({bend} m outwards, z = {h / 2}) "
        f"and the platform (z = {h}). Grubler-Kutzbach gives 6 (6 - 6 - 1) + 6 = 0; it moves with 1 DoF, a translation "
        "along z.",
    )
    for name, axis, out in (("A", [1.0, 0, 0], np.array([0.0, -1.0, 0])), ("B", [0, 1.0, 0], np.array([1.0, 0, 0]))):
        limb = b.limb(name)
        limb.revolute("r1", at=off * out, axis=axis, actuated=name == "A")
        limb.revolute("r2", at=(off + bend) * out + [0, 0, h / 2], axis=axis)
        limb.revolute("r3", at=off * out + [0, 0, h], axis=axis)
        limb.tip(at=[0.0, 0.0, h])
    phi = float(np.arctan2(bend, h / 2))
    straight = {f"{x}_{j}": round(v, 12) for x in "AB" for j, v in (("r1", -phi), ("r2", 2 * phi), ("r3", -phi))}
    confs = {
        "generic": {"joints": {}, "expected": expect(1, "1T", "P. F. Sarrus, Comptes Rendus 36, 1853; " + HAND)},
        "stretched": {
            "joints": straight,
            "expected": expect(0, "rigid", f"{HAND} (both limbs straight: first-order rigid at the top dead centre)"),
        },
    }
    return b, confs, None
