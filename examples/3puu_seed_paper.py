"""The seed paper's quantities for its 3-PUU (Zhao et al., eqs. 20-38), computed by pinmob.

Prints:

* ``3-PUU`` at ``generic``: each limb's constraint wrench beside the paper's eq. 20
  couple, with beta_i and theta_i measured on the model's configuration (the link
  direction and the slider angle), and the free space S_F (eq. 38).
* ``3-PUU-flat`` at ``flat`` (beta_i = 0), the paper's own procedure (generic limb
  couples carried to beta = 0, :func:`pinmob.paper_view`): the stacked couples
  (eq. 30), their SVD ``U Sigma V^T`` (eqs. 31-33), the constraint space (eq. 34)
  and the free space S_F (eq. 37): 4 DoF, 3T1R.
* where pinmob's own analysis (wrenches from the Jacobians at the configuration)
  differs: every limb is serially singular there, so the answer is 1T1R;
* and what exists at finite amplitude (``finite=True``, docs/finite-mobility.md): only
  the translation along z, 1T; the rotation about z is blocked at order 2.

Wrenches are printed ``(f; tau)`` as in the paper; twists in the paper's axis-first
layout ``(w; v)``. Run: ``python examples/3puu_seed_paper.py``
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

import pinmob
from pinmob.screw.algebra import twist_to_paper


def row(v: np.ndarray) -> str:
    return "(" + " ".join(f"{x:7.4f}" for x in np.round(np.asarray(v, float), 4) + 0.0) + ")"


def matrix(name: str, m: np.ndarray) -> None:
    print(f"  {name} =")
    for r in np.atleast_2d(m):
        print("    " + row(r))


def limb_angles(mech: pinmob.Mechanism, q: np.ndarray, limb: str) -> tuple[float, float]:
    """beta_i (elevation of the U-joint plane's normal: the link, seen along t_i) and theta_i (slider angle)."""
    data = mech.model.createData()
    pin.framesForwardKinematics(mech.model, data, q)
    u1, u2 = (data.oMf[mech.model.getFrameId(f"{limb}_{j}")].translation for j in ("u1a", "u2a"))
    theta = float(np.arctan2(u1[1], u1[0]))
    d = u2 - u1
    return float(np.arctan2(abs(d[2]), abs(d @ [np.cos(theta), np.sin(theta), 0.0]))), theta


def oriented(w: np.ndarray, theta: float) -> np.ndarray:
    """Unit couple pointing radially out and up, like eq. 20 (both components >= 0 for 0 <= beta <= pi/2)."""
    w = w / np.linalg.norm(w)
    return w if w[3:] @ [np.cos(theta), np.sin(theta), 1.0] >= 0 else -w


def eq20(beta: float, theta: float) -> np.ndarray:
    return np.array([0, 0, 0, np.cos(beta) * np.cos(theta), np.cos(beta) * np.sin(theta), np.sin(beta)])


def generic() -> None:
    mech = pinmob.load("3-PUU")
    q = pinmob.closed_configuration(mech, "generic")
    mob = pinmob.analyze(mech, q)
    print("3-PUU at 'generic': each limb's constraint wrench (f; tau) and eq. 20")
    for limb in mob.limbs:
        beta, theta = limb_angles(mech, q, limb.name)
        print(
            f"  {limb.name}: beta {np.degrees(beta):6.2f} deg, theta {np.degrees(theta):7.2f} deg  "
            f"pinmob {row(oriented(limb.wrenches[:, 0], theta))}  eq. 20 {row(eq20(beta, theta))}"
        )
    print(f"  constraint rank {mob.constraint_rank} (eq. 29); free space S_F (eq. 38), (w; v):")
    matrix("S_F", twist_to_paper(mob.free_twists.T))
    print(f"  {mob.dof} DoF, {mob.motion_type}")


def flat() -> None:
    mech = pinmob.load("3-PUU-flat")
    q = pinmob.closed_configuration(mech, "flat")
    paper = pinmob.paper_view(mech, "flat")  # approached along the configuration's declared 'approach'

    print("\n3-PUU-flat at 'flat' (beta_i = 0), the paper's procedure (eq. 20 carried to beta = 0):")
    thetas = [limb_angles(mech, q, limb.name)[1] for limb in paper.limbs]
    sr = np.array([oriented(limb.wrenches[:, 0], t) for limb, t in zip(paper.limbs, thetas)])
    matrix("$^r (eq. 30)", sr)
    # SVD $^r = U Sigma V^T. Two singular values are equal, so the SVD's own U and V are unique only up to a
    # rotation of that pair; V^T is taken in pinmob's canonical bases (constraint couples along x, y; free twists
    # T x, T y, T z, R z in [v; w], the null space of $^r under the plain product), U = $^r V_1 / sigma and
    # the left null vector.
    u_svd, sigma, _ = np.linalg.svd(sr)
    d = paper.constraint_rank
    vt = np.vstack([paper.constraint_wrenches.T, paper.free_twists.T])
    left_null = u_svd[:, d:] * np.sign(u_svd[:, d:].sum(axis=0))  # (1, 1, 1) / sqrt(3) here
    u = np.column_stack([sr @ vt[i] / sigma[i] for i in range(d)] + [left_null])
    sig = np.zeros((3, 6))
    sig[:d, :d] = np.diag(sigma[:d])
    assert np.allclose(u @ sig @ vt, sr, atol=1e-9) and np.allclose(u.T @ u, np.eye(3), atol=1e-9)
    matrix("U (eq. 31)", u)
    matrix("Sigma (eq. 32)", sig)
    matrix("V^T (eq. 33)", vt)
    print(
        f"  constraint space C (eq. 34): the first {d} rows of V^T, d = {d} (eq. 35); free space S_F (eq. 37), (w; v):"
    )
    matrix("S_F", twist_to_paper(paper.free_twists.T))
    print(f"  paper's view: {paper.dof} DoF, {paper.motion_type}")

    real = pinmob.analyze(mech, q, configuration="flat", finite=True)
    print("\npinmob at the same configuration (wrenches from the Jacobians there):")
    for limb in real.limbs:
        print(
            f"  {limb.name}: twist rank {limb.twist_rank} (generic {limb.generic_twist_rank}), "
            f"{limb.wrench_count} wrenches" + ("  <- serial singularity" if limb.serially_singular else "")
        )
    print(
        f"  constraint rank {real.constraint_rank}: {real.dof} DoF, {real.motion_type} "
        f"({', '.join(m.label for m in real.motions)}); the paper's {paper.motion_type} misses the radial forces "
        f"of the serially singular limbs {', '.join(real.serially_singular_limbs)}"
    )
    fm = real.finite
    print(f"\nat finite amplitude (higher-order conditions up to order {fm.order}, traced, sampled):")
    for v in fm.motions:
        print(f"  {v.label}: {v.words()}")
    print(
        f"  {fm.finite_dof} DoF finite, {' '.join(b.motion_type or '' for b in fm.free.branches)}; the whole "
        f"mechanism {fm.finite_mechanism_dof} DoF (instantaneous {fm.free.mechanism_dof})"
    )


def main() -> None:
    generic()
    flat()


if __name__ == "__main__":
    main()
