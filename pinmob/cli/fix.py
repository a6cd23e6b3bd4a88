"""``pinmob fix FILE --output OUT``: the mechanism file with its minimal closures, in the input's format.

The proposal is :attr:`pinmob.analysis.report.Report.minimal_closures` at the configuration asked for (the
first named one by default). TOML and Extended URDF files get it as it is (:func:`pinmob.fix_closures`),
checked by re-analysing both mechanisms at every named configuration, and the written file is read back and
analysed. MJCF gets the nearest change MuJoCo can express: a weld whose rotation rows are redundant becomes a
connect (checked the same way, and by MuJoCo's rank of the new file's equality rows); any other proposal is
said, not written. The output is never the input (nor a link to it, nor its URDF), never an existing file
without ``--force``, never in a folder that does not exist.
"""

from __future__ import annotations

import argparse
import os
import re
from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np

from pinmob.analysis import MinimalClosures, analyze, check_fixed, chosen_proposal, describe, fix_closures
from pinmob.assembly import CLOSURE_TOL
from pinmob.cli.common import load_for, with_elsewhere
from pinmob.exceptions import ConfigurationError
from pinmob.model import ClosureType, Mechanism
from pinmob.output_files import Replacing, check_target

#: Output suffixes by input format.
SUFFIXES = {"toml": (".toml",), "sidecar": (".yaml", ".yml"), "mjcf": (".xml", ".mjcf")}
WORDS = {"toml": "a pinmob TOML file", "sidecar": "an Extended URDF sidecar", "mjcf": "an MJCF file"}


def _format(mech: Mechanism) -> str:
    source = mech.source
    suffix = source.suffix.lower() if source is not None else ""
    for kind, suffixes in SUFFIXES.items():
        if suffix in suffixes:
            return kind
    raise ConfigurationError(
        f"pinmob fix writes pinmob TOML, Extended URDF sidecars (.yaml) and MJCF (.xml); {mech.name!r} was read "
        f"from {str(source) if source else 'no file'}"
    )


def _check_output(mech: Mechanism, kind: str, doc: dict[str, Any] | None, output: str, force: bool) -> Path:
    target = Path(output).expanduser()
    inputs = [mech.source] if mech.source is not None else []
    if doc is not None:
        inputs.append(_urdf_of(mech, kind, doc))
    for p in inputs:
        if target.absolute() == Path(p).absolute() or (target.exists() and os.path.samefile(target, p)):
            raise ConfigurationError(
                f"--output {str(target)!r} is the input file {str(p)!r} (or a link to it); pinmob fix never "
                "overwrites its input: give a new file name"
            )
    if target.suffix.lower() not in SUFFIXES[kind]:
        raise ConfigurationError(
            f"--output {str(target)!r}: the input is {WORDS[kind]}, so the output needs the suffix "
            f"{' or '.join(SUFFIXES[kind])}"
        )
    return check_target("--output", target, force)


def _document(mech: Mechanism, kind: str) -> dict[str, Any] | None:
    """The input's document, read once for the output's checks and the writer.

    A pinmob TOML file's or an Extended URDF sidecar's; None for MJCF (its writer reads the XML) or no file.
    """
    if mech.source is None or kind == "mjcf":
        return None
    if kind == "toml":
        from pinmob.io import read_toml

        return read_toml(mech.source)
    from pinmob.io import read_sidecar

    return read_sidecar(mech.source)


def _urdf_of(mech: Mechanism, kind: str, doc: dict[str, Any]) -> Path:
    """The URDF the input (:func:`_document`'s ``doc``, read from ``mech.source``) names."""
    assert mech.source is not None  # a document is read from a file
    if kind == "toml":
        return mech.source.parent / str(doc.get("urdf", ""))
    from pinmob.io import sidecar_urdf

    return sidecar_urdf(mech.source, doc)


def run(args: argparse.Namespace) -> int:
    """``pinmob fix``: write the corrected file and say what changed and what was checked; 0, or 2 on an error."""
    mech = load_for(args)
    kind = _format(mech)
    doc = _document(mech, kind)
    target = _check_output(mech, kind, doc, args.output, args.force)
    tol = CLOSURE_TOL if args.closure_tol is None else args.closure_tol
    with with_elsewhere(mech):
        if args.config is None:  # the most generic named configuration (chosen_proposal)
            config, minimal = chosen_proposal(mech, closure_tol=tol)
        else:
            config = mech.configuration_name(args.config)
            minimal = analyze(mech, config, closure_tol=tol).minimal_closures
        report = analyze(mech, config, closure_tol=tol)
    where = f" at {report.configuration!r}" if report.configuration else ""
    if minimal is not None and not minimal.changes:
        print("\n".join(minimal.lines()))
        print(f"none of them is changed (couplings are kept); nothing to fix, {target} not written")
        return 0
    if minimal is None:
        elsewhere = [
            n
            for n in mech.configurations
            if n != config and analyze(mech, n, closure_tol=tol).mechanism_mobility.redundant_constraints
        ]
        others = f" (redundant ones only at {', '.join(map(repr, elsewhere))}, singular there)" if elsewhere else ""
        print(f"{mech.name}{where}: no closure equation is redundant{others}; nothing to fix, {target} not written")
        return 0
    print("\n".join(minimal.lines()))  # the proposal, without its hint to run this command
    if kind == "mjcf":
        return _fix_mjcf(mech, minimal, report.state.q, target, tol)
    fixed = fix_closures(mech, minimal, closure_tol=tol)
    check = check_fixed(mech, fixed, closure_tol=tol)
    if not check.same:
        raise ConfigurationError(
            f"the minimal closures change the answers ({'; '.join(check.differences)}); {target} not written"
        )
    if kind == "toml":
        from pinmob.io import fixed_toml

        text = fixed_toml(mech.source, doc, fixed, target)  # type: ignore[arg-type]
    else:
        from pinmob.io import fixed_sidecar

        text = fixed_sidecar(doc, fixed, _urdf_of(mech, kind, doc), target)  # type: ignore[arg-type]
    _write(target, text)
    _report_written(mech, target, check.configurations, tol)
    if kind == "sidecar" and any(str(c.type) not in ("6d", "3d") for c in fixed.closures):
        print(
            "note: the sidecar now uses pinmob's closure types beyond 6d/3d (with 'axis' per loop): pinmob reads "
            "it, the LAAS tools (6d/3d only) do not"
        )
    return 0


def _write(target: Path, text: str) -> None:
    replacing = Replacing(target)
    with replacing as tmp:
        tmp.write_text(text, encoding="utf-8")
        replacing.commit()


def _report_written(original: Mechanism, target: Path, configurations: tuple[str | None, ...], tol: float) -> None:
    """Read the written file back, analyse it where the check did, and print one line per configuration."""
    from pinmob.io import load

    written = load(target)
    for name in configurations:
        before = analyze(original, name, closure_tol=tol)
        after = analyze(written, name if name else before.state.q, closure_tol=tol)
        a, b = before.mechanism_mobility, after.mechanism_mobility
        where = f"at {name!r}" if name else "at the default configuration"
        types = ", ".join(f"{f.frame} {f.motion_type}" for f in b.frames if f.frame in b.end_frames)
        print(
            f"{target} {where}: closure equations {a.rows} -> {b.rows}, redundant {a.redundant_constraints} -> "
            f"{b.redundant_constraints}; mechanism DoF {b.mechanism_dof} (was {a.mechanism_dof}), idle motions "
            f"{b.idle_dof} (was {a.idle_dof}){'; ' + types if types else ''}"
        )
    print(f"wrote {target}")


def _fix_mjcf(mech: Mechanism, minimal: MinimalClosures, q: np.ndarray, target: Path, tol: float) -> int:
    """Welds whose rotation rows are redundant become connects; the other proposals are said, not written."""
    import mujoco

    from pinmob.io import compile_mjcf

    source = mech.source
    if source is None:
        raise ConfigurationError(f"{mech.name!r} was read from no file")
    m = compile_mjcf(source, warn=False)
    rank = analyze(mech, q, closure_tol=tol).mechanism_mobility.rank
    by_name = {c.name: c for c in mech.closures}
    connects: dict[str, int] = {}
    anchors: dict[str, list[float]] = {}
    for change in minimal.changes:
        c = by_name.get(change.name)
        proposed = "remove it" if change.proposed is None else describe(change.proposed)
        if c is None or c.type is not ClosureType.WELD:
            print(
                f"{change.name}: MuJoCo has no equality with exactly its {change.needed} equation(s) ({proposed}); left as it is"
            )
            continue
        trial = replace(mech, closures=tuple(replace(x, type=ClosureType.BALL) if x is c else x for x in mech.closures))
        if analyze(trial, q, closure_tol=tol).mechanism_mobility.rank != rank:
            print(
                f"{change.name}: weld -> the nearest MuJoCo equality, connect, would free a rotation it needs; its "
                f"{change.needed} independent equation(s) ({proposed}) have no MuJoCo equality: left a weld"
            )
            continue
        e = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_EQUALITY, c.name)
        unnamed = re.fullmatch(r"equality#(\d+)", c.name)
        if e < 0 and unnamed is not None:  # pinmob's label of MuJoCo's equality k without a name
            e = int(unnamed.group(1))
        if e < 0:
            print(f"{change.name}: not found among MuJoCo's equalities; left as it is")
            continue
        connects[c.name] = e
        anchors[c.name] = [float(x) for x in m.eq_data[e, 3:6]]
        left = 3 - change.needed
        print(
            f"{change.name}: weld -> connect (its rotation rows are redundant)"
            + (
                f"; {left} of the connect's 3 rows stay redundant: MuJoCo has no {change.needed}-row equality"
                if left
                else ""
            )
        )
    if not connects:
        print(f"nothing MuJoCo can express changes; {target} not written")
        return 0
    from pinmob.io import fixed_mjcf

    trial = replace(
        mech, closures=tuple(replace(x, type=ClosureType.BALL) if x.name in connects else x for x in mech.closures)
    )
    check = check_fixed(mech, trial, closure_tol=tol)  # every connect together, at every named configuration
    if not check.same:
        raise ConfigurationError(
            f"the connects change the answers ({'; '.join(check.differences)}); {target} not written"
        )
    _write(target, fixed_mjcf(source, connects, anchors))
    new = compile_mjcf(target, warn=False)
    rows, rank_mj = mujoco_equality_rank(new)
    print(f"MuJoCo, {target} at qpos0: {rows} equality rows of rank {rank_mj}")
    _report_written(mech, target, tuple(mech.configurations) or (None,), tol)
    return 0


def mujoco_equality_rank(m: object, rtol: float = 1e-9) -> tuple[int, int]:
    """MuJoCo's equality rows (``efc_J``) at ``qpos0`` and their rank (singular values above ``rtol`` times the largest)."""
    import mujoco

    d = mujoco.MjData(m)
    mujoco.mj_forward(m, d)
    rows = np.flatnonzero(d.efc_type[: d.nefc] == mujoco.mjtConstraint.mjCNSTR_EQUALITY)
    nv = m.nv  # type: ignore[attr-defined]
    jac = np.array(d.efc_J).reshape(-1, nv)[rows] if nv else np.zeros((0, 0))
    if not jac.size:
        return len(rows), 0
    s = np.linalg.svd(jac, compute_uv=False)
    return len(rows), int(np.sum(s > rtol * s[0]))
