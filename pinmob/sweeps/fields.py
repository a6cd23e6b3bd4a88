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

TYPES = {name: kind for name, kind, _, _ in FIELDS}
UNITS = {name: unit for name, _, unit, _ in FIELDS}

#: Prefix of the fields giving the scan parameters where the smallest distance was found.
MIN_AT = "min_distance_"


def record_fields(parameters: tuple[str, ...], scan_parameters: list[str]) -> list[tuple[str, str]]:
    """(name, type) of every field of a record, in order: ``design``, the parameters, ``FIELDS``, ``MIN_AT`` ones."""
    return (
        [("design", "int")]
        + [(p, "float") for p in parameters]
        + [(name, kind) for name, kind, _, _ in FIELDS]
        + [(MIN_AT + p, "float") for p in scan_parameters]
    )
