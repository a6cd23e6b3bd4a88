"""The compiled MuJoCo model asked at a Pinocchio configuration: tendon lengths, their rows, actuator moments.

MuJoCo's rows are on its ``qvel``; Pinocchio's on ``v``. They are the same for hinges, slides and ball
joints (a ball's rate is the angular velocity in the body frame in both); a free joint's linear rate is in
the world frame in MuJoCo and in the body frame in Pinocchio (``qvel_lin = R v_lin``), so its row is
turned by ``R^T`` (:meth:`MujocoKinematics.to_v`).
"""

from __future__ import annotations

import threading
from typing import Any

import numpy as np
import pinocchio as pin

from pinmob.io.mjcf.mjcf_tree import FREE, q_to_qpos
from pinmob.screw import Array


class MujocoKinematics:
    """The compiled MuJoCo model asked for tendon lengths, tendon Jacobians and actuator moments at a q.

    Each thread has its own ``MjData`` (made once), recomputed when q changes: ``mj_kinematics``,
    ``mj_comPos``, ``mj_tendon`` and ``mj_transmission``. Pickles (a Dask worker's copy) with the model.
    """

    def __init__(self, m: Any, model: pin.Model) -> None:
        self.m = m
        self.model = model
        self._init()

    def _init(self) -> None:
        m, model = self.m, self.model
        self._local = threading.local()
        self._perm = np.zeros(m.nv, int)  # MuJoCo dof -> Pinocchio velocity index
        self._free: list[tuple[int, int]] = []  # (velocity index, q index of the quaternion) per free joint
        for j in range(m.njnt):
            joint = model.joints[j + 1]  # one Pinocchio joint per MuJoCo joint, in MuJoCo's order
            adr = int(m.jnt_dofadr[j])
            self._perm[adr : adr + joint.nv] = np.arange(joint.idx_v, joint.idx_v + joint.nv)
            if int(m.jnt_type[j]) == FREE:
                self._free.append((joint.idx_v, joint.idx_q + 3))

    def __getstate__(self) -> dict[str, Any]:
        return {"m": self.m, "model": self.model}

    def __setstate__(self, state: dict[str, Any]) -> None:
        self.m, self.model = state["m"], state["model"]
        self._init()

    def at(self, q: Array) -> Any:
        """This thread's ``MjData`` with the positions, tendons and transmissions of q (Pinocchio's)."""
        import mujoco

        local = self._local
        if getattr(local, "data", None) is None:
            local.data, local.q = mujoco.MjData(self.m), None
        d = local.data
        if local.q is None or not np.array_equal(local.q, q):
            d.qpos[:] = q_to_qpos(self.model, q)
            for step in (mujoco.mj_kinematics, mujoco.mj_comPos, mujoco.mj_tendon, mujoco.mj_transmission):
                step(self.m, d)
            local.q = np.array(q, float)
        return d

    def to_v(self, row_qvel: Array, q: Array) -> Array:
        """(nv,) a row on MuJoCo's ``qvel`` as a row on Pinocchio's ``v`` at q (see the module docstring)."""
        row = np.zeros(self.model.nv)
        row[self._perm] = row_qvel
        for v, iq in self._free:
            rot = pin.Quaternion(np.array(q[iq : iq + 4], float)).normalized().toRotationMatrix()  # (x, y, z, w)
            row[v : v + 3] = rot.T @ row[v : v + 3]
        return row

    def sparse_row(self, values: Array, nnz: int, adr: int, colind: Array) -> Array:
        """(nv,) a dense row on ``qvel`` from MuJoCo's compressed storage."""
        out = np.zeros(self.m.nv)
        out[np.asarray(colind[adr : adr + nnz], int)] = values[adr : adr + nnz]
        return out

    def moment_row(self, out: int, q: Array) -> Array:
        """(nv,) MuJoCo's ``actuator_moment`` row of output ``out`` at q, on Pinocchio's ``v``."""
        d = self.at(np.asarray(q, float))
        row = self.sparse_row(d.actuator_moment, int(d.moment_rownnz[out]), int(d.moment_rowadr[out]), d.moment_colind)
        return self.to_v(row, q)
