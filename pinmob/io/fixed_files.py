"""Writing a mechanism file again with other closures, in its own format (``pinmob fix``).

Plain data in (the input's document as the caller read it, or the MJCF file, and the mechanism to write), text
out; the caller checks the target (:func:`pinmob.output_files.check_target`) and writes it through
:class:`pinmob.output_files.Replacing`.

- pinmob TOML: the input's document with ``[[limbs]]``, ``[[closures]]`` and ``actuated`` taken from the
  mechanism, ``urdf`` made relative to the output's folder and ``length_scale`` the input's L (other frames
  would give another), each pose configuration seeded with the joint values the input closes there
  (:func:`fixed_toml`); comments are not kept.
- Extended URDF: the YAML sidecar with its ``type`` per loop, and, for pinmob's own closure types beyond
  ``6d`` / ``3d``, ``axis`` / ``axis_b`` per loop (``null`` where a type has none) and ``urdf`` (the URDF beside
  the input): keys that pinmob reads and the LAAS tools do not (:func:`fixed_sidecar`).
- MJCF: the input's XML with each ``<weld>`` named by ``connects`` turned into a ``<connect>`` at the weld's
  point (:func:`fixed_mjcf`); MuJoCo has no equality with the other kinds.
"""

from __future__ import annotations

import os
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from pinmob.exceptions import MechanismFileError
from pinmob.io.schema import file_error, toml_key, toml_string, unicode_text
from pinmob.model import Closure, Mechanism


def _vector(v: Any) -> list[float]:
    return [float(f"{x:.15g}") + 0.0 for x in np.asarray(v, float)]


def closure_table(c: Closure) -> dict[str, Any]:
    """A ``[[closures]]`` table: name, frames, type, and the axes its type has."""
    out: dict[str, Any] = {"name": c.name, "frames": [c.frame_a, c.frame_b], "type": str(c.type)}
    if c.axis is not None:
        out["axis"] = _vector(c.axis)
    if c.axis_b is not None:
        out["axis_b"] = _vector(c.axis_b)
    return out


def _toml_value(value: Any) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, str):
        return toml_string(value)
    if isinstance(value, (int, float)):
        return repr(value)
    if isinstance(value, list):
        return "[" + ", ".join(_toml_value(v) for v in value) + "]"
    if isinstance(value, Mapping):
        return "{ " + ", ".join(f"{toml_key(k)} = {_toml_value(v)}" for k, v in value.items()) + " }"
    raise TypeError(f"no TOML for {value!r}")


def toml_document(doc: Mapping[str, Any]) -> str:
    """A mechanism file's document as TOML text: scalars and lists, then ``[[limbs]]``, ``[[closures]]``, tables.

    A top-level table is written as ``[k]`` with its plain values, then ``[k.name]`` per sub-table (deeper tables
    inline), so a TOML parser reads back ``doc``.
    """
    lines = []
    tables = {k: v for k, v in doc.items() if isinstance(v, Mapping)}
    arrays = {k: v for k, v in doc.items() if isinstance(v, list) and v and all(isinstance(x, Mapping) for x in v)}
    for k, v in doc.items():
        if k not in tables and k not in arrays:
            lines.append(f"{toml_key(k)} = {_toml_value(v)}")
    for k, items in arrays.items():
        for item in items:
            lines += ["", f"[[{toml_key(k)}]]"] + [f"{toml_key(a)} = {_toml_value(b)}" for a, b in item.items()]
    for k, table in tables.items():
        plain = {a: b for a, b in table.items() if not isinstance(b, Mapping)}
        if plain or not table:  # one [k] header for all its plain values (TOML defines a table once); [k] if empty
            lines += ["", f"[{toml_key(k)}]"] + [f"{toml_key(a)} = {_toml_value(b)}" for a, b in plain.items()]
        for name, sub in table.items():
            if isinstance(sub, Mapping):
                lines += ["", f"[{toml_key(k)}.{toml_key(name)}]"] + [
                    f"{toml_key(a)} = {_toml_value(b)}" for a, b in sub.items()
                ]
    return "\n".join(lines) + "\n"


def fixed_toml(source: Path, document: Mapping[str, Any], fixed: Mechanism, target: Path) -> str:
    """The TOML text of ``fixed``, read from ``source`` (pinmob TOML) and written at ``target``.

    ``document``: ``source``'s, as :func:`pinmob.io.read_toml` reads it (the caller reads the file once; it is not
    changed).

    Raises:
        ConfigurationError: text no TOML can hold (a lone surrogate, :func:`pinmob.io.schema.unicode_text`), e.g. the
            URDF's path from ``target``'s folder through a folder whose name is not UTF-8.
    """
    doc: dict[str, Any] = dict(document)
    urdf = (source.parent / doc["urdf"]).resolve()
    doc["urdf"] = unicode_text(  # a folder name that is not UTF-8 (bytes read as surrogates): no TOML can hold it
        "the URDF's path from the output's folder",
        os.path.relpath(urdf, target.resolve().parent),
        "a folder's name is not UTF-8: rename it, or write the output in the URDF's folder",
    )
    doc.setdefault("length_scale", float(fixed.length_scale))  # the same L (to the bit): the same rank decisions
    configurations = {k: dict(v) for k, v in doc.get("configurations", {}).items()}
    for name, conf in configurations.items():
        named = fixed.configurations.get(name)
        if named is not None and named.seed and "pose" in conf:  # the assembly the input finds there
            conf["seed"] = {k: float(v) for k, v in named.seed.items()}
    if configurations:
        doc["configurations"] = configurations
    doc.pop("limbs", None)
    doc.pop("closures", None)
    doc.pop("actuated", None)
    out: dict[str, Any] = {}
    for k, v in doc.items():  # the order of the input: name, description, urdf, platform, ...
        out[k] = v
        if k == "platform" or (k == "urdf" and "platform" not in doc):
            if fixed.limbs:
                out["limbs"] = [
                    {"name": limb.name, "tip": limb.tip} | ({"actuated": list(limb.actuated)} if limb.actuated else {})
                    for limb in fixed.limbs
                ]
            if fixed.extra_actuated:
                out["actuated"] = list(fixed.extra_actuated)
            if fixed.closures:
                out["closures"] = [closure_table(c) for c in fixed.closures]
    return toml_document(out)


def fixed_sidecar(document: Mapping[str, Any], fixed: Mechanism, urdf: Path, target: Path) -> str:
    """The YAML sidecar of ``fixed``, read from an Extended URDF sidecar whose URDF is ``urdf``, written at ``target``.

    ``document``: the sidecar's, as :func:`pinmob.io.read_sidecar` reads it (the caller reads the file once; it is
    not changed). Each loop keeps its pair of frames (closures named ``a=b``, as read); a loop whose closure went
    is dropped.
    """
    import yaml

    doc = dict(document)
    by_frames = {(c.frame_a, c.frame_b): c for c in fixed.closures}
    loops, types, axes, axes_b = [], [], [], []
    for a, b in doc.get("closed_loop") or []:
        c = by_frames.get((a, b))
        if c is None:
            continue
        loops.append([a, b])
        types.append(str(c.type))
        axes.append(None if c.axis is None else _vector(c.axis))
        axes_b.append(None if c.axis_b is None else _vector(c.axis_b))
    doc["closed_loop"], doc["type"] = loops, types
    if any(t not in ("6d", "3d") for t in types):
        doc["axis"] = axes
        if any(a is not None for a in axes_b):
            doc["axis_b"] = axes_b
    if urdf.resolve().parent != target.resolve().parent or urdf.stem != target.stem:
        doc["urdf"] = os.path.relpath(urdf.resolve(), target.resolve().parent)
    return str(yaml.safe_dump(doc, sort_keys=False, default_flow_style=None))


def fixed_mjcf(source: Path, connects: Mapping[str, int], anchors: Mapping[str, Sequence[float]]) -> str:
    """The MJCF text of ``source`` with each weld of ``connects`` (name -> its index among the equalities) a connect.

    The connect is at ``anchors[name]`` (in body1's frame; a weld between sites keeps its sites).

    Raises:
        MechanismFileError: a weld is not in the file itself (an included file), or not found.
    """
    import xml.etree.ElementTree as ET

    tree = ET.parse(source, parser=ET.XMLParser(target=ET.TreeBuilder(insert_comments=True)))
    root = tree.getroot()
    equalities = [e for eq in root.iter("equality") for e in eq if isinstance(e.tag, str)]
    included = root.find(".//include") is not None
    for name, index in connects.items():
        named = [e for e in equalities if e.tag == "weld" and e.get("name") == name]
        if not named and not included and index < len(equalities) and equalities[index].tag == "weld":
            named = [equalities[index]]
        if len(named) != 1:
            raise file_error(source, f"weld {name!r} is not in this file (an included file?); change it by hand")
        weld = named[0]
        weld.tag = "connect"
        for key in ("relpose", "torquescale", "anchor"):
            weld.attrib.pop(key, None)
        if weld.get("site1") is None:
            weld.set("anchor", " ".join(f"{x:.15g}" for x in _vector(anchors[name])))
    ET.indent(tree)
    original = source.read_text(encoding="utf-8")
    start = original.find(f"<{root.tag}")
    head = original[:start] if start > 0 else ""  # the comments before the root element (ElementTree drops them)
    text = ET.tostring(root, encoding="unicode")
    if not text.strip():
        raise MechanismFileError(f"{source}: nothing to write")
    return head + text + "\n"
