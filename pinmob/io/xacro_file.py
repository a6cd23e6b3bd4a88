"""xacro files expanded to URDF by the PyPI ``xacro`` library, under pinmob's rules for hostile input.

The library does the macro expansion (``xacro:macro``, ``xacro:property``, ``xacro:if``, ``xacro:include``,
``xacro:arg``); pinmob replaces what would run or read anything:

- every ``${...}`` is evaluated by :func:`pinmob.io.xacro_expressions.evaluate` (arithmetic, comparisons, math
  functions on properties and arguments; never Python's ``eval``);
- ``$(arg name)`` gives an argument (``--xacro-arg name:=value``, else the file's ``xacro:arg`` default),
  ``$(find pkg)`` the folder ``pkg`` inside the package folders the user named (``--package-path``, then
  ``ROS_PACKAGE_PATH``), ``$(dirname)`` the current file's folder; ``$(env)``, ``$(optenv)``, ``$(eval)``,
  ``$(anon)`` and ``$(cwd)`` are refused;
- includes and ``load_yaml`` read only regular files, within the file bound, inside the xacro file's own folder
  or a package folder named; an XML ``<!ENTITY`` declaration is refused (entities can expand without bound);
- macro calls are bounded (:data:`MAX_MACRO_CALLS` in all, Python's recursion limit in depth) and so is the
  expanded text (the file bound).

Errors are one :class:`~pinmob.exceptions.MechanismFileError` line naming the xacro file being read (the
library gives no line numbers). The library keeps its state in module globals,
so expansions are serialised by a lock.
"""

from __future__ import annotations

import os
import re
import threading
from collections.abc import Iterator, Mapping, Sequence
from contextlib import contextmanager
from pathlib import Path
from typing import Any

from pinmob.bounds import bound
from pinmob.exceptions import MechanismFileError
from pinmob.io.text_file import check_regular
from pinmob.io.xacro_expressions import ExpressionError, evaluate

#: Macro calls, included files and evaluated elements one expansion may make, together (a "billion laughs" of
#: macros, of includes or of inserted blocks is refused long before it costs memory or time).
MAX_MACRO_CALLS = 100_000
#: ``$(...)`` commands pinmob resolves; the others are refused.
COMMANDS = ("arg", "find", "dirname")
_LOCK = threading.Lock()
#: ``NAME:=VALUE`` of ``--xacro-arg``.
ARG = re.compile(r"^([A-Za-z_][A-Za-z0-9_]*):=(.*)$")


def parse_xacro_args(items: Sequence[str]) -> dict[str, str]:
    """``["a:=1", "b:=x"]`` as ``{"a": "1", "b": "x"}``.

    Raises:
        MechanismFileError: an item that is not ``NAME:=VALUE``.
    """
    out = {}
    for item in items:
        match = ARG.match(item.strip())
        if not match:
            raise MechanismFileError(f"xacro argument {item!r} is not NAME:=VALUE (e.g. prefix:=left_)")
        out[match.group(1)] = match.group(2)
    return out


def package_folders(package_dirs: Sequence[str | Path] = ()) -> list[Path]:
    """The folders ``$(find pkg)`` searches: those given, then ``ROS_PACKAGE_PATH``'s."""
    env = [d for d in os.environ.get("ROS_PACKAGE_PATH", "").split(os.pathsep) if d]
    return [Path(d).expanduser().resolve() for d in [*map(str, package_dirs), *env]]


def find_package(name: str, folders: Sequence[Path]) -> Path:
    """The folder of package ``name``: ``<folder>/name`` or ``<folder>/.../name`` holding a ``package.xml``.

    Raises:
        ValueError: not found (the message names the folders searched).
    """
    if not re.fullmatch(r"[A-Za-z0-9_.-]+", name) or name in (".", ".."):
        raise ValueError(f"$(find {name}): not a package name")
    for folder in folders:
        if (folder / name).is_dir():
            return folder / name
        for found in sorted(folder.glob(f"*/{name}/package.xml")) + sorted(folder.glob(f"*/*/{name}/package.xml")):
            return found.parent
        if folder.name == name:
            return folder
    where = ", ".join(map(str, folders)) or "none given"
    raise ValueError(
        f"$(find {name}): no package {name!r} in the package folders ({where}); name the folder holding it"
    )


def inside(path: Path, roots: Sequence[Path]) -> bool:
    """True when ``path`` (resolved) lies inside one of ``roots``."""
    real = path.resolve()
    return any(real == r or r in real.parents for r in roots)


class Expansion:
    """One expansion's state: the roots files may be read from, the arguments, the macro calls made."""

    def __init__(self, path: Path, args: Mapping[str, str], folders: Sequence[Path]) -> None:
        self.path, self.args, self.folders = path, dict(args), list(folders)
        self.roots = [path.parent.resolve(), *self.folders]
        self.calls = 0

    def readable(self, filename: str, what: str) -> Path:
        """``filename`` checked: inside the roots, a regular file within the bound."""
        path = Path(filename)
        if not inside(path, self.roots):
            raise ValueError(
                f"{what} {filename!r} is outside the folders pinmob reads ({', '.join(map(str, self.roots))}); "
                "name the package folder holding it"
            )
        check_regular(path, f"{what} {filename!r}", "xacro")
        return path

    def extension(self, text: str, current: str) -> str:
        """The value of ``$(command args)``."""
        inner = text[2:-1].strip()
        command, _, rest = inner.partition(" ")
        rest = rest.strip()
        if command == "arg":
            if rest not in self.args:
                raise ValueError(f"$(arg {rest}): no argument {rest!r}; give it as {rest}:=VALUE")
            return self.args[rest]
        if command == "find":
            return str(find_package(rest, self.folders))
        if command == "dirname":
            return str(Path(current).resolve().parent)
        raise ValueError(f"$({command} ...) is not allowed in a xacro file pinmob reads; valid: {', '.join(COMMANDS)}")

    def load_yaml(self, filename: str, current: str) -> Any:
        """``load_yaml``: a YAML file inside the roots, read safely, as xacro's wrappers (``d.key``)."""
        import xacro
        import yaml

        name = filename if os.path.isabs(filename) else os.path.join(os.path.dirname(current), filename)
        path = self.readable(name, "load_yaml file")
        limit = bound("bytes")
        text = path.read_bytes()[: limit + 1].decode("utf-8", errors="replace")
        if "&" in text and "*" in text:  # anchors and aliases: a YAML bomb expands without bound
            raise ValueError(f"load_yaml file {filename!r} uses YAML anchors and aliases, which pinmob does not read")
        return xacro.YamlListWrapper.wrap(yaml.safe_load(text))


def _message(exc: BaseException) -> str:
    """One line of what the library or pinmob said."""
    text = str(exc)
    inner = getattr(exc, "exc", None)
    if inner is not None and str(inner) not in text:
        text = f"{text} {inner}"
    return " ".join(text.split())[:400]


@contextmanager
def _patched(expansion: Expansion) -> Iterator[Any]:
    """The ``xacro`` module with pinmob's evaluation, extensions, includes and bounds (restored after)."""
    import xacro

    names = ("safe_eval", "eval_extension", "get_include_files", "handle_macro_call", "parse", "eval_all")
    saved = {k: getattr(xacro, k) for k in names}

    def safe_eval(expr: str, symbols: Any, locals: Any = None) -> Any:
        current = xacro.filestack[-1] if xacro.filestack else str(expansion.path)
        return evaluate(expr, symbols, lambda f: expansion.load_yaml(f, current), expansion.args)

    def eval_extension(text: str) -> str:
        current = xacro.filestack[-1] if xacro.filestack else str(expansion.path)
        try:
            return expansion.extension(text, current)
        except ValueError as exc:
            raise xacro.XacroException(str(exc)) from None

    def count(what: str) -> None:
        expansion.calls += 1  # macro calls, includes and elements: all that can multiply
        if expansion.calls > MAX_MACRO_CALLS:
            raise xacro.XacroException(f"over {MAX_MACRO_CALLS} {what}: the expansion is refused")

    def eval_all(node: Any, macros: Any, symbols: Any) -> Any:
        count("macro calls, includes and elements")
        return saved["eval_all"](node, macros, symbols)

    def get_include_files(spec: str, symbols: Any) -> Iterator[str]:
        for filename in saved["get_include_files"](spec, symbols):
            count("macro calls, includes and elements")
            try:
                yield str(expansion.readable(filename, "include"))
            except (ValueError, MechanismFileError) as exc:
                raise xacro.XacroException(str(exc)) from None

    def handle_macro_call(node: Any, macros: Any, symbols: Any) -> Any:
        if node.tagName.startswith("xacro:"):
            count("macro calls, includes and elements")
        return saved["handle_macro_call"](node, macros, symbols)

    def parse(inp: Any, filename: str | None = None) -> Any:
        if inp is None and filename is not None:
            limit = check_regular(Path(filename), f"xacro file {filename!r}", "xacro")
            with open(filename, "rb") as f:
                data = f.read(limit + 1)
            if b"<!ENTITY" in data:
                raise xacro.XacroException(
                    f"{filename}: <!ENTITY> declarations are not read (they expand without bound)"
                )
            inp = data.decode("utf-8", errors="replace")
        return saved["parse"](inp, filename)

    replacements = {
        "safe_eval": safe_eval,
        "eval_extension": eval_extension,
        "get_include_files": get_include_files,
        "handle_macro_call": handle_macro_call,
        "parse": parse,
        "eval_all": eval_all,
    }
    with _LOCK:
        for k, v in replacements.items():
            setattr(xacro, k, v)
        xacro.all_includes = []  # the library lists every file it read here, across expansions
        try:
            yield xacro
        finally:
            for k, v in saved.items():
                setattr(xacro, k, v)
            xacro.all_includes = []


def expand_xacro(
    path: str | Path, args: Mapping[str, str] | None = None, package_dirs: Sequence[str | Path] = ()
) -> str:
    """The URDF text of xacro file ``path`` (see the module docstring).

    Raises:
        MechanismFileError: one line naming the file (and the macro) and what is refused or wrong.
    """
    path = Path(path)
    check_regular(path, f"xacro file {str(path)!r}", "xacro")
    try:
        import xacro  # noqa: F401  # a dependency of pinmob; an environment without it gets one line
    except ImportError:
        raise MechanismFileError(
            f"{path}: reading a xacro file needs the xacro package (pip install 'xacro>=2.1.1,<2.2')"
        ) from None
    expansion = Expansion(path, args or {}, package_folders(package_dirs))
    with _patched(expansion) as xacro:
        try:
            doc = xacro.process_file(str(path), mappings=expansion.args, verbosity=0)  # defaults added to it
            text = str(doc.toxml())
        except (xacro.XacroException, ExpressionError, ValueError, MechanismFileError, OSError) as exc:
            where = xacro.filestack[-1] if xacro.filestack else str(path)
            raise MechanismFileError(f"xacro {where}: {_message(exc)}") from None
        except RecursionError:
            raise MechanismFileError(f"xacro {path}: macros or properties nested too deeply (recursion)") from None
        except Exception as exc:  # the library's own errors on malformed input (ExpatError, KeyError...)
            where = xacro.filestack[-1] if xacro.filestack else str(path)
            raise MechanismFileError(f"xacro {where}: {type(exc).__name__}: {_message(exc)}") from None
    if len(text) > bound("bytes"):
        raise MechanismFileError(f"xacro {path}: expands to {len(text)} characters, over the file bound")
    return text
