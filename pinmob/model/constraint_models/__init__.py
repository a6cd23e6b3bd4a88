"""Pinocchio's constraint models as a format pinmob reads and writes (both APIs; mimic joints as couplings).

:func:`read_constraint_models` (:meth:`pinmob.Mechanism.from_pinocchio`) and :func:`write_constraint_models`
(:meth:`pinmob.Mechanism.to_pinocchio`); :class:`ConstraintModelError` for a constraint pinmob cannot read,
:class:`PinocchioExportWarning` for closures Pinocchio has no exact model for.
"""

from pinmob.model.constraint_models.constraint_errors import ConstraintModelError, PinocchioExportWarning
from pinmob.model.constraint_models.constraint_reading import limb_welds, mechanism_parts, read_constraint_models
from pinmob.model.constraint_models.constraint_writing import APIS, write_constraint_models

__all__ = [
    "APIS",
    "ConstraintModelError",
    "PinocchioExportWarning",
    "limb_welds",
    "mechanism_parts",
    "read_constraint_models",
    "write_constraint_models",
]
