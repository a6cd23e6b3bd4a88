"""What a scene shows, computed before meshcat is touched: the closed configuration, its analysis, the motions.

:func:`prepare` closes the configuration, shows a mechanism without a platform by its output frame that moves
most (:func:`viewed_frame`), analyses it (:func:`pinmob.analyze`:
the platform's mobility, the singularity report and the whole mechanism's
mobility, for the panel's words), follows each free motion
(:func:`pinmob.analysis.follow.motion_path.follow_motion`), reporting progress, and
tells each motion's finite-mobility verdict (:mod:`pinmob.analysis.finite.finite_mobility`). Every
error a bad argument can cause happens here, before any server is started.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
import pinocchio as pin

from pinmob.analysis import (
    Configuration,
    MechanismMobility,
    MinimalClosures,
    Mobility,
    MotionPath,
    Report,
    Singularity,
    analyze,
    as_configuration,
    branch_point_name,
    finite_mobility,
    follow_motion,
)
from pinmob.exceptions import ConfigurationError, PinmobError, ViewerError
from pinmob.model import Mechanism, frame_id
from pinmob.name_matching import match_name
from pinmob.progress import step
from pinmob.screw import RTOL
from pinmob.viewer.options import ViewOptions

Array = np.ndarray


@dataclass(frozen=True)
class Prepared:
    """What a scene shows, computed before meshcat is touched (:func:`prepare`).

    Attributes:
        mechanism: the mechanism shown: the one given, or, for one without a platform, a copy whose platform is
            the output frame shown (:func:`viewed_frame`).
        options: the scene's options.
        q: (nq,) the closed configuration.
        mobility: the platform's mobility there.
        paths: the followed motions, by label.
        motion: the motion shown first (its label as the analysis spells it), or None.
        singularity: the singularity report (None where it does not apply).
        chain: the whole mechanism's mobility (None when it could not be computed).
        branch_point: where motion branches meet at q, their DoF and the platform's motion type on each
            (:func:`pinmob.analysis.finite.branches.branch_point_name`; None elsewhere, or without verdicts).
        output_frame: that output frame's name (None: the mechanism's own platform is shown).
        note: why that frame is shown ("" for a mechanism with a platform).
        minimal: the minimal closures (None where no closure equation is redundant, or not computed).
    """

    mechanism: Mechanism
    options: ViewOptions
    q: Array
    mobility: Mobility
    paths: dict[str, MotionPath]
    motion: str | None
    singularity: Singularity | None
    chain: MechanismMobility | None
    branch_point: str | None = None
    output_frame: str | None = None
    note: str = ""
    minimal: MinimalClosures | None = None


def viewed_frame(mech: Mechanism, state: Configuration | Array | str) -> tuple[Mechanism, Configuration, str]:
    """The mechanism and closed configuration to show: without a platform, its output frame that moves most.

    The outputs are those of the analysis (the tree's free leaf bodies), else every moving body; the
    one with the most DoF (the deepest in the tree among equals) becomes the platform of a copy of the
    mechanism, and the note says so.

    Raises:
        ConfigurationError: a mechanism without a platform that has no moving body.
        ClosureError: the configuration does not close.
    """
    conf = as_configuration(mech, state)
    if mech.has_platform:
        return mech, conf, ""
    frames = analyze(conf, closure_tol=conf.closure_tol).mechanism_mobility.frames
    if not frames:
        bodies = [f.name for f in mech.model.frames if f.type == pin.FrameType.BODY and f.parentJoint > 0]
        frames = analyze(conf, closure_tol=conf.closure_tol, frames=bodies).mechanism_mobility.frames
    if not frames:
        raise ConfigurationError(f"{mech.name!r} has no platform and no moving body to show")
    model = mech.model
    best = max(frames, key=lambda f: (f.dof, model.frames[frame_id(model, f.frame)].parentJoint))
    viewed = replace(mech, platform=best.frame)
    conf = Configuration.from_checked(viewed, conf.q, conf.closure_tol, name=conf.name, source=conf.source)
    note = (
        f"{mech.name!r} names no platform: showing the motions of its output frame {best.frame!r} "
        f"({best.dof} DoF of the mechanism's outputs)"
    )
    return viewed, conf, note


def prepare(
    mech: Mechanism,
    q: Array | str | Configuration,
    mobility: Mobility | Report | None,
    options: ViewOptions,
) -> Prepared:
    """Closed q, its analysis and the followed motions (everything that can fail before meshcat).

    A mechanism without a platform is shown by its output frame that moves most (:func:`viewed_frame`; the
    mobility given, if any, is then not used). With ``options.finite`` (and a platform), each path carries its
    motion's verdict from
    :func:`pinmob.analysis.finite.finite_mobility.finite_mobility`: a motion that exists only to first order is then
    drawn as such by :func:`pinmob.viewer.scene.build` and the panel's verdict column says so.

    Raises:
        ConfigurationError: ``motion`` is not the label of a free motion at q (matched ignoring case).
        ClosureError: q does not close.
    """
    motion, animate = options.motion, options.animate
    shown, conf, note = viewed_frame(mech, q)
    if shown is not mech:
        mobility = None
    given = mobility if isinstance(mobility, Report) and np.array_equal(mobility.state.q, conf.q) else None
    report = given or analyze(conf, rtol=RTOL)  # a Report at q: its answers, not a second analysis
    if isinstance(mobility, Report):  # the whole report given: its platform mobility
        mobility = mobility.mobility
    mob = mobility if mobility is not None else report.mobility
    if mob is None:
        raise ViewerError(f"{mech.name!r} has no platform frame: the viewer shows a platform's free motions")
    mech = shown
    if motion is not None:
        motion = match_name(motion, [m.label for m in mob.motions], "free motion", " at this configuration")
    paths = {}
    with step(f"following the free motions of {mech.name}", total=len(mob.motions) if animate else 0) as bar:
        for m in mob.motions:
            bar.set_postfix_str(m.label)
            if animate:
                paths[m.label] = follow_motion(mech, conf, m, amplitude=options.amplitude, steps=options.steps)
                bar.update()
            else:
                paths[m.label] = MotionPath(m.label, (conf.q,), (conf.q,), (0.0, 0.0), 0.0)
    branch_point = None
    if options.finite and mech.has_platform and mob.motions:
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
        minimal = report.minimal_closures
    except PinmobError:
        chain, sing, minimal = None, None, None
    output = None if not note else mech.platform
    return Prepared(mech, options, conf.q, mob, paths, motion, sing, chain, branch_point, output, note, minimal)
