"""The information panel over the 3D view: the analysis in words, as a document the page's script lays out.

:func:`panel_document` gathers what the panel says (plain JSON: numbers raw,
sentences ready): the mechanism and configuration, the platform's DoF and
motion type, one row per free motion (kind, direction, axis point in world
coordinates [m], pitch [m/rad], how far its clip went and why it stopped, and a
finite/instantaneous ``verdict`` column shown when one is given), the motion
branches meeting at q (named, when given), the singularity class, the whole mechanism's DoF, the constraint wrenches, the
legend, and the glyphs' labels (their world anchors). :class:`PanelCommand`
carries it to the page as pinmob's ``pinmob_panel`` command, which
``static/panel.js`` understands (see :mod:`pinmob.viewer.page`).
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np

from pinmob.analysis import KIND_WORDS, MechanismMobility, MinimalClosures, Mobility, MotionPath, Singularity, vector
from pinmob.screw import MotionKind
from pinmob.viewer.glyphs import (
    COUPLE_COLOR,
    FORCE_COLOR,
    INSTANTANEOUS_COLOR,
    ROTATION_COLOR,
    TRANSLATION_COLOR,
    Glyph,
    pitch_color,
)
from pinmob.viewer.world import AXIS_COLORS, GRID_COLOR, WorldFrame

#: the pinmob command carrying the panel (the page's script handles it)
COMMAND = "pinmob_panel"


class PanelCommand:
    """The ``pinmob_panel`` command: the panel's document, sent like meshcat's own commands."""

    def __init__(self, document: dict[str, Any]):
        self.document = document

    def lower(self) -> dict[str, Any]:
        """The command as meshcat's commands are sent (a dictionary packed with msgpack)."""
        return {"type": COMMAND, "path": "", "document": self.document}


def hex_color(color: int) -> str:
    """``#rrggbb`` of a 0xRRGGBB colour."""
    return f"#{color:06x}"


def _reason(note: str) -> str:
    """The cause in a stop note, short: the limbs at the edge of their workspace, else the step's failure.

    Prefixed ``forwards,`` or ``backwards,`` when one direction stopped.
    """
    why = note.split(": ", 1)[1] if ": " in note else note
    sign = (
        "forwards, " if why.startswith("stopped forwards") else "backwards, " if why.startswith("stopped back") else ""
    )
    if why.startswith("stopped ") and ": " in why:  # "stopped forwards after 0.02 rad of 0.35: <why>"
        why = why.split(": ", 1)[1]
    why = why.removeprefix("cannot be followed either way from here: ")
    why = why.split("; the mobility found there is only instantaneous")[0]
    return sign + (why.split(", so ")[0] if why.startswith("limb") else why.split(" (also with steps")[0])


def _clip(path: MotionPath, unit: str) -> tuple[str, str, list[str], list[str]]:
    """(status, what the clip does, why it stops in short, the full stop notes) of one followed motion."""
    if path.amplitude == 0.0:
        return "static", "not followed (a still scene)", [], []
    amp = f"{path.amplitude:.3g} {unit}"
    notes = [note.split(": ", 1)[1] if ": " in note else note for note in path.notes]
    why = [_reason(note) for note in path.notes]
    if path.complete:
        return "full", f"moves the whole amplitude, +/- {amp}", [], []
    if path.reached == (0.0, 0.0):
        return "still", "stays still: this motion exists only to first order here (instantaneous)", why, notes
    reached = f"+{path.reached[0]:.3g} / -{path.reached[1]:.3g} {unit}"
    return "partial", f"stops early: {reached} of +/- {amp}", why, notes


def motion_rows(
    mob: Mobility, paths: Mapping[str, MotionPath], verdicts: Mapping[str, str] | None = None
) -> list[dict[str, Any]]:
    """One row per free motion: label, kind, direction, world axis point [m], pitch, clip, why, verdict."""
    rows = []
    for m in mob.motions:
        unit = "m" if m.kind is MotionKind.TRANSLATION else "rad"
        status, text, why, notes = _clip(paths[m.label], unit)
        color = {MotionKind.TRANSLATION: TRANSLATION_COLOR, MotionKind.ROTATION: ROTATION_COLOR}.get(
            m.kind, pitch_color(float(m.pitch or 0.0), mob.length_scale)
        )
        if paths[m.label].finite is False:  # drawn grey: it exists only to first order
            color = INSTANTANEOUS_COLOR
        rows.append(
            {
                "label": m.label,
                "kind": m.kind.value,
                "kind_word": KIND_WORDS[m.kind],
                "direction": vector(m.direction),
                "point": vector(m.world_point(mob.platform_origin, mob.length_scale)),
                "pitch": m.pitch,
                "unit": unit,
                "amplitude": paths[m.label].amplitude,
                "reached": list(paths[m.label].reached),
                "status": status,
                "clip_text": text,
                "why": why,
                "notes": notes,
                "verdict": (verdicts or {}).get(m.label),
                "color": hex_color(color),
            }
        )
    return rows


def answer(mob: Mobility) -> dict[str, Any]:
    """The platform's DoF and motion type, and the type in words (``1 translation, 1 rotation``)."""
    counts = [(mob.translations, "translation"), (mob.rotations, "rotation"), (mob.screws, "screw")]
    words = ", ".join(f"{n} {w}{'s' if n > 1 else ''}" for n, w in counts if n)
    return {"dof": mob.dof, "motion_type": mob.motion_type, "words": words or "it cannot move"}


def singularity_text(sing: Singularity | None, subject: str = "the platform") -> str:
    """The singularity class in words (``subject``: what moves, the platform or the output frame shown)."""
    if sing is None:
        return "not analysed (the limb-wise singularity classes do not apply to this mechanism)."
    closest = sing.closest_all
    if not sing.classes:
        state = "near a singularity" if sing.near_singular else "none here"
        return (
            f"{state} (distance {sing.distance:.3g} to the closest, {', '.join(closest)}; "
            "0 = singular, 1 = best conditioned)."
        )
    parts = []
    if sing.limbs:
        parts.append(
            f"limb{'s' if len(sing.limbs) > 1 else ''} {', '.join(sing.limbs)} at a serial singularity "
            "(Type I: stretched or folded, at the edge of its workspace)"
        )
    if sing.actuation:
        unc = ", ".join(m.label for m in sing.uncontrolled) or "-"
        parts.append(f"actuation singularity (Type II): with the actuators locked {subject} can still move ({unc})")
    if sing.constraint:
        parts.append(
            f"constraint singularity: constraint rank {sing.constraint_rank} below its generic {sing.generic_rank} "
            f"(dependent limbs {', '.join(sing.dependent_limbs) or '-'})"
        )
    return f"{sing.label.replace('+', ' + ')}: " + "; ".join(parts) + "."


def mechanism_text(chain: MechanismMobility | None, mob: Mobility, subject: str = "the platform") -> str:
    """The whole mechanism's DoF, and how it splits into ``subject``'s (the platform's) and the internal motions."""
    if chain is None:
        return "not analysed."
    internal = chain.internal_dof
    if not internal:
        return f"{chain.mechanism_dof} DoF: every motion of the mechanism moves {subject}."
    return (
        f"{chain.mechanism_dof} DoF = {subject}'s {mob.dof} + {internal} internal motion(s): joints moving while "
        f"{subject} stays still ({chain.idle_dof} of them idle: moving no actuated joint, joint centre or closure point)."
    )


def legend(
    mob: Mobility, world: WorldFrame, generated: bool, instantaneous: bool = False, subject: str = "the platform"
) -> list[dict[str, str]]:
    """Every glyph shape and colour in the scene, in words.

    ``instantaneous``: some motion is only first order; ``subject``: what moves, the platform or the output frame.
    """
    items = [
        {"icon": "→", "color": hex_color(TRANSLATION_COLOR), "text": "translation: blue arrow (a free vector: the "
         f"arrows start together beside the origin of {subject})"},
        {"icon": "⟳", "color": hex_color(ROTATION_COLOR), "text": "rotation: orange axis line through the axis "
         "point, ring arrow = positive sense (right hand)"},
    ]  # fmt: skip
    if instantaneous:
        items.append({"icon": "◌", "color": hex_color(INSTANTANEOUS_COLOR), "text": "grey, half transparent, "
                      "pulsing: a motion that exists only to first order (its clip cannot move the mechanism)"})  # fmt: skip
    if mob.screws:
        items.append({"icon": "∿", "color": hex_color(pitch_color(0.0, 1.0)), "text": "screw: axis and helix, "
                      "coloured by pitch (blue < 0, grey 0, red > 0)"})  # fmt: skip
    items += [
        {"icon": "↦", "color": hex_color(FORCE_COLOR), "text": "constraint force: red arrow on its line of action"},
        {"icon": "⇉", "color": hex_color(COUPLE_COLOR), "text": "constraint couple: purple double arrow (free vector)"},
        {"icon": "┼", "color": hex_color(AXIS_COLORS[0]), "text": f"world axes x (red), y (green), z (blue) at the "
         f"world origin; grey grid: {world.spacing:g} m squares in the plane z = 0"},
    ]  # fmt: skip
    if generated:
        items.append({"icon": "●", "color": "#f29a1a", "text": f"orange disc: {subject}; grey bars: the base "
                      "(a stick figure: the URDF has no visuals)"})  # fmt: skip
    return items


def glyph_labels(glyphs: list[tuple[str, list[str], Glyph]], world: WorldFrame, world_path: list[str]) -> list[dict]:
    """Every label drawn in the scene: (group, meshcat path, glyph) of each glyph, and the world frame's."""
    out = [
        {"group": group, "label": g.name, "path": path, "anchor": vector(g.anchor), "color": hex_color(g.color)}
        for group, path, g in glyphs
    ]
    for name, point in world.anchors.items():
        color = AXIS_COLORS["xyz".index(name)] if name in "xyz" and len(name) == 1 else GRID_COLOR
        out.append({"group": "world", "label": name, "path": world_path, "anchor": vector(point),
                    "color": hex_color(color if name != "world origin" else 0x444444)})  # fmt: skip
    return out


def panel_document(
    mech_name: str,
    mob: Mobility,
    paths: Mapping[str, MotionPath],
    *,
    singularity: Singularity | None,
    chain: MechanismMobility | None,
    glyphs: list[tuple[str, list[str], Glyph]],
    world: WorldFrame,
    paths_of: dict[str, list[str]],
    clips: dict[str, Any],
    visible: str | None,
    wrenches: bool,
    generated: bool,
    verdicts: Mapping[str, str] | None = None,
    branch_point: str | None = None,
    output_frame: str | None = None,
    minimal: MinimalClosures | None = None,
) -> dict[str, Any]:
    """The panel's document (plain JSON); see the module docstring.

    Args:
        mech_name: the mechanism's name.
        mob: the platform's mobility shown.
        paths: the followed motions, by label.
        singularity: the singularity report (None where it does not apply).
        chain: the whole mechanism's mobility (None when not analysed).
        glyphs: (group ``motion`` or ``wrench``, meshcat path, glyph) of every glyph drawn.
        world: the world axes and grid drawn.
        paths_of: the meshcat paths of the ``world`` and ``wrenches`` groups (shown or hidden together).
        clips: the lowered animation clip of each motion, by label.
        visible: the motion playing on opening.
        wrenches: the constraint wrenches are shown on opening.
        generated: the mechanism is drawn as a generated stick figure.
        verdicts: a finite/instantaneous verdict per motion label, shown as a column when given.
        branch_point: the motion branches meeting at q, named (a line of the summary), or None.
        output_frame: the output frame shown in place of a platform (None: the mechanism's platform); the panel
            names what moves by it.
        minimal: the minimal closures (:mod:`pinmob.analysis.minimal`), shown as lines under the whole
            mechanism (``minimal_closures``: None where no closure equation is redundant).
    """
    subject = "the platform" if output_frame is None else f"the output frame {output_frame!r}"
    where = f" at '{mob.configuration}'" if mob.configuration else ""
    summary = ["Axis points are in world coordinates [m]; the world origin and axes are drawn in the scene."]
    centre = mob.rotation_centre
    if centre is not None:
        summary.append(
            f"The {mob.rotations} rotation axes meet at ({', '.join(f'{x:.4g}' for x in centre + 0.0)}) m: "
            f"{subject} turns about that point."
        )
    if branch_point:
        summary.append(f"Motion branches meet here: {branch_point} ({subject}'s DoF and motion type on each).")
    if generated:
        summary.append("The mechanism is drawn as a stick figure (its URDF has no visuals).")
    constraints = [
        {"name": f"{c.kind.value} {i + 1}", "kind": c.kind.value, "direction": vector(c.direction),
         "point": vector(c.world_point(mob.platform_origin, mob.length_scale)), "pitch": c.pitch,
         "color": hex_color(COUPLE_COLOR if c.kind.value == "couple" else FORCE_COLOR)}
        for i, c in enumerate(mob.constraints)
    ]  # fmt: skip
    return {
        "title": f"{mech_name}{where}",
        "answer": answer(mob),
        "summary": summary,
        "motions": motion_rows(mob, paths, verdicts),
        "subject": subject,
        "singularity": singularity_text(singularity, subject),
        "mechanism": mechanism_text(chain, mob, subject),
        "minimal_closures": None if minimal is None else str(minimal).splitlines(),
        "constraints": constraints,
        "constraint_rank": mob.constraint_rank,
        "wrenches_drawn": bool(wrenches),
        "wrench_path": paths_of["wrenches"],
        "world": {"path": paths_of["world"], "visible": True, "spacing": world.spacing},
        "glyphs": glyph_labels(glyphs, world, paths_of["world"]),
        "legend": legend(mob, world, generated, any(p.finite is False for p in paths.values()), subject),
        "clips": clips,
        "visible": visible,
        "length_scale": float(mob.length_scale),
        "platform_origin": vector(np.asarray(mob.platform_origin)),
        "footer": "pinmob: terms explained by the command pinmob glossary [TERM]. Play, pause and time: Open Controls > Animations.",
    }
