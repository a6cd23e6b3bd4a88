"""MJCF models read as MuJoCo reads them: MuJoCo's compiler, then the Pinocchio tree of the compiled model.

MuJoCo (the ``mujoco`` package, imported when an MJCF file is loaded) is the reference compiler of
its format: it resolves includes, defaults (a joint ``pos`` given in a ``<default>`` class),
``ref`` and ``qpos0``, sites, compiler settings and the data of each equality. pinmob builds its
Pinocchio model from the compiled model (:mod:`pinmob.io.mjcf.mjcf_tree`), so that Pinocchio's ``q``
of a hinge or slide is MuJoCo's ``qpos`` and every anchor, axis and closure point is MuJoCo's.

Closures, from the compiled ``eq_data`` (MuJoCo's ``mj_instantiateEquality``):

- ``connect``: a ``3d`` closure. By body: ``eq_data[0:3]`` in body1's frame meets ``eq_data[3:6]``
  in body2's frame (MuJoCo computes the second at the reference pose); by site: the two sites'
  origins meet.
- ``weld``: a ``6d`` closure between frame a = body1 ``* (relpose quat eq_data[6:10], eq_data[3:6])``
  and frame b = body2 ``* (I, anchor eq_data[0:3])``; by site, the two site frames. A weld with
  ``torquescale="0"`` transmits no couple: a ``3d`` closure at its anchor.
- ``joint``: a ``joint`` coupling, ``qpos1 - qpos0_1 = sum_k c_k (qpos2 - qpos0_2)^k``
  (``polycoef``; ``qpos1 - qpos0_1 = c_0`` without joint2).
- ``tendon``: a ``tendon`` coupling, ``l1 - l1_0 = sum_k c_k (l2 - l2_0)^k`` between tendon lengths,
  fixed or spatial (:mod:`pinmob.io.mjcf.mjcf_tendons`).
- ``flex`` and any other kind are refused (one line naming them); an equality that is
  inactive at the start (``active="false"``) is left out, with a warning.

Actuated joints are those of actuators on a hinge or slide (``joint``, ``jointinparent``); every other
actuator MuJoCo moves is held as its moment arms at the configuration (:mod:`pinmob.io.mjcf.mjcf_tendons`: a
fixed tendon's coefficients, MuJoCo's ``actuator_moment`` row for a spatial tendon, a site, a slider-crank
or a ball joint). One warning names what is left out: actuators on bodies (adhesion) and tendon limits
(one-sided). Named configurations: ``reference`` (MuJoCo's ``qpos0``, the
default) when the equalities hold there (MuJoCo's test models close only once simulated: without
it, the analysis finds a closed configuration) and one per ``<keyframe><key>`` (its ``qpos``); those
that do not close are starts (:attr:`pinmob.model.named.NamedConfiguration.start`), from which the
analysis searches for a closed configuration. The
visual geometry is MuJoCo's geoms (:mod:`pinmob.io.mjcf.mjcf_geometry`), built when first drawn. Objects
are shown by their names in the file, unnamed ones by labels with their MuJoCo id (``#k`` for joint
k, ``equality#k`` for the closure of equality k: :mod:`pinmob.io.mjcf.mjcf_names`).
"""

from __future__ import annotations

import warnings
from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np
import pinocchio as pin

from pinmob.bounds import check_bound
from pinmob.io.mesh_files import confine, mesh_roots
from pinmob.io.mjcf.mjcf_assets import drop_unread_files
from pinmob.io.mjcf.mjcf_includes import check_xml_files
from pinmob.io.mjcf.mjcf_names import add_frame, check_labels, closure_frames, label, labels
from pinmob.io.mjcf.mjcf_tendons import is_length, left_out, read_actuators, tendon_closure
from pinmob.io.mjcf.mjcf_tree import Tree, build_tree, qpos_to_q, se3
from pinmob.io.mjcf.mujoco_kinematics import MujocoKinematics
from pinmob.io.schema import errors_at, file_error
from pinmob.model import CLOSURE_TOL, Closure, Geometry, Mechanism, NamedConfiguration, make_closure, make_coupling

#: The equality kinds pinmob reads as closures.
SUPPORTED = ("connect", "weld", "joint", "tendon")
#: MuJoCo's object type of a site (``mjtObj.mjOBJ_SITE``).
OBJ_SITE = 6


def compile_mjcf(path: Path, warn: bool = True) -> Any:
    """The compiled ``mujoco.MjModel`` of the file, or a one-line error with MuJoCo's message.

    Kinematics needs no mass: a moving body without mass or inertia (which MuJoCo refuses to simulate) is
    given a tiny one (the compiler's ``boundmass`` and ``boundinertia``, when the file sets none). Mesh and
    texture files that are missing or outside the model's folders are left out, with a warning (``warn``)
    (:func:`pinmob.io.mjcf.mjcf_assets.drop_unread_files`); a model or include file that is not a regular file, is
    too large or (an include) lies outside those folders is refused (:mod:`pinmob.io.mjcf.mjcf_includes`).
    """
    import mujoco

    check_xml_files(path)
    said: list[str] = []  # MuJoCo's own warnings (e.g. a NaN in the XML), printed by default: kept as one warning
    previous = mujoco.get_mju_user_warning()
    mujoco.set_mju_user_warning(said.append)
    try:
        spec = mujoco.MjSpec.from_file(str(path))
        spec.compiler.boundmass = spec.compiler.boundmass or 1e-9
        spec.compiler.boundinertia = spec.compiler.boundinertia or 1e-12
        unread = drop_unread_files(spec, path)
        m = spec.compile()
    except Exception as exc:  # MuJoCo raises ValueError with the compiler's message
        raise file_error(path, f"MuJoCo cannot compile it: {' '.join(str(exc).split())[:300]}") from None
    finally:
        mujoco.set_mju_user_warning(previous)
    if unread and warn:
        warnings.warn(f"{path.name}: {unread}", stacklevel=3)
    if said and warn:
        warnings.warn(f"{path.name}: MuJoCo says: {' '.join(dict.fromkeys(said))[:300]}", stacklevel=3)
    return m


def _kind(m: Any, e: int) -> str:
    import mujoco

    return mujoco.mjtEq(int(m.eq_type[e])).name.removeprefix("mjEQ_").lower()


def _frames(m: Any, tree: Tree, e: int, on_site: bool) -> tuple[tuple[int, pin.SE3], tuple[int, pin.SE3]]:
    """(joint, placement) of the two sides of connect or weld ``e``, before the equality's own data."""
    out = []
    for obj in (int(m.eq_obj1id[e]), int(m.eq_obj2id[e])):
        if on_site:
            body = int(m.site_bodyid[obj])
            out.append((tree.body_joint[body], tree.body_placement[body] * se3(m.site_pos[obj], m.site_quat[obj])))
        else:
            body = max(obj, 0)  # body2 omitted: the world
            out.append((tree.body_joint[body], tree.body_placement[body]))
    return out[0], out[1]


def equality_closure(m: Any, tree: Tree, e: int, name: str, kinematics: MujocoKinematics) -> Closure:
    """The :class:`Closure` of equality ``e`` of the compiled model (see the module docstring)."""
    model, kind, data = tree.model, _kind(m, e), np.array(m.eq_data[e], float)
    if kind == "tendon":
        return tendon_closure(m, tree, e, name, kinematics)
    if kind == "joint":
        joints = [tree.joint_names[int(j)] for j in (m.eq_obj1id[e], m.eq_obj2id[e]) if j >= 0]
        refs = [float(m.qpos0[m.jnt_qposadr[int(j)]]) for j in (m.eq_obj1id[e], m.eq_obj2id[e]) if j >= 0]
        return make_coupling(model, name, tuple(joints), tuple(data[:5]), tuple(refs))
    on_site = int(m.eq_objtype[e]) == OBJ_SITE
    (j1, m1), (j2, m2) = _frames(m, tree, e, on_site)
    if kind == "connect" and not on_site:
        m1, m2 = m1 * pin.SE3(np.eye(3), data[0:3]), m2 * pin.SE3(np.eye(3), data[3:6])
    elif kind == "weld" and not on_site:
        m1, m2 = m1 * se3(data[3:6], data[6:10]), m2 * pin.SE3(np.eye(3), data[0:3])
    closure_kind = "3d" if kind == "connect" or data[10] == 0 else "6d"
    (na, nb), what = closure_frames(name), f"equality {name!r}"
    fa = add_frame(model, pin.Frame(na, j1, m1, pin.FrameType.OP_FRAME), what)
    fb = add_frame(model, pin.Frame(nb, j2, m2, pin.FrameType.OP_FRAME), what)
    return make_closure(model, name, model.frames[fa].name, model.frames[fb].name, closure_kind)


def closes_at(m: Any, qpos: Any, length: float, tol: float = CLOSURE_TOL) -> bool:
    """True when MuJoCo's equality residuals (``efc_pos``) at ``qpos`` are within ``tol`` (lengths / L).

    A weld's rotation rows are ``torquescale * sin(angle / 2) * axis``; a joint row is a length when
    joint1 slides, a tendon row when tendon1's length is one. A ``qpos`` that is not finite does not close.
    """
    import mujoco

    if not np.isfinite(qpos).all():
        return False
    d = mujoco.MjData(m)
    d.qpos[:] = qpos
    mujoco.mj_forward(m, d)
    rows = np.flatnonzero(d.efc_type[: d.nefc] == mujoco.mjtConstraint.mjCNSTR_EQUALITY)
    for e in range(m.neq):
        pos = np.array(d.efc_pos[rows[d.efc_id[rows] == e]])
        kind = _kind(m, e)
        if kind in ("joint", "tendon"):
            obj = int(m.eq_obj1id[e])
            slide = int(m.jnt_type[obj]) == mujoco.mjtJoint.mjJNT_SLIDE if kind == "joint" else is_length(m, obj)
            worst = np.abs(pos).max(initial=0.0) / (length if slide else 1.0)
        else:
            worst = np.abs(pos[:3]).max(initial=0.0) / length
            if kind == "weld" and m.eq_data[e, 10] > 0:
                worst = max(worst, 2 * float(np.arcsin(min(1.0, np.linalg.norm(pos[3:6]) / m.eq_data[e, 10]))))
        if worst > tol:
            return False
    return True


def named_configurations(m: Any, tree: Tree, length: float) -> dict[str, NamedConfiguration]:
    """``reference`` (MuJoCo's ``qpos0``) and each keyframe (its ``qpos``), as whole vectors; those that close first.

    A keyframe keeps its name (``key#k`` when unnamed); ``reference`` is ``#reference`` when a keyframe has
    that name. A keyframe that does not close as given is a start (``NamedConfiguration.start``): the analysis
    searches for a closed configuration from it; so is ``qpos0`` when it does not close and the file has
    keyframes (without keyframes the search starts from Pinocchio's neutral, MuJoCo's ``qpos0`` but for
    ``ref``).
    """
    model = tree.model
    keys = labels(m, "key", m.nkey)
    ref_name = "#reference" if "reference" in keys else "reference"
    vectors = [(name, m.key_qpos[k]) for k, name in enumerate(keys)] + [(ref_name, m.qpos0)]
    closed, starts = {}, {}
    for name, qpos in vectors[-1:] + vectors[:-1]:  # reference first among those that close, last among starts
        vector = tuple(qpos_to_q(model, qpos))
        if closes_at(m, qpos, length):
            closed[name] = NamedConfiguration(name, vector=vector)
        elif keys:
            starts[name] = NamedConfiguration(name, vector=vector, start=True)
    if ref_name in starts:
        starts[ref_name] = starts.pop(ref_name)  # the keyframes first: the file's author chose them
    return closed | starts


class Visuals:
    """The :class:`Geometry` loader of an MJCF: its visual geometry (:func:`pinmob.io.mjcf.mjcf_geometry.visual_geometry`).

    It builds from the model :func:`load_mjcf` compiled, held until the first draw (then dropped: the
    :class:`Geometry` keeps what it built), so drawing compiles nothing again. It pickles as its path (a
    Dask worker's copy holds no compiled model): a copy that draws compiles the file once.
    """

    def __init__(self, path: Path, compiled: Any = None) -> None:
        self.path, self._compiled = path, compiled

    def __call__(self, model: pin.Model) -> tuple[pin.GeometryModel | None, None]:
        """``(visual, None)`` for ``model`` (None when the file has no geom to draw)."""
        from pinmob.io.mjcf.mjcf_geometry import visual_geometry

        m, self._compiled = self._compiled, None
        if m is None:
            m = compile_mjcf(self.path, warn=False)  # load_mjcf warned
        geometry = confine(
            visual_geometry(m, build_tree(m, model.name), self.path), mesh_roots(self.path), self.path.name
        )
        return (geometry if geometry.ngeoms else None), None

    def __getstate__(self) -> dict[str, Any]:
        return {"path": self.path}

    def __setstate__(self, state: dict[str, Any]) -> None:
        self.path, self._compiled = state["path"], None


def load_mjcf(path: str | Path) -> Mechanism:
    """Load an MJCF file through MuJoCo's compiler: the tree, its equalities as closures, its actuated joints.

    Raises:
        MechanismFileError: MuJoCo cannot compile the file, an equality of an unsupported kind, or a
            tree pinmob cannot build (the message says which).
    """
    path = Path(path)
    m = compile_mjcf(path)
    check_bound("joints", int(m.njnt), f"mjcf {str(path)!r}")  # before anything builds a Pinocchio Data
    kinds = [_kind(m, e) for e in range(m.neq)]
    unsupported = sorted({k for k in kinds if k not in SUPPORTED})
    if unsupported:
        raise file_error(
            path,
            f"<equality> kind(s) {', '.join(f'<{t}>' for t in unsupported)} are not loop closures pinmob reads; "
            f"valid: {', '.join(f'<{t}>' for t in SUPPORTED)}",
        )
    name = bytes(m.names).split(b"\0", 1)[0].decode() or path.stem  # the model's name comes first
    try:
        check_labels(m)
        tree = build_tree(m, name)
    except ValueError as exc:
        raise file_error(path, str(exc)) from None
    inactive = [e for e in range(m.neq) if not m.eq_active0[e]]
    if inactive:
        names = ", ".join(label(m, "equality", e) for e in inactive)
        warnings.warn(f"{path.name}: equalities {names} are inactive (active=false): left out", stacklevel=2)
    closures = []
    kinematics = MujocoKinematics(m, tree.model)
    with errors_at(path):
        equalities = labels(m, "equality", m.neq)
        try:
            closures += [
                equality_closure(m, tree, e, equalities[e], kinematics) for e in range(m.neq) if m.eq_active0[e]
            ]
        except ValueError as exc:  # a closure's frame name taken (pinmob.io.mjcf.mjcf_names.add_frame)
            raise file_error(path, str(exc)) from None
        try:
            joints, tendons, adhesion = read_actuators(m, tree, kinematics)
        except ValueError as exc:  # an actuator of several outputs pinmob does not read
            raise file_error(path, str(exc)) from None
        if note := left_out(m, adhesion):
            warnings.warn(f"{path.name}: {note}", stacklevel=2)
        if not closures:
            raise file_error(path, "no active <connect>, <weld>, <joint> or <tendon> equality: no loop to analyse")
        mech = Mechanism.from_model(
            tree.model,
            [],
            name=name,
            actuated={"": list(dict.fromkeys(joint for _, joint in joints))},
            description=f"MJCF {path.name} (compiled by MuJoCo)",
            source=path,
            closures=closures,
            geometry=Geometry(Visuals(path, m)),
        )
    named = named_configurations(m, tree, mech.length_scale)
    left = tuple(f"inactive equality {label(m, 'equality', e)!r}" for e in inactive)  # warned above
    return replace(
        mech,
        configurations=named,
        quaternion_wxyz=True,
        actuated_tendons=tuple(tendons),
        joint_actuators=tuple(joints),
        ignored=left,
    )
