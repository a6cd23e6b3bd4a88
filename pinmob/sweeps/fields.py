"""The fields of a sweep record: one record per design, its parameters first, then these (name, type, unit, meaning).

Types: ``int``, ``float``, ``bool``, ``str``; a missing value (a design that
failed, a fraction of no sample) is ``None`` (null in Parquet, blank in CSV).
``MIN_AT`` names the fields giving where the smallest distance was found, one per
scan parameter (``min_distance_s`` on a path, ``min_distance_grid_x`` and
``min_distance_grid_y`` on a grid over x and y).
"""

from __future__ import annotations

#: (name, type, unit, meaning) of the fields after the parameters.
FIELDS: tuple[tuple[str, str, str, str], ...] = (
    ("status", "str", "", "'ok', or 'failed' (the reason says why)"),
    ("reason", "str", "", "why the design failed ('' when ok)"),
    ("dof", "int", "", "platform DoF at the reference configuration (the scan's 'at' or 'from')"),
    ("motion_type", "str", "", "motion type there, e.g. 3T"),
    ("constraint_rank", "int", "", "rank of the platform's constraint wrenches there"),
    ("generic_rank", "int", "", "generic constraint rank of the design"),
    ("mechanism_dof", "int", "", "DoF of the whole closed chain there"),
    ("redundant_constraints", "int", "", "closure equations implied by the others (over-constraint)"),
    ("actuation_valid", "bool", "", "the declared actuators make the mechanism rigid there, every idle motion aside"),
    ("samples", "int", "", "samples of the workspace scan"),
    ("assembled", "float", "fraction", "fraction of the scanned samples that assemble"),
    ("singularity_free", "float", "fraction", "fraction of the assembled samples that are not singular"),
    ("refined_points", "int", "", "singular or near-singular points the scan refined between samples"),
    ("motion_types", "str", "", "motion types met at the assembled samples, ';'-separated"),
    ("min_distance", "float", "sigma_r / sigma_1", "smallest distance to a singularity over the scan"),
    ("min_distance_class", "str", "", "the test closest to singular there (constraint, actuation, a limb)"),
)

#: The fields a spec asking for the finite analysis (``finite = true``) adds, after ``FIELDS``.
FINITE_FIELDS: tuple[tuple[str, str, str, str], ...] = (
    ("finite_dof", "int", "", "platform DoF at finite amplitude at the reference (null: cannot decide)"),
    ("finite_mechanism_dof", "int", "", "closed chain's DoF at finite amplitude there (null: cannot decide)"),
    (
        "finite_dof_locked",
        "int",
        "",
        "platform DoF at finite amplitude with the actuators held (null: none declared, or cannot decide)",
    ),
    (
        "finite_motions",
        "str",
        "",
        "each instantaneous platform motion's verdict, e.g. 'T1 z: finite; R1 z: blocked at order 2'",
    ),
)

TYPES = {name: kind for name, kind, _, _ in FIELDS + FINITE_FIELDS}
UNITS = {name: unit for name, _, unit, _ in FIELDS + FINITE_FIELDS}

#: Prefix of the fields giving the scan parameters where the smallest distance was found.
MIN_AT = "min_distance_"


def record_fields(
    parameters: tuple[str, ...], scan_parameters: list[str], finite: bool = False
) -> list[tuple[str, str]]:
    """(name, type) of every field of a record, in order.

    ``design``, the parameters, ``FIELDS``, the ``MIN_AT`` ones, and with ``finite`` the ``FINITE_FIELDS``.
    """
    return (
        [("design", "int")]
        + [(p, "float") for p in parameters]
        + [(name, kind) for name, kind, _, _ in FIELDS]
        + [(MIN_AT + p, "float") for p in scan_parameters]
        + ([(name, kind) for name, kind, _, _ in FINITE_FIELDS] if finite else [])
    )
