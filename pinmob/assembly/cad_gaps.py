"""CAD gaps held: the mechanism whose loops close exactly at a configuration that closes them only to CAD accuracy.

A file exported from CAD closes its loops only to about a micron (``--closure-tol``, Python ``closure_tol``):
at its reference configuration ``q_ref`` each loop misses by a small *gap*. A solver polishing every sample
of a scan to round-off would close the gaps elsewhere, by moving joints (a 3-PUU whose tip frame C is
turned by 1e-5 rad closes exactly with limb C turned by about 1e-5 rad, where the mobility decided at the
residual's tolerance is 2T1R, not the 3T of ``q_ref``): another geometry than the one analysed at ``q_ref``.

Holding the gaps instead: each loop's gap at ``q_ref`` is taken into the placement of one of its frames
(:func:`frame_gaps`), so that the mechanism so corrected (:func:`gaps_closed`) closes exactly at ``q_ref``;
its samples are assembled (and polished) on it, and analysed on the mechanism as the file gives it, at the
closure tolerance (each keeps the gaps of ``q_ref``, exactly when they are a fixed offset of a frame).

* a limb tip: its placement ``jM_tip`` becomes ``jM_tip G^-1``, ``G = oM_platform^-1 oM_tip`` at ``q_ref``;
* a ``6d``, ``revolute``, ``cylindrical``, ``prismatic``, ``planar``, ``planar_weld``, ``orientation``,
  ``parallel_axes`` or ``perpendicular`` closure: frame b's placement becomes ``jM_b G^-1``,
  ``G = oM_a^-1 oM_b`` (b then coincides with a at ``q_ref``; a rotation about a hinge's axis is allowed
  anyway);
* a ``3d``, ``universal``, ``inline`` or ``inplane`` closure: frame b's origin moves onto frame a's at ``q_ref`` (a universal's
  angle condition keeps its gap);
* a coupling of joints or tendons has no frame to move: it keeps its gap.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pinocchio as pin

from pinmob.assembly.residual import check_closed
from pinmob.model import Mechanism, borrowed
from pinmob.screw import Array

#: Frame placements that hold a configuration's gaps: (frame index, its 12 numbers: rotation row by row,
#: then translation), hashable (a key of the mechanism's cache, and picklable with a scan's spec).
Gaps = tuple[tuple[int, tuple[float, ...]], ...]

#: Closure types whose gap is a relative pose (``log6``), and those whose gap is a distance between origins.
_POSE_TYPES = (
    "6d",
    "revolute",
    "cylindrical",
    "prismatic",
    "planar",
    "planar_weld",
    "orientation",
    "parallel_axes",
    "perpendicular",
)
_POINT_TYPES = ("3d", "universal", "inline", "inplane")


def frame_gaps(mech: Mechanism, q: Array, closure_tol: float) -> Gaps:
    """The frame placements (in their parent joints' frames) that close every loop of ``mech`` exactly at q.

    See the module docstring for which frame of each loop moves. A loop already closed to round-off gives
    (almost) its own placement back.

    Raises:
        ClosureError: q does not close within ``closure_tol``: its misses are not CAD gaps but open loops.
    """
    check_closed(mech, q, closure_tol, what="the configuration whose CAD gaps a scan holds")
    model = mech.model
    out: dict[int, pin.SE3] = {}
    with borrowed(model) as data:
        pin.framesForwardKinematics(model, data, mech.check_q(q))
        if mech.has_platform:
            platform = data.oMf[mech.platform_id]
            for limb in mech.limbs:
                if limb.tip_id != mech.platform_id:
                    gap = platform.actInv(data.oMf[limb.tip_id])
                    out[limb.tip_id] = model.frames[limb.tip_id].placement * gap.inverse()
        for c in mech.closures:
            a, b = data.oMf[c.frame_a_id], data.oMf[c.frame_b_id]
            placement = pin.SE3(model.frames[c.frame_b_id].placement)
            if c.type in _POSE_TYPES:
                out[c.frame_b_id] = placement * a.actInv(b).inverse()
            elif c.type in _POINT_TYPES:
                joint = data.oMi[model.frames[c.frame_b_id].parentJoint]
                placement.translation = joint.actInv(a.translation)
                out[c.frame_b_id] = placement
    return tuple((f, tuple(float(x) for x in (*m.rotation.ravel(), *m.translation))) for f, m in sorted(out.items()))


def gaps_closed(mech: Mechanism, gaps: Gaps) -> Mechanism:
    """``mech`` with the frame placements ``gaps`` (:func:`frame_gaps`): ``mech`` itself when there are none.

    A copy of the model (the file's model is not changed), made once per mechanism and gaps (its cache).
    """
    if not gaps:
        return mech

    def corrected() -> Mechanism:
        model = pin.Model(mech.model)
        for f, numbers in gaps:
            frame = model.frames[f]
            frame.placement = pin.SE3(np.reshape(numbers[:9], (3, 3)), np.array(numbers[9:]))
            model.frames[f] = frame
        return replace(mech, model=model)

    return mech.memo(("cad gaps held", gaps), corrected)
