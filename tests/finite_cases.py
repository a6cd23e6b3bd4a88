"""Classical linkages for the finite-mobility tests, built in memory with ``pinmob.builder.MechanismBuilder``.

Each builder returns the mechanism; its reference configuration (all joints zero) is the special
configuration of the test, closed by construction. The geometry and its known behaviour are
derived by hand in the docstrings (the tests cite them).
"""

from __future__ import annotations

import numpy as np

import pinmob
from pinmob.builder import MechanismBuilder


def four_bar_flat(ground: float = 0.3, crank: float = 0.1) -> pinmob.Mechanism:
    """Planar four-bar with equal opposite links (ground = coupler, crank = rocker) at its flat change point.

    Crank A at (0, 0) -> B = (crank, 0), coupler B -> C = (ground + crank, 0), rocker D = (ground, 0)
    -> C, all along x: the four links collinear. The closure at C is a revolute (axis z). Joint
    coordinates (crank_A, crank_B, rocker_D) = (theta, alpha - theta, psi) with alpha the coupler's
    absolute angle and psi the rocker's. To second order, |C - B|^2 = ground^2 reads
    ``(psi - theta) [crank (psi - theta) - ground (psi + theta)] = 0``: two branches cross,
    the parallelogram ``psi = theta`` (rates (1, -1, 1)) and the antiparallelogram
    ``psi = theta (ground + crank) / (crank - ground)``, on which ``alpha = crank (psi - theta) / ground``
    (rates (1, k, k), ``k = (ground + crank) / (crank - ground)``).
    """
    b = MechanismBuilder("four-bar-flat", "planar four-bar with equal opposite links, flat (change point)")
    arm = b.chain("crank")
    arm.revolute("A", at=[0, 0, 0], axis=[0, 0, 1], actuated=True)
    arm.revolute("B", at=[crank, 0, 0], axis=[0, 0, 1])
    arm.frame("C", at=[ground + crank, 0, 0])
    rocker = b.chain("rocker")
    rocker.revolute("D", at=[ground, 0, 0], axis=[0, 0, 1])
    rocker.frame("C", at=[ground + crank, 0, 0])
    b.closure("C", "crank_C", "rocker_C", "revolute", axis=[0, 0, 1])
    return b.mechanism()


def three_rpr_radial(
    base: float = 0.3,
    platform: float = 0.1,
    order: str = "ABC",
    rotation: np.ndarray | None = None,
    shift: tuple[float, float, float] = (0.0, 0.0, 0.0),
) -> pinmob.Mechanism:
    """Planar 3-RPR with radial legs: base pivots at ``base`` (A, B, C at 90, 210, 330 deg), platform pivots at
    ``platform`` on the same rays, platform centred: the three leg lines meet at the centre (Type II).

    With the legs (prismatic joints) held, a rotation phi of the platform about the centre gives each leg
    the squared length ``base^2 + platform^2 - 2 base platform cos(phi) = (base - platform)^2 +
    base platform phi^2 + O(phi^4)``: the rotation is free to first order and impossible at second
    order (shaky), while the translations are blocked at first order.

    ``order`` declares the limbs in another order; ``rotation`` (3, 3) and ``shift`` [m] place the
    whole mechanism elsewhere (the answers must not change).
    """
    rot = np.eye(3) if rotation is None else np.asarray(rotation, float)
    move = np.asarray(shift, float)
    b = MechanismBuilder("3-RPR-radial", "planar 3-RPR, radial legs: the leg lines meet at the centre (Type II)")
    for name in order:
        angle = np.pi / 2 + 2 * np.pi * "ABC".index(name) / 3
        u = rot @ np.array([np.cos(angle), np.sin(angle), 0.0])
        z = rot @ np.array([0.0, 0.0, 1.0])
        limb = b.limb(name)
        limb.revolute("r1", at=move + base * u, axis=z)
        limb.prismatic("p", at=move + base * u, axis=-u, actuated=True)
        limb.revolute("r2", at=move + platform * u, axis=z)
        limb.tip(at=move, rotation=rot)
    return b.mechanism()


Line = tuple[np.ndarray, np.ndarray]


def loop_6r(name: str, lines: list[Line]) -> pinmob.Mechanism:
    """A closed 6R loop on the joint axes ``lines`` (point, unit direction), 1..6 in loop order.

    The ground is the link from axis 6 to axis 1; limb X holds joints 1, 2, 3, limb Y joints 6, 5, 4;
    their tips meet on the link from axis 3 to axis 4 (the platform). Grubler-Kutzbach:
    ``6 (6 - 1) - 5 x 6 = 0``.
    """
    b = MechanismBuilder(name, "closed 6R loop")
    x, y = b.limb("X"), b.limb("Y")
    for i in (0, 1, 2):
        x.revolute(f"j{i + 1}", at=lines[i][0], axis=lines[i][1])
    for i in (5, 4, 3):
        y.revolute(f"j{i + 1}", at=lines[i][0], axis=lines[i][1])
    tip = 0.5 * (lines[2][0] + lines[3][0])
    x.tip(at=tip)
    y.tip(at=tip)
    return b.mechanism()


def random_lines(rng: np.random.Generator, count: int) -> list[Line]:
    """``count`` random lines: a point within about 0.2 m of the origin and a unit direction."""
    out = []
    for _ in range(count):
        d = rng.normal(size=3)
        out.append((rng.normal(scale=0.2, size=3), d / np.linalg.norm(d)))
    return out


def half_turn(point: np.ndarray) -> np.ndarray:
    """The half-turn about the z axis: ``(x, y, z) -> (-x, -y, z)``."""
    return np.array([-point[0], -point[1], point[2]])


def bricard_line_symmetric(seed: int = 3) -> pinmob.Mechanism:
    """Bricard's line-symmetric 6R linkage: axes 4, 5, 6 are the half-turns about z of axes 1, 2, 3.

    The half-turn maps the loop onto itself (link 12 to 45, 23 to 56, 34 to 61): Bricard (1897) showed
    such a loop moves with one DoF though Grubler-Kutzbach gives 0. Applying the half-turn to the
    loop equation ``S1 w1 + S2 w2 + S3 w3 - S4 w4 - S5 w5 - S6 w6 = 0`` (joints 4, 5, 6 of limb Y, whose
    rates w4, w5, w6 run the other way) gives the same equation with the rates exchanged, so along the
    one-DoF motion ``|w1| = |w4|, |w2| = |w5|, |w3| = |w6|``.
    """
    lines = random_lines(np.random.default_rng(seed), 3)
    lines += [(half_turn(p), half_turn(d)) for p, d in lines]
    return loop_6r("Bricard-line-symmetric", lines)


def generic_6r(seed: int = 5) -> pinmob.Mechanism:
    """A closed 6R loop on six random axes: generically rigid (Grubler-Kutzbach 0, first-order rigid)."""
    return loop_6r("generic-6R", random_lines(np.random.default_rng(seed), 6))


def arm_closed_by(kind: str, seed: int = 11) -> pinmob.Mechanism:
    """A serial 6R arm on random axes whose end frame is joined to a ground frame by a ``kind`` closure.

    A single loop with ``6 - rows`` DoF (3d: 3, revolute: 1, universal and cylindrical: 2, planar: 3).
    """
    rng = np.random.default_rng(seed)
    b = MechanismBuilder(f"6R-{kind}", f"6R arm closed by a {kind} closure")
    arm = b.chain("arm")
    for i, (p, d) in enumerate(random_lines(rng, 6)):
        arm.revolute(f"j{i + 1}", at=p, axis=d)
    end = np.array([0.1, 0.2, 0.3])
    arm.frame("end", at=end)
    ground = b.chain("ground")
    ground.frame("end", at=end)
    u = np.array([0.2, -0.5, 0.84]) / np.linalg.norm([0.2, -0.5, 0.84])
    axis = u if kind in ("revolute", "universal", "cylindrical", "planar") else None
    axis_b = np.cross(u, [1.0, 0, 0]) if kind == "universal" else None  # perpendicular to u (frames b = a at q)
    b.closure("cut", "ground_end", "arm_end", kind, axis=axis, axis_b=axis_b)
    return b.mechanism()


def _project(mech: pinmob.Mechanism, q: np.ndarray, du: np.ndarray, held: tuple[int, ...]) -> np.ndarray | None:
    """q moved by the dimensionless joint step ``du`` and projected back on the closed set by the minimum-norm
    damped solver (``held`` joints kept); None when it does not close."""
    import pinocchio as pin

    from pinmob.assembly.residual import closure_residual
    from pinmob.assembly.solver import solve
    from pinmob.model.joints import linear_velocity_mask

    model = mech.model
    col = np.where(linear_velocity_mask(model), mech.length_scale, 1.0)
    free = np.ones(model.nv, bool)
    free[list(held)] = False
    res = solve(model, closure_residual(mech), pin.integrate(model, q, col * du), tol=1e-12, max_iter=200,
                length=mech.length_scale, free=free)  # fmt: skip
    return res.q if res.residual <= 1e-9 else None


def platform_follows(
    mech: pinmob.Mechanism, q: np.ndarray, twist: np.ndarray, held: tuple[int, ...] = (), step: float = 0.02
) -> tuple[float, float]:
    """How far the platform follows a first-order motion at finite amplitude, measured without the finite analysis.

    The joint rates moving the platform along ``twist`` ([v; w] at the platform origin, world axes) at unit
    dimensionless speed (least squares on the closed chain's rates, ``held`` joints still, from the closure
    Jacobian's SVD) are stepped by ``+-step`` and projected back on the closed set by the minimum-norm solver; the
    platform's displacement (Pinocchio's kinematics, ``[dx / L; log(R R0^T)]``) along the motion, as a fraction of
    ``step``, is returned for both signs. A motion that exists at finite amplitude gives about 1 (the projection
    moves little: the step left the closed set by O(step^2)); one blocked at order 2 gives about 0 (the closed
    set holds no curve along it: the projection falls back onto what does move).
    """
    import pinocchio as pin

    from pinmob.assembly.residual import closure_residual
    from pinmob.model.joints import linear_velocity_mask

    model, data = mech.model, mech.model.createData()
    length = mech.length_scale
    col = np.where(linear_velocity_mask(model), length, 1.0)
    w = np.r_[np.full(3, 1 / length), np.ones(3)]
    rows = np.vstack([closure_residual(mech)(q)[1] * col, np.eye(model.nv)[list(held)]])
    _, s, vt = np.linalg.svd(rows)
    null = vt[int(np.sum(s > 1e-6 * s[0])) :].T
    pin.computeJointJacobians(model, data, q)
    pin.updateFramePlacements(model, data)
    jp = w[:, None] * pin.getFrameJacobian(model, data, mech.platform_id, pin.LOCAL_WORLD_ALIGNED) * col
    t = w * np.asarray(twist, float)
    t /= np.linalg.norm(t)
    u = null @ np.linalg.lstsq(jp @ null, t, rcond=None)[0]
    u /= np.linalg.norm(jp @ u)
    start = data.oMf[mech.platform_id].copy()
    out = []
    for sign in (1.0, -1.0):
        moved = _project(mech, q, sign * step * u, held)
        if moved is None:
            out.append(float("nan"))
            continue
        pin.framesForwardKinematics(model, data, moved)
        end = data.oMf[mech.platform_id]
        d = np.r_[end.translation - start.translation, pin.log3(end.rotation @ start.rotation.T)]
        out.append(float(sign * (w * d) @ t / step))
    return out[0], out[1]


def joints_follow(mech: pinmob.Mechanism, q: np.ndarray, rates: np.ndarray, step: float = 0.02) -> tuple[float, float]:
    """Like :func:`platform_follows` for dimensionless joint rates: the projected joint displacement along them."""
    from pinmob.model.joints import linear_velocity_mask, short_difference

    col = np.where(linear_velocity_mask(mech.model), mech.length_scale, 1.0)
    u = np.asarray(rates, float) / np.linalg.norm(rates)
    out = []
    for sign in (1.0, -1.0):
        moved = _project(mech, q, sign * step * u, ())
        out.append(
            float("nan") if moved is None else float(sign * (short_difference(mech.model, q, moved) / col) @ u / step)
        )
    return out[0], out[1]
