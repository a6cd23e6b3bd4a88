"""Writes the CAD-gap fixtures of this folder (run from the repository root: python tests/data/cad_gaps/make_cad_gaps.py).

* ``spherical_3rrr/robot.urdf``: a spherical 3-RRR in onshape-to-robot's URDF convention (closing frames
  ``closing_<name>_1/_2``). Every joint axis passes through the centre C = (0.03, -0.02, 0.12) (the joint
  frames sit on their axes, 4 to 8 cm from C). Leg 1 carries the platform; legs 2 and 3 end on distal links
  whose closing frames sit on the platform's hinge axes w2, w3, 7 cm from C, and the platform's closing
  frames sit 1.0 um and 0.6 um further out along the same axes: every body turns about C, so each pair of
  points stays on two concentric spheres and the loops can never close better than that (a CAD gap).
* ``legged/robot.xml``: a small quadruped (free base) whose legs are planar five-bars (two coaxial hip
  hinges, two knees, the foot closed by ``<equality connect site1 site2>``), closed exactly at MuJoCo's
  reference pose; its keyframe ``stand`` (base lifted and tilted, hips turned, knees solved by MuJoCo's
  kinematics) has one knee per leg turned so that the feet miss by 1.04, 0.8, 0.6 and 0.3 um.
"""

from __future__ import annotations

from pathlib import Path

import mujoco
import numpy as np

HERE = Path(__file__).resolve().parent

# --------------------------------------------------------------------------- spherical 3-RRR (URDF)

C = np.array([0.03, -0.02, 0.12])


def unit(v: list[float]) -> np.ndarray:
    a = np.asarray(v, float)
    return a / np.linalg.norm(a)


#: Per leg: base hinge u, middle hinge v, platform hinge w (world axes at the neutral configuration).
AXES = [
    (unit([0.9, 0.1, -0.45]), unit([0.2, 0.85, -0.3]), unit([0.35, 0.3, 0.9])),
    (unit([-0.5, 0.8, -0.4]), unit([-0.9, -0.2, -0.35]), unit([-0.45, 0.25, 0.85])),
    (unit([-0.4, -0.85, -0.42]), unit([0.7, -0.6, -0.2]), unit([0.1, -0.5, 0.8])),
]
RADII = (0.05, 0.08, 0.06)  # joint frames on their axes, this far from C
R_CLOSE = 0.07
GAPS = {2: 1.0e-6, 3: 0.6e-6}


def xyz(v: np.ndarray) -> str:
    return " ".join(f"{x:.12g}" for x in v)


def spherical_urdf() -> str:
    links = ["base", "platform"]
    joints = []
    limit = '<limit lower="-3.14" upper="3.14" effort="1" velocity="1"/>'
    for i, (u, v, w) in enumerate(AXES, start=1):
        pa, pb, pc = C + RADII[0] * u, C + RADII[1] * v, C + RADII[2] * w
        links += [f"proximal{i}", f"distal{i}"]
        joints.append(
            f'  <joint name="a{i}" type="revolute"><parent link="base"/><child link="proximal{i}"/>'
            f'<origin xyz="{xyz(pa)}"/><axis xyz="{xyz(u)}"/>{limit}</joint>'
        )
        joints.append(
            f'  <joint name="b{i}" type="revolute"><parent link="proximal{i}"/><child link="distal{i}"/>'
            f'<origin xyz="{xyz(pb - pa)}"/><axis xyz="{xyz(v)}"/>{limit}</joint>'
        )
        if i == 1:
            joints.append(
                f'  <joint name="c1" type="revolute"><parent link="distal1"/><child link="platform"/>'
                f'<origin xyz="{xyz(pc - pb)}"/><axis xyz="{xyz(w)}"/>{limit}</joint>'
            )
            continue
        p1 = C + R_CLOSE * w
        p2 = C + (R_CLOSE + GAPS[i]) * w
        links += [f"closing_leg{i}_1", f"closing_leg{i}_2"]
        joints.append(
            f'  <joint name="closing_leg{i}_1_frame" type="fixed"><parent link="distal{i}"/>'
            f'<child link="closing_leg{i}_1"/><origin xyz="{xyz(p1 - pb)}"/></joint>'
        )
        platform = C + RADII[2] * AXES[0][2]  # the platform's frame: joint c1's
        joints.append(
            f'  <joint name="closing_leg{i}_2_frame" type="fixed"><parent link="platform"/>'
            f'<child link="closing_leg{i}_2"/><origin xyz="{xyz(p2 - platform)}"/></joint>'
        )
    body = "\n".join([f'  <link name="{n}"/>' for n in links] + joints)
    return (
        '<?xml version="1.0"?>\n<!-- Written by make_cad_gaps.py: a spherical 3-RRR (every axis through C = '
        "(0.03, -0.02, 0.12)) in onshape-to-robot's convention; the closing frames of legs 2 and 3 miss by 1.0 "
        "and 0.6 um along the platform hinge axes. -->\n"
        f'<robot name="spherical_3rrr">\n{body}\n</robot>\n'
    )


# --------------------------------------------------------------------------- five-bar quadruped (MJCF)

HIPS = {"fl": (0.1, 0.06), "fr": (0.1, -0.06), "hl": (-0.1, 0.06), "hr": (-0.1, -0.06)}
KNEE_A, KNEE_B, FOOT = np.array([0.03, 0, -0.04]), np.array([-0.03, 0, -0.04]), np.array([0.0, 0, -0.12])
LEG_GAPS = {"fl": 1.04e-6, "fr": 0.8e-6, "hl": 0.6e-6, "hr": 0.3e-6}
HIP_ANGLES = {"fl": (0.25, -0.1), "fr": (0.3, -0.15), "hl": (-0.2, 0.1), "hr": (-0.1, 0.2)}


def legged_mjcf(keyframe: str = "") -> str:
    legs = []
    for leg, (x, y) in HIPS.items():
        legs.append(
            f'      <body name="upper_a_{leg}" pos="{x} {y} 0"><joint name="hip_a_{leg}" axis="0 1 0"/>'
            f'<geom type="capsule" fromto="0 0 0 {xyz(KNEE_A)}" size="0.008"/>\n'
            f'        <body name="lower_a_{leg}" pos="{xyz(KNEE_A)}"><joint name="knee_a_{leg}" axis="0 1 0"/>'
            f'<geom type="capsule" fromto="0 0 0 {xyz(FOOT - KNEE_A)}" size="0.006"/>'
            f'<site name="foot_{leg}" pos="{xyz(FOOT - KNEE_A)}"/></body></body>\n'
            f'      <body name="upper_b_{leg}" pos="{x} {y} 0"><joint name="hip_b_{leg}" axis="0 1 0"/>'
            f'<geom type="capsule" fromto="0 0 0 {xyz(KNEE_B)}" size="0.008"/>\n'
            f'        <body name="lower_b_{leg}" pos="{xyz(KNEE_B)}"><joint name="knee_b_{leg}" axis="0 1 0"/>'
            f'<geom type="capsule" fromto="0 0 0 {xyz(FOOT - KNEE_B)}" size="0.006"/>'
            f'<site name="toe_{leg}" pos="{xyz(FOOT - KNEE_B)}"/></body></body>'
        )
    connects = "".join(f'<connect site1="foot_{leg}" site2="toe_{leg}"/>' for leg in HIPS)
    motors = "".join(f'<motor joint="hip_a_{leg}"/><motor joint="hip_b_{leg}"/>' for leg in HIPS)
    return (
        '<mujoco model="legged">\n  <!-- Written by make_cad_gaps.py: a quadruped whose legs are planar five-bars '
        "closed at the foot; the keyframe 'stand' misses by 1.04, 0.8, 0.6 and 0.3 um. -->\n"
        '  <worldbody>\n    <body name="torso" pos="0 0 0.2"><freejoint name="base"/>'
        '<geom type="box" size="0.13 0.07 0.02"/>\n' + "\n".join(legs) + "\n    </body>\n  </worldbody>\n"
        f"  <equality>{connects}</equality>\n  <actuator>{motors}</actuator>\n{keyframe}</mujoco>\n"
    )


def stand_qpos() -> tuple[np.ndarray, dict[str, float]]:
    """MuJoCo's qpos of 'stand' and the feet's gaps [m]: hips set, knees solved by Newton on MuJoCo's sites."""
    m = mujoco.MjModel.from_xml_string(legged_mjcf())
    d = mujoco.MjData(m)
    d.qpos[:3] = [0.01, 0.02, 0.25]
    d.qpos[3:7] = unit([1.0, 0.05, -0.08, 0.1])
    adr = {m.joint(j).name: m.jnt_qposadr[j] for j in range(m.njnt)}

    def miss(leg: str) -> np.ndarray:
        mujoco.mj_kinematics(m, d)
        return (d.site(f"toe_{leg}").xpos - d.site(f"foot_{leg}").xpos)[[0, 2]]

    gaps = {}
    for leg, (ta, tb) in HIP_ANGLES.items():
        d.qpos[adr[f"hip_a_{leg}"]], d.qpos[adr[f"hip_b_{leg}"]] = ta, tb
        knees = [adr[f"knee_a_{leg}"], adr[f"knee_b_{leg}"]]
        d.qpos[knees] = [-0.3, 0.3]
        for _ in range(50):  # Newton on the two knees, the torso's frame is a rotation about y away
            e = miss(leg)
            jac = np.zeros((2, 2))
            for k, a in enumerate(knees):
                d.qpos[a] += 1e-7
                jac[:, k] = (miss(leg) - e) / 1e-7
                d.qpos[a] -= 1e-7
            d.qpos[knees] -= np.linalg.solve(jac, e)
        d.qpos[knees[0]] += LEG_GAPS[leg] / np.linalg.norm(FOOT - KNEE_A)  # the foot swings off by the gap
        mujoco.mj_kinematics(m, d)
        gaps[leg] = float(np.linalg.norm(d.site(f"toe_{leg}").xpos - d.site(f"foot_{leg}").xpos))
    return d.qpos.copy(), gaps


def main() -> None:
    (HERE / "spherical_3rrr").mkdir(exist_ok=True)
    (HERE / "spherical_3rrr" / "robot.urdf").write_text(spherical_urdf())
    qpos, gaps = stand_qpos()
    key = f'  <keyframe><key name="stand" qpos="{" ".join(f"{x:.15g}" for x in qpos)}"/></keyframe>\n'
    (HERE / "legged").mkdir(exist_ok=True)
    (HERE / "legged" / "robot.xml").write_text(legged_mjcf(key))
    print("feet gaps [m]:", {k: f"{v:.3g}" for k, v in gaps.items()})


if __name__ == "__main__":
    main()
