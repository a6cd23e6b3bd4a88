"""Following a free motion of the platform with the whole mechanism closed.

:mod:`~pinmob.analysis.follow.motion_path` (:class:`MotionPath`, :func:`follow_motion`) walks both ways with
the predictor-corrector of :mod:`~pinmob.analysis.follow.path_follower`, measures each step by
:mod:`~pinmob.analysis.follow.displacement`, and :mod:`~pinmob.analysis.follow.motion_limits` says what stops it.
"""

#: Continuation steps per direction of :func:`~pinmob.analysis.follow.motion_path.follow_motion` by default (and of
#: the viewers' animations, ``pinmob show --steps``).
STEPS = 12
