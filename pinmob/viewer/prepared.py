"""What a scene shows, computed before meshcat is touched: the closed configuration, its analysis, the motions.

:func:`prepare` closes the configuration, analyses it (:func:`pinmob.analyze`:
the platform's mobility, the singularity report and the whole mechanism's
mobility, for the panel's words), follows each free motion
(:func:`pinmob.analysis.follow.motion_path.follow_motion`), reporting progress, and
tells each motion's finite-mobility verdict (:mod:`pinmob.analysis.finite.finite_mobility`). Every
error a bad argument can cause happens here, before any server is started.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from pinmob.analysis.chain.mechanism_mobility import MechanismMobility
from pinmob.analysis.configuration import Configuration, as_configuration
from pinmob.analysis.entry_point import analyze
from pinmob.analysis.finite.branch_names import branch_point_name
from pinmob.analysis.finite.finite_mobility import finite_mobility
from pinmob.analysis.follow.motion_path import MotionPath, follow_motion
from pinmob.analysis.mobility import Mobility
from pinmob.analysis.report import Report
from pinmob.analysis.singularity.result import Singularity
from pinmob.exceptions import PinmobError, ViewerError
from pinmob.model.mechanism import Mechanism
from pinmob.name_matching import match_name
from pinmob.progress import step
from pinmob.screw.rank import RTOL

Array = np.ndarray


@dataclass(frozen=True)
class Prepared:
    """What a scene shows, computed before meshcat is touched (:func:`prepare`).

    Attributes:
        q: (nq,) the closed configuration.
        mobility: the platform's mobility there.
        paths: the followed motions, by label.
        motion: the motion shown first (its label as the analysis spells it), or None.
        singularity: the singularity report (None where it does not apply).
        chain: the whole mechanism's mobility (None when it could not be computed).
        branch_point: where motion branches meet at q, their DoF and the platform's motion type on each
            (:func:`pinmob.analysis.finite.branch_names.branch_point_name`; None elsewhere, or without verdicts).
    """

    q: Array
    mobility: Mobility
    paths: dict[str, MotionPath]
    motion: str | None
    singularity: Singularity | None
    chain: MechanismMobility | None
    branch_point: str | None = None


def prepare(
    mech: Mechanism,
    q: Array | str | Configuration,
    mobility: Mobility | Report | None,
    amplitude: float | None,
    steps: int,
    animate: bool,
    motion: str | None = None,
    finite: bool = True,
) -> Prepared:
    """Closed q, its analysis and the followed motions (everything that can fail before meshcat).

    With ``finite`` (and a platform), each path carries its motion's verdict from
    :func:`pinmob.analysis.finite.finite_mobility.finite_mobility`: a motion that exists only to first order is then
    drawn as such by :func:`pinmob.viewer.scene.build` and the panel's verdict column says so.

    Raises:
        ConfigurationError: ``motion`` is not the label of a free motion at q (matched ignoring case).
        ClosureError: q does not close.
    """
    conf = as_configuration(mech, q)
    given = mobility if isinstance(mobility, Report) and np.array_equal(mobility.state.q, conf.q) else None
    report = given or analyze(conf, rtol=RTOL)  # a Report at q: its answers, not a second analysis
    if isinstance(mobility, Report):  # the whole report given: its platform mobility
        mobility = mobility.mobility
    mob = mobility if mobility is not None else report.mobility
    if mob is None:
        raise ViewerError(f"{mech.name!r} has no platform frame: the viewer shows a platform's free motions")
    if motion is not None:
        motion = match_name(motion, [m.label for m in mob.motions], "free motion", " at this configuration")
    paths = {}
    with step(f"following the free motions of {mech.name}", total=len(mob.motions) if animate else 0) as bar:
        for m in mob.motions:
            bar.set_postfix_str(m.label)
            if animate:
                paths[m.label] = follow_motion(mech, conf, m, amplitude=amplitude, steps=steps)  # conf: checked
                bar.update()
            else:
                paths[m.label] = MotionPath(m.label, (conf.q,), (conf.q,), (0.0, 0.0), 0.0)
    branch_point = None
    if finite and mech.has_platform and mob.motions:
        fm = finite_mobility(conf, RTOL, motions=mob.motions)
        branch_point = branch_point_name(fm.free.branches)
        verdicts = {v.label: v for v in fm.motions}
        for label, path in paths.items():
            v = verdicts.get(label)
            if v is not None:
                paths[label] = replace(path, finite=v.finite, verdict=v.words())
    try:  # the panel's words; a mechanism whose singularity classes cannot be estimated is still shown
        chain: MechanismMobility | None = report.mechanism_mobility
        sing = report.singularity
    except PinmobError:
        chain, sing = None, None
    return Prepared(conf.q, mob, paths, motion, sing, chain, branch_point)
