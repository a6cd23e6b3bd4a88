"""The package's layering: no import cycle (function-level and type-only imports count), imports only go down."""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

PACKAGE = Path(__file__).resolve().parent.parent / "pinmob"

#: The layers, bottom first: a module may import only from its own layer or those below.
LAYERS = [
    {
        "pinmob.exceptions",
        "pinmob.output_files",
        "pinmob.name_matching",
        "pinmob.frozen",
        "pinmob.jit_cache",
        "pinmob.held_setting",
        "pinmob.blas",
        "pinmob.collector",
        "pinmob.signals",
        "pinmob.progress",
        "pinmob.bounds",
        "pinmob.glossary",
        "pinmob.lazy_names",
    },
    {"pinmob.screw"},
    {"pinmob.model"},
    {"pinmob.assembly", "pinmob.io"},
    {"pinmob.analysis"},
    {"pinmob.scan", "pinmob.parallel", "pinmob.figures", "pinmob.viewer", "pinmob.testing", "pinmob.builder"},
    {"pinmob.catalog"},
    {"pinmob.sweeps"},
    {"pinmob.cli", "pinmob", "pinmob.__main__"},
]
#: Third-party packages only the presentation layers may import (the core never draws or plots).
PRESENTATION = {"meshcat", "matplotlib", "zmq", "tqdm", "tornado", "umsgpack"}


def module_name(path: Path) -> str:
    parts = list(path.relative_to(PACKAGE.parent).with_suffix("").parts)
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


MODULES = {module_name(p): p for p in PACKAGE.rglob("*.py")}


def imports(name: str) -> list[tuple[str, int]]:
    """The pinmob modules (and third-party top-level packages) that module ``name`` imports, anywhere in it."""
    path = MODULES[name]
    package = name if path.name == "__init__.py" else name.rpartition(".")[0]
    out = []
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        targets: list[str] = []
        if isinstance(node, ast.Import):
            targets = [a.name for a in node.names]
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split(".")[: len(package.split(".")) - (node.level - 1)]
                prefix = ".".join(base + ([node.module] if node.module else []))
            else:
                prefix = node.module or ""
            targets = [f"{prefix}.{a.name}" for a in node.names] + [prefix]
        for t in targets:
            found = t
            while found and found not in MODULES:
                found = found.rpartition(".")[0]
            if found and found != name:
                out.append((found, node.lineno))
            elif not t.startswith("pinmob"):
                out.append((t.split(".")[0], node.lineno))
    return out


def layer(name: str) -> int:
    for i, members in enumerate(LAYERS):
        if any(name == m or name.startswith(m + ".") for m in members if m != "pinmob") or name in members:
            return i
    raise AssertionError(f"module {name} is in no layer: add it to LAYERS")


def test_no_import_cycle() -> None:
    """Tarjan's strongly connected components of the import graph: every one is a single module."""
    graph = {m: {t for t, _ in imports(m) if t in MODULES} for m in MODULES}
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    cycles = []

    def visit(v: str) -> None:
        index[v] = low[v] = len(index)
        stack.append(v)
        for w in graph[v]:
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            group = []
            while True:
                w = stack.pop()
                group.append(w)
                if w == v:
                    break
            if len(group) > 1:
                cycles.append(sorted(group))

    for v in sorted(graph):
        if v not in index:
            visit(v)
    assert not cycles, f"import cycles: {cycles}"


def test_the_checker_sees_function_level_and_type_only_imports(tmp_path: Path) -> None:
    """The cycle test above can fail: both kinds of import are edges of the graph."""
    source = MODULES["pinmob.model.closure"].read_text(encoding="utf-8")
    assert "TYPE_CHECKING" in source and any(t == "pinmob.model.limb" for t, _ in imports("pinmob.model.closure"))
    assert any(t == "pinmob.assembly" for t, _ in imports("pinmob.builder.closed_joints"))


def test_imports_only_go_down() -> None:
    """A module imports only from its own layer or below; the core never imports the viewer, plots or the CLI."""
    wrong = []
    for name in MODULES:
        for target, line in imports(name):
            if target in MODULES and layer(target) > layer(name):
                wrong.append(f"{name}:{line} imports {target}")
            if target in PRESENTATION and layer(name) <= layer("pinmob.analysis"):
                wrong.append(f"{name}:{line} imports {target} (presentation) in the core")
    assert not wrong, "\n".join(wrong)


#: Beyond this many lines a file is a room of several concepts, not a module: the only size that fails.
ROOM = 1000


def test_module_sizes_are_reported(capsys: pytest.CaptureFixture[str]) -> None:
    """Module size is a report, not a gate (issue 34): the largest modules are printed, to look for two concepts in.

    300 lines is a hint (docs/development.md); a line-count gate made helpers cut one concept in two. Only a
    file past ``ROOM`` lines fails, which no module here comes near.
    """
    sizes = sorted(((len(p.read_text(encoding="utf-8").splitlines()), n) for n, p in MODULES.items()), reverse=True)
    with capsys.disabled():
        print("\nlargest modules (300 lines is a hint to look for two concepts):")
        for lines, name in sizes[:8]:
            print(f"  {lines:5d}  {name}")
    assert sizes[0][0] <= ROOM, f"{sizes[0][1]} has {sizes[0][0]} lines: more than one concept lives there"


#: A folder of more modules than this is a flat room to split into subpackages (the issue's "about 15")
FOLDER = 16


def test_no_flat_folder_is_a_room() -> None:
    """Each package folder holds at most ``FOLDER`` modules besides its ``__init__`` (``io/`` held 19: MJCF is
    ``io/mjcf/`` now)."""
    folders = {p.parent for p in PACKAGE.rglob("*.py")}
    crowded = {
        str(f.relative_to(PACKAGE.parent)): n
        for f in folders
        if (n := len([p for p in f.glob("*.py") if p.name != "__init__.py"])) > FOLDER
    }
    assert not crowded, f"folders of more than {FOLDER} modules (make subpackages): {crowded}"


def test_module_file_names_are_unique() -> None:
    """One file name, one module: ``spec.py`` was a scan's and a sweep's, ``named.py`` a model's and an assembly's."""
    seen: dict[str, list[str]] = {}
    for p in PACKAGE.rglob("*.py"):
        if p.name not in ("__init__.py", "__main__.py"):
            seen.setdefault(p.name, []).append(str(p.relative_to(PACKAGE.parent)))
    twice = {name: paths for name, paths in seen.items() if len(paths) > 1}
    assert not twice, f"file names used twice (name each module for what it defines): {twice}"


#: imports of another package's inner module that its face cannot replace: the function ``singularity`` has
#: the name of its own subpackage, so ``pinmob.analysis`` cannot export it (it would hide the subpackage); it
#: comes from that subpackage's face
THROUGH_SUBPACKAGE_FACES = {("pinmob/scan/sample.py", "pinmob.analysis.singularity")}


def deep_imports() -> list[tuple[str, int, str]]:
    """Imports (function-level too) that reach into another package's inner module instead of its ``__init__``."""
    packages = {p.name for p in PACKAGE.iterdir() if (p / "__init__.py").exists()}
    found = []
    for path in PACKAGE.rglob("*.py"):
        rel = path.relative_to(PACKAGE).parts
        own = rel[0] if len(rel) > 1 else None
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.ImportFrom):
                if node.level:
                    base = list(rel[:-1])[: len(rel) - node.level]
                    module = ".".join(["pinmob", *base] + ([node.module] if node.module else []))
                else:
                    module = node.module or ""
                targets = [module] + [f"{module}.{a.name}" for a in node.names if len(module.split(".")) == 2]
            elif isinstance(node, ast.Import):
                targets = [a.name for a in node.names]
            else:
                continue
            for target in targets:
                parts = target.split(".")
                if parts[0] != "pinmob" or len(parts) < 3 or parts[1] not in packages or parts[1] == own:
                    continue
                if len(parts) == 3 and target != module:  # from pinmob.P import X: deep only when X is a module
                    sub = PACKAGE / parts[1] / parts[2]
                    if not (sub.with_suffix(".py").exists() or (sub / "__init__.py").exists()):
                        continue
                where = str(path.relative_to(PACKAGE.parent))
                if (where, target) not in THROUGH_SUBPACKAGE_FACES:
                    found.append((where, node.lineno, target))
    return found


def test_packages_are_used_through_their_faces() -> None:
    """Each package's ``__init__`` is its face: other packages import from it, never from its inner modules
    (issue 34: 448 such imports; a package's inner modules can then change without touching the others)."""
    deep = deep_imports()
    assert not deep, f"{len(deep)} imports bypass a package's face, e.g. " + "; ".join(
        f"{w}:{n}: {t}" for w, n, t in deep[:10]
    )
