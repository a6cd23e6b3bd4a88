"""The seed paper's 3-PUU: eq. 20 at generic configurations, and hand derivations at beta = 0 and pi/2.

Geometry (pinmob/catalog.py): limb i at theta_i = 0, 120, 240 deg, slider on the
vertical guide through R e_i, platform vertex at r e_i, platform hanging below.
e_i = (cos theta_i, sin theta_i, 0), t_i = z x e_i.

Note on the paper's labels: its sliders are P1 at 0 deg, P2 at 240 deg, P3 at
120 deg, while eqs. 21-22 give limb 2 the couple at theta = 120 deg. As a set the
three couples agree with the sliders; the tests pair each limb with the eq. 20
couple at its own slider angle.
"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest
from numpy.testing import assert_allclose

import pinmob
from pinmob.screw.algebra import twist_from_paper, wrench_scaling
from pinmob.screw.bases import subspace_gap

THETAS = {"A": 0.0, "B": 2 * np.pi / 3, "C": 4 * np.pi / 3}
Z = np.array([0.0, 0.0, 1.0])


def radial(theta: float) -> np.ndarray:
    return np.array([np.cos(theta), np.sin(theta), 0.0])


def paper_couple(beta: float, theta: float) -> np.ndarray:
    """Eq. 20 as a wrench [f; tau]: a pure couple (cos b cos t, cos b sin t, sin b)."""
    return np.r_[0.0, 0.0, 0.0, np.cos(beta) * np.cos(theta), np.cos(beta) * np.sin(theta), np.sin(beta)]


def same_span(a: np.ndarray, b: np.ndarray, length: float) -> bool:
    s = wrench_scaling(length)[:, None]
    return subspace_gap(s * a.reshape(6, -1), s * b.reshape(6, -1)) < 1e-7


def test_generic_matches_paper_eq20_and_eq38(puu: pinmob.Mechanism) -> None:
    """3T, constraint rank 3, each limb's only wrench the couple of eq. 20 (beta from the geometry)."""
    mob = pinmob.analyze(puu, "generic")
    big_r, small_r, link = 0.3, 0.15, 0.25  # the catalog's dimensions
    beta = np.arctan2(np.sqrt(link**2 - (big_r - small_r) ** 2), big_r - small_r)
    assert (mob.dof, mob.motion_type, mob.constraint_rank) == (3, "3T", 3)
    for limb in mob.limbs:
        assert limb.wrench_count == 1
        assert same_span(limb.wrenches, paper_couple(beta, THETAS[limb.name]), puu.length_scale)
    # eq. 38: the free space is the three translations
    assert_allclose(mob.free_twists, np.vstack([np.eye(3), np.zeros((3, 3))]), atol=1e-9)
    # eq. 23-25: |K| = (sqrt 3 / 2) * 3 sin b cos^2 b != 0 for equal betas
    k = np.array([paper_couple(beta, THETAS[n])[3:] for n in "ABC"])
    assert_allclose(np.linalg.det(k), np.sqrt(3) / 2 * 3 * np.sin(beta) * np.cos(beta) ** 2, rtol=1e-12)


def limb_angles(mech: pinmob.Mechanism, q: np.ndarray, limb: str) -> tuple[float, float]:
    """beta_i, theta_i of eq. 20 from the link's direction (Pinocchio frame positions of the two U centres).

    The couple is normal to the U-joint plane, spanned by the outer axis t_i (fixed to slider and platform,
    so t_i = z x e_i at every configuration: the sliders translate and the platform does not rotate) and the
    intermediate axis n_i (normal to t_i and to the link). It is therefore along t_i x n_i, the link's
    component normal to t_i: d - (d . t_i) t_i with d = (U2 centre) - (U1 centre). Pointing it upward,
    beta_i = atan2(|d_z|, |d . e_i|) (elevation above the xoy plane) and theta_i = the slider's angle.
    """
    model = mech.model
    data = model.createData()
    pin.framesForwardKinematics(model, data, q)
    d = data.oMf[model.getFrameId(f"{limb}_u2a")].translation - data.oMf[model.getFrameId(f"{limb}_u1a")].translation
    theta = THETAS[limb]
    return float(np.arctan2(abs(d[2]), abs(d @ radial(theta)))), theta


def test_offset_configuration_keeps_eq20_couples(puu: pinmob.Mechanism) -> None:
    """At an asymmetric pose each limb's only wrench is eq. 20's couple at its own beta_i, theta_i.

    The platform is off-centre, so the three links have different elevations (checked), and each couple
    must follow its own link (the angles come from the geometry, see :func:`limb_angles`).
    """
    q = pinmob.closed_configuration(puu, "offset")
    mob = pinmob.analyze(puu, q)
    assert (mob.dof, mob.motion_type) == (3, "3T")
    betas = []
    for limb in mob.limbs:
        beta, theta = limb_angles(puu, q, limb.name)
        betas.append(beta)
        assert limb.wrench_count == 1
        assert same_span(limb.wrenches, paper_couple(beta, theta), puu.length_scale)
    assert np.ptp(betas) > 0.05  # the limbs really differ: one beta for all would fail the check above
    # eq. 25's determinant at these betas is non-zero: constraint rank 3
    k = np.array([paper_couple(b, THETAS[n])[3:] for b, n in zip(betas, "ABC")])
    assert abs(np.linalg.det(k)) > 0.1


def test_flat_hand_derivation(puu_flat: pinmob.Mechanism) -> None:
    """beta = 0 (links horizontal, radial, length R - r), derived by hand.

    Limb i, with P the slider point and M the vertex, d = M - P = -(R - r) e_i:
    joint screws  P: [z; 0]   U1: rot t_i at P, rot z at P   U2: rot z at M, rot t_i at M.
    rot(t_i at M) - rot(t_i at P) = [d x t_i; 0] = (R - r) [-z; 0]: the slider's translation
    is a combination of the U joints, so the twist rank is 4, not 5 (serial singularity).
    Twist space {T z, T t_i, R z, R t_i (through P)}; its reciprocal wrenches: f, tau with
    f.z = f.t_i = 0 and tau (at P) . z = tau . t_i = 0, i.e. a couple along e_i and a
    force along e_i through P -- a radial line through the platform centre.
    Three limbs: couples along x, y and forces along x, y through the centre: rank 4.
    Free: translation along z and rotation about z through the centre: 1T1R, 2 DoF.
    """
    mob = pinmob.analyze(puu_flat, "flat")
    centre = np.zeros(3)
    for limb in mob.limbs:
        e = radial(THETAS[limb.name])
        assert (limb.twist_rank, limb.generic_twist_rank, limb.wrench_count) == (4, 5, 2)
        assert limb.serially_singular
        expected = np.column_stack([np.r_[0, 0, 0, e], np.r_[e, np.cross(centre, e)]])
        assert same_span(limb.wrenches, expected, puu_flat.length_scale)
    assert (mob.dof, mob.motion_type, mob.constraint_rank) == (2, "1T1R", 4)
    t, r = mob.motions
    assert_allclose(t.direction, Z, atol=1e-12)
    assert_allclose(r.direction, Z, atol=1e-12)
    assert_allclose(r.point, centre, atol=1e-9)
    assert mob.serially_singular_limbs == ("A", "B", "C")


def test_flat_paper_view_reproduces_eq30_to_eq37(puu_flat: pinmob.Mechanism) -> None:
    """The paper's substitution beta = 0 in eq. 20: couples along e_i (eq. 30), rank 2 (eq. 35),
    constraint space = torques about x and y (eq. 34), free space 3T + R about z (eq. 37)."""
    mob = pinmob.paper_view(puu_flat, "flat")
    assert mob.view == "paper"
    for limb in mob.limbs:
        assert limb.wrench_count == 1
        assert same_span(limb.wrenches, paper_couple(0.0, THETAS[limb.name]), puu_flat.length_scale)
    assert (mob.dof, mob.motion_type, mob.constraint_rank) == (4, "3T1R", 2)
    eq34 = np.array([[0, 0, 0, 1, 0, 0], [0, 0, 0, 0, 1, 0]], float).T
    assert same_span(mob.constraint_wrenches, eq34, puu_flat.length_scale)
    # eq. 37 in the paper's axis-first order (w; v); converted to [v; w]
    eq37_paper = np.array([[0, 0, 0, 1, 0, 0], [0, 0, 0, 0, 1, 0], [0, 0, 0, 0, 0, 1], [0, 0, 1, 0, 0, 0]], float)
    eq37 = twist_from_paper(eq37_paper).T
    assert subspace_gap(eq37, mob.free_twists) < 1e-7


def test_paper_view_equals_analysis_where_no_limb_is_serially_singular(puu: pinmob.Mechanism) -> None:
    """At a generic configuration the generic limb wrenches are the wrenches there: both views agree."""
    paper = pinmob.paper_view(puu, "offset")
    real = pinmob.analyze(puu, "offset")
    assert paper.view == "paper" and (paper.dof, paper.motion_type) == (real.dof, real.motion_type) == (3, "3T")
    assert_allclose(paper.free_twists, real.free_twists, atol=1e-12)


def test_paper_view_misses_sarrus_lock() -> None:
    """Sarrus fully stretched: each limb's three parallel revolutes become coplanar with their axes'
    common normal, so the limb loses a twist and gains a constraint; with both limbs so, nothing
    is free (hand derivation in tests/test_models.py). The generic limb wrenches -- those of a
    planar 3R chain, which forbid the two rotations normal to its axes and the translation along
    them -- carried to that configuration still leave the translation normal to both limbs'
    axes: the paper's procedure reports 1T where the mechanism is locked (to first order)."""
    sarrus = pinmob.load("Sarrus")
    real = pinmob.analyze(sarrus, "stretched")
    paper = pinmob.paper_view(sarrus, "stretched")  # approached from the 'generic' configuration
    assert (real.dof, real.motion_type) == (0, "rigid")
    assert (paper.dof, paper.motion_type) == (1, "1T")
    assert set(real.serially_singular_limbs) == {"A", "B"}


def test_vertical_hand_derivation(puu_vertical: pinmob.Mechanism) -> None:
    """beta = pi/2 (R = r, links vertical, length l), derived by hand.

    U axes t_i, n_i = -e_i at both ends, d = M - P = -l z:
    rot(e_i at M) - rot(e_i at P) = [d x e_i; 0] ~ T t_i and rot(t_i at M) - rot(t_i at P) ~ T e_i,
    so the limb spans 3T + R e_i + R t_i: rank 5 (no serial singularity), one wrench:
    a couple along z (normal to e_i and t_i). The three couples coincide: rank 1,
    free 3T2R (rotations about x and y), 5 DoF -- the paper's 'another singular case'.
    """
    mob = pinmob.analyze(puu_vertical, "vertical")
    for limb in mob.limbs:
        assert (limb.twist_rank, limb.wrench_count) == (5, 1)
        assert same_span(limb.wrenches, np.r_[0, 0, 0, Z], puu_vertical.length_scale)
    assert (mob.dof, mob.motion_type, mob.constraint_rank) == (5, "3T2R", 1)
    rotations = [m for m in mob.motions if m.kind is pinmob.MotionKind.ROTATION]
    assert_allclose(np.array([m.direction for m in rotations]), np.eye(3)[:2], atol=1e-12)
    assert pinmob.analyze(puu_vertical, "generic").motion_type == "3T"


def test_horizontal_links_do_not_close_with_longer_links(puu: pinmob.Mechanism) -> None:
    """3-PUU's links (l = 0.25 m) are longer than R - r (0.15 m): beta = 0 cannot be assembled.

    Tilt every link to horizontal (u1a = +beta0 about t_i, beta0 = atan2(0.2, 0.15) its elevation at the
    reference, u2b = -beta0 to keep the platform's orientation). Vertex i moves from (r e_i, -0.2) to
    ((R - l) e_i, 0), so tip i moves by d_i = (R - l - r) e_i + 0.2 z = -0.10 e_i + 0.2 z. The platform
    frame is limb A's tip, so the residual of limb i is |d_i - d_A| = 0.10 |e_i - e_A| = 0.10 sqrt(3) m
    for B and C (0 for A), with no rotation: the configuration is rejected with these, never analysed.
    """
    beta0 = np.arctan2(0.2, 0.15)
    q = puu.q_from_joints({f"{x}_u1a": beta0 for x in "ABC"} | {f"{x}_u2b": -beta0 for x in "ABC"})
    data = puu.model.createData()
    pin.framesForwardKinematics(puu.model, data, q)
    for x in "ABC":  # the links are horizontal indeed
        d = (
            data.oMf[puu.model.getFrameId(f"{x}_u2a")].translation
            - data.oMf[puu.model.getFrameId(f"{x}_u1a")].translation
        )
        assert abs(d[2]) < 1e-12 and np.linalg.norm(d) == pytest.approx(0.25)
    with pytest.raises(pinmob.ClosureError, match="does not close") as err:
        pinmob.analyze(puu, q)
    res = err.value.residuals
    assert set(res) == {"A", "B", "C"}
    assert_allclose([res[x][0] for x in "ABC"], [0.0, 0.1 * np.sqrt(3), 0.1 * np.sqrt(3)], atol=1e-12)
    assert_allclose([res[x][1] for x in "ABC"], 0.0, atol=1e-12)


def test_seed_paper_example_prints_the_papers_numbers() -> None:
    """examples/3puu_seed_paper.py: the numbers it prints are the paper's, derived here from its equations.

    Generic (R - r = 0.15, drop 0.2, link 0.25): cos beta = 0.6, sin beta = 0.8, so eq. 20 for limb B
    (theta = 120 deg) is (0 0 0 -0.3 0.3 sqrt3 0.8), and pinmob's couple prints the same on the same line.
    Flat: eq. 31's U has rows (sqrt6/3, 0, sqrt3/3), (-sqrt6/6, sqrt2/2, sqrt3/3), (-sqrt6/6, -sqrt2/2, sqrt3/3);
    Sigma = diag(sqrt6/2, sqrt6/2, 0) (the Gram matrix of three unit couples 120 deg apart has eigenvalues
    3/2, 3/2, 0); S_F (eq. 37) ends with the rotation about z, (0 0 1 0 0 0) axis-first.
    """
    script = Path(__file__).resolve().parent.parent / "examples" / "3puu_seed_paper.py"
    out = subprocess.run([sys.executable, str(script)], capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stderr

    def fmt(*xs: float) -> str:
        return "(" + " ".join(f"{x + 0.0:7.4f}" for x in xs) + ")"

    lines = out.stdout.splitlines()
    b_line = next(line for line in lines if line.strip().startswith("B: beta"))
    couple_b = fmt(0, 0, 0, -0.5 * 0.6, np.sqrt(3) / 2 * 0.6, 0.8)
    assert b_line.count(couple_b) == 2 and "beta  53.13 deg" in b_line
    for u_row in ((np.sqrt(6) / 3, 0, np.sqrt(3) / 3), (-np.sqrt(6) / 6, np.sqrt(2) / 2, np.sqrt(3) / 3)):
        assert fmt(*u_row) in out.stdout
    assert fmt(np.sqrt(6) / 2, 0, 0, 0, 0, 0) in out.stdout and fmt(0, np.sqrt(6) / 2, 0, 0, 0, 0) in out.stdout
    s_f = lines.index("  paper's view: 4 DoF, 3T1R") - 1
    assert lines[s_f].strip() == fmt(0, 0, 1, 0, 0, 0)
    assert "constraint rank 4: 2 DoF, 1T1R (T1 z, R1 z)" in out.stdout and "limbs A, B, C" in out.stdout
