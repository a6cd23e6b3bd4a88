"""Where a sweep's mechanisms come from: a built-in family with its parameters, or a template mechanism file.

Either way, a design's mechanism is written as files (URDF + pinmob TOML) into a
scratch folder and loaded from there as any mechanism file is (kinematics only:
a template's meshes are not copied).
"""

from __future__ import annotations

import tomllib
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

from pinmob.catalog import family
from pinmob.exceptions import ConfigurationError, MechanismFileError
from pinmob.io import load_toml
from pinmob.model import Mechanism
from pinmob.sweeps.template import fill, names_used, placeholders

if TYPE_CHECKING:
    import pinocchio as pin

#: File names of a family member in the scratch folder.
DESIGN_TOML, DESIGN_URDF = "design.toml", "design.urdf"


@dataclass(frozen=True)
class Source:
    """A family (``family``) or a template (``texts``: relative file name -> text, the first one the TOML file).

    Attributes:
        family: name of a built-in family (:data:`pinmob.catalog.families.FAMILIES`), or ''.
        texts: the template's files, each with its placeholders.
        units: unit of each parameter (families know theirs; a template's come from the spec's [units]).
    """

    family: str = ""
    texts: tuple[tuple[str, str], ...] = ()
    units: dict[str, str] = field(default_factory=dict)

    @property
    def name(self) -> str:
        """The family's name or the template's file name."""
        return self.family or self.texts[0][0]

    def parameters(self) -> tuple[str, ...]:
        """The parameter names this source takes: a family's, or those the template's placeholders use."""
        if self.family:
            return family(self.family).names()
        used: set[str] = set()
        for fname, text in self.texts:
            for expr in placeholders(text):
                used |= names_used(expr, fname)
        return tuple(sorted(used))

    def files(self, values: dict[str, float]) -> dict[str, str]:
        """The design's files (name -> text); the first is its TOML mechanism file.

        Raises:
            ConfigurationError: values the family refuses, or a placeholder without a value or not computable.
        """
        return self._design(values)[0]

    def _design(self, values: dict[str, float]) -> tuple[dict[str, str], pin.Model | None]:
        """:meth:`files`, and a family member's URDF model: parsed once, for the TOML's angles and the loading."""
        if self.family:
            builder, confs, length = family(self.family).build(values)
            urdf = builder.urdf()
            model = builder.model(urdf)
            return {DESIGN_TOML: builder.toml(DESIGN_URDF, confs, length, model=model), DESIGN_URDF: urdf}, model
        return {fname: fill(text, values, fname) for fname, text in self.texts}, None

    def mechanism(self, values: dict[str, float], folder: Path) -> Mechanism:
        """The design's mechanism, its files written into ``folder`` (which must outlive its use).

        A family member's URDF is parsed once: the model the builder wrote the TOML with is the one loaded
        (:func:`pinmob.io.load_toml`'s ``urdf_model``; a new model per design).
        """
        files, model = self._design(values)
        for fname, text in files.items():
            path = folder / fname
            path.parent.mkdir(parents=True, exist_ok=True)
            path.write_text(text, encoding="utf-8")
        return load_toml(folder / next(iter(files)), urdf_model=model)

    def configuration_names(self, values: dict[str, float]) -> list[str]:
        """The named configurations of the design's mechanism file (without loading it)."""
        fname, text = next(iter(self.files(values).items()))
        try:
            return list(tomllib.loads(text).get("configurations", {}))
        except tomllib.TOMLDecodeError as exc:
            raise MechanismFileError(f"template {fname!r} with placeholders filled is not TOML: {exc}") from None


def template_source(path: Path, extra: list[str], units: dict[str, str], where: str) -> Source:
    """A template from its TOML file and the files beside it that it needs (default: the URDF it names).

    Raises:
        ConfigurationError: not a TOML file, a file missing, outside the template's folder or not UTF-8 text.
    """
    if path.suffix.lower() != ".toml":
        raise ConfigurationError(
            f"{where}: template {str(path)!r} must be a pinmob TOML mechanism file (a sweep scans the platform, "
            "which only TOML files name)"
        )
    main = _read(path, where)
    names = list(extra)
    if not names:
        for line in main.splitlines():
            key, _, value = line.partition("=")
            if key.strip() == "urdf" and value.strip().startswith('"'):
                names = [value.strip().split('"')[1]]
                break
    texts = [(path.name, main)]
    for name in names:
        rel = Path(name)
        if rel.is_absolute() or ".." in rel.parts:
            raise ConfigurationError(f"{where}: template file {name!r} must be a path inside the template's folder")
        texts.append((rel.as_posix(), _read(path.parent / rel, where)))
    return Source(texts=tuple(texts), units=dict(units))


def _read(path: Path, where: str) -> str:
    try:
        return path.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise ConfigurationError(f"{where}: template file {str(path)!r} does not exist") from None
    except (OSError, UnicodeDecodeError) as exc:
        raise ConfigurationError(f"{where}: template file {str(path)!r} cannot be read as UTF-8 text: {exc}") from None
