"""xacro's ``${...}`` expressions evaluated by pinmob: arithmetic, comparisons and math on properties, nothing else.

A xacro file is code: the PyPI ``xacro`` library evaluates ``${...}`` with Python's ``eval`` and forbids only
names that start with ``__`` at the expression's top level, so a lambda or a generator expression reaches
``os.system``, and ``xacro.load_yaml`` reads any file. pinmob parses each expression with :mod:`ast` and walks the
tree itself; it allows only:

- constants (numbers, strings, ``True``/``False``/``None``), tuples and lists of allowed expressions;
- names of properties and arguments (xacro's symbol table; a value that is a function or a module is refused);
- ``+ - * / // % **`` (a power's exponent at most :data:`MAX_EXPONENT` in size, a string or list result at
  most :data:`MAX_LENGTH` items), unary ``+ - not``, ``and``/``or``, comparisons (``== != < <= > >= in``),
  ``a if c else b``;
- calls, without keywords or ``*``, of the math functions (``sin(x)``, ``math.sin(x)``, :data:`FUNCTIONS`),
  of ``xacro.arg('name')`` (an argument's value), and of ``load_yaml('file')`` / ``xacro.load_yaml('file')``
  through the caller's confined reader (None: refused);
- ``math.<constant>`` (``math.pi``), a property of an included file's namespace (``ns.length``), and
  ``d['key']``, ``d[0]`` or ``d.key`` into what ``load_yaml`` read (dicts and lists).

Everything else (lambdas, comprehensions and generators, attributes of other objects, f-strings, walrus,
starred arguments) raises :class:`ExpressionError` naming what is not allowed, before anything is evaluated.
"""

from __future__ import annotations

import ast
import math
import operator
from collections.abc import Callable, Mapping
from typing import Any

#: math's functions whose cost grows with the value of their arguments, not its size: left out.
UNBOUNDED = ("factorial", "comb", "perm")
#: Functions an expression may call by name (and as ``math.<name>``).
FUNCTIONS: dict[str, Callable[..., Any]] = {
    # math's functions but those whose time grows with their argument's value (factorial(10**8) runs for hours)
    **{k: v for k, v in math.__dict__.items() if callable(v) and not k.startswith("_") and k not in UNBOUNDED},
    "abs": abs,
    "min": min,
    "max": max,
    "round": round,
    "int": int,
    "float": float,
    "bool": bool,
}
#: Constants of ``math`` (``math.pi``; ``pi`` is also a global symbol of xacro).
CONSTANTS = {k: v for k, v in math.__dict__.items() if isinstance(v, float)}
#: Largest exponent of ``**`` (|exponent|), longest string or list an operation may build, largest integer [bits].
MAX_EXPONENT, MAX_LENGTH, MAX_BITS = 1000, 100_000, 10_000
#: Longest expression text [characters], and deepest expression tree.
MAX_TEXT, MAX_DEPTH = 10_000, 100

_BINARY: dict[type, Callable[[Any, Any], Any]] = {
    ast.Add: operator.add,
    ast.Sub: operator.sub,
    ast.Mult: operator.mul,
    ast.Div: operator.truediv,
    ast.FloorDiv: operator.floordiv,
    ast.Mod: operator.mod,
    ast.Pow: operator.pow,
}
_COMPARE: dict[type, Callable[[Any, Any], Any]] = {
    ast.Eq: operator.eq,
    ast.NotEq: operator.ne,
    ast.Lt: operator.lt,
    ast.LtE: operator.le,
    ast.Gt: operator.gt,
    ast.GtE: operator.ge,
    ast.In: lambda a, b: a in b,
    ast.NotIn: lambda a, b: a not in b,
}
#: Plain values an expression may hold.
VALUES = (int, float, str, bool, type(None), tuple, list, dict)


class ExpressionError(ValueError):
    """An expression pinmob does not evaluate (not allowed, or out of bounds)."""


def _check(tree: ast.AST, text: str) -> None:
    """Refuse any node that is not allowed (before anything is evaluated)."""
    allowed = (
        ast.Expression, ast.Constant, ast.Name, ast.Load, ast.BinOp, ast.UnaryOp, ast.BoolOp, ast.Compare,
        ast.IfExp, ast.Call, ast.Attribute, ast.Subscript, ast.Tuple, ast.List, ast.And, ast.Or, ast.Not,
        ast.UAdd, ast.USub, *(_BINARY), *(_COMPARE),
    )  # fmt: skip
    for node in ast.walk(tree):
        if not isinstance(node, allowed):
            raise ExpressionError(f"{type(node).__name__} is not allowed in a xacro expression: {text[:80]!r}")
        if isinstance(node, ast.Call) and (node.keywords or any(isinstance(a, ast.Starred) for a in node.args)):
            raise ExpressionError(f"keyword or starred arguments are not allowed in a xacro expression: {text[:80]!r}")
        if isinstance(node, ast.Name | ast.Attribute) and (
            getattr(node, "id", "") or getattr(node, "attr", "")
        ).startswith("_"):
            raise ExpressionError(f"a name starting with '_' is not allowed in a xacro expression: {text[:80]!r}")


class Evaluator:
    """Evaluates one checked expression against xacro's symbols (see the module docstring)."""

    def __init__(
        self,
        symbols: Mapping[str, Any],
        text: str,
        load_yaml: Callable[[str], Any] | None,
        args: Mapping[str, str],
    ) -> None:
        self.symbols, self.text, self.load_yaml, self.args = symbols, text, load_yaml, args

    def refuse(self, what: str) -> ExpressionError:
        """The error naming ``what`` and the expression."""
        return ExpressionError(what)  # xacro adds "when evaluating expression '...'"

    def name(self, name: str) -> Any:
        """A property's or argument's value (a function or module is refused)."""
        try:
            value = self.symbols[name]
        except KeyError:
            raise self.refuse(f"unknown name {name!r}") from None
        if not isinstance(value, VALUES) and not _is_namespace(value):
            raise self.refuse(f"{name!r} is not a value")
        return self.bounded(value)  # a property the library joined from pieces ("${a}${a}") is checked here

    def bounded(self, value: Any) -> Any:
        """``value``, refused when a string or list is over :data:`MAX_LENGTH`."""
        if isinstance(value, str | list | tuple) and len(value) > MAX_LENGTH:
            raise self.refuse(f"a result of {len(value)} items (over {MAX_LENGTH})")
        if isinstance(value, int) and value.bit_length() > MAX_BITS:
            raise self.refuse(f"an integer of over {MAX_BITS} bits")
        return value

    def call(self, node: ast.Call) -> Any:
        """A call of a math function, ``xacro.arg`` or ``load_yaml``."""
        func = node.func
        args = [self.eval(a) for a in node.args]
        if isinstance(func, ast.Name) and func.id in FUNCTIONS:
            chosen: Callable[..., Any] = FUNCTIONS[func.id]
        elif isinstance(func, ast.Name) and func.id == "load_yaml" or (
            isinstance(func, ast.Attribute) and isinstance(func.value, ast.Name) and func.value.id == "xacro"
            and func.attr == "load_yaml"
        ):  # fmt: skip
            if self.load_yaml is None:
                raise self.refuse("load_yaml is not allowed here")
            if len(args) != 1 or not isinstance(args[0], str):
                raise self.refuse("load_yaml takes one file name")
            return self.load_yaml(args[0])
        elif isinstance(func, ast.Attribute) and isinstance(func.value, ast.Name) and func.value.id == "math":
            if func.attr not in FUNCTIONS:
                raise self.refuse(f"math.{func.attr} is not a math function")
            chosen = FUNCTIONS[func.attr]
        elif isinstance(func, ast.Attribute) and isinstance(func.value, ast.Name) and func.value.id == "xacro":
            if func.attr != "arg" or len(args) != 1 or not isinstance(args[0], str):
                raise self.refuse(f"xacro.{func.attr}(...) is not allowed (only xacro.arg('name'))")
            if args[0] not in self.args:
                raise self.refuse(f"no argument {args[0]!r}")
            return self.args[args[0]]
        else:
            raise self.refuse(f"a call of {ast.unparse(func)[:40]!r} (only math functions)")
        if any(not isinstance(a, int | float | bool) for a in args) and chosen not in (
            min,
            max,
            int,
            float,
            bool,
            abs,
            round,
        ):
            raise self.refuse("a math function called with a non-number")
        try:
            return self.bounded(chosen(*args))
        except (TypeError, ValueError, OverflowError, ZeroDivisionError) as exc:
            raise self.refuse(f"{type(exc).__name__}: {exc}") from None

    def eval(self, node: ast.AST) -> Any:
        """The value of an allowed node."""
        if isinstance(node, ast.Expression):
            return self.eval(node.body)
        if isinstance(node, ast.Constant):
            return node.value
        if isinstance(node, ast.Name):
            return self.name(node.id)
        if isinstance(node, ast.Tuple | ast.List):
            items = [self.eval(e) for e in node.elts]
            return tuple(items) if isinstance(node, ast.Tuple) else items
        if isinstance(node, ast.UnaryOp):
            value = self.eval(node.operand)
            if isinstance(node.op, ast.Not):
                return not value
            if not isinstance(value, int | float):
                raise self.refuse("a sign on a non-number")
            return -value if isinstance(node.op, ast.USub) else +value
        if isinstance(node, ast.BinOp):
            left, right = self.eval(node.left), self.eval(node.right)
            if isinstance(node.op, ast.Pow) and (not isinstance(right, int | float) or abs(right) > MAX_EXPONENT):
                raise self.refuse(f"an exponent over {MAX_EXPONENT}")
            if isinstance(left, int) and isinstance(right, int) and isinstance(node.op, ast.Pow | ast.Mult):
                bits = (
                    left.bit_length() * abs(right)
                    if isinstance(node.op, ast.Pow)
                    else left.bit_length() + right.bit_length()
                )
                if bits > MAX_BITS:
                    raise self.refuse(f"an integer of over {MAX_BITS} bits")
            if isinstance(node.op, ast.Mult) and isinstance(left, str | list | tuple) and isinstance(right, int):
                if len(left) * right > MAX_LENGTH:
                    raise self.refuse(f"a result over {MAX_LENGTH} items")
            if isinstance(node.op, ast.Mult) and isinstance(right, str | list | tuple) and isinstance(left, int):
                if len(right) * left > MAX_LENGTH:
                    raise self.refuse(f"a result over {MAX_LENGTH} items")
            try:
                return self.bounded(_BINARY[type(node.op)](left, right))
            except (TypeError, ValueError, OverflowError, ZeroDivisionError) as exc:
                raise self.refuse(f"{type(exc).__name__}: {exc}") from None
        if isinstance(node, ast.BoolOp):
            value = self.eval(node.values[0])
            for item in node.values[1:]:
                if isinstance(node.op, ast.And) and not value or isinstance(node.op, ast.Or) and value:
                    return value
                value = self.eval(item)
            return value
        if isinstance(node, ast.Compare):
            left = self.eval(node.left)
            for op, comparator in zip(node.ops, node.comparators, strict=True):
                right = self.eval(comparator)
                try:
                    if not _COMPARE[type(op)](left, right):
                        return False
                except TypeError as exc:
                    raise self.refuse(f"TypeError: {exc}") from None
                left = right
            return True
        if isinstance(node, ast.IfExp):
            return self.eval(node.body) if self.eval(node.test) else self.eval(node.orelse)
        if isinstance(node, ast.Call):
            return self.call(node)
        if isinstance(node, ast.Attribute):
            return self.attribute(node)
        if isinstance(node, ast.Subscript):
            container, key = self.eval(node.value), self.eval(node.slice)
            if not isinstance(container, dict | list | tuple | str) or not isinstance(key, int | str):
                raise self.refuse("an index into something that is not a dict, list or string")
            try:
                value = container[key]  # type: ignore[index]  # a str key into a list: the TypeError below
            except (KeyError, IndexError, TypeError) as exc:
                raise self.refuse(f"no item {key!r} ({type(exc).__name__})") from None
            if not isinstance(value, VALUES) and not _is_namespace(value):  # xacro's namespaces hold its functions
                raise self.refuse(f"item {key!r} is not a value")
            return value
        raise self.refuse(f"{type(node).__name__}")  # _check refused it already

    def attribute(self, node: ast.Attribute) -> Any:
        """``math.<constant>``, a namespace's property, or a YAML key."""
        if isinstance(node.value, ast.Name) and node.value.id == "math":
            if node.attr in CONSTANTS:
                return CONSTANTS[node.attr]
            raise self.refuse(f"math.{node.attr} is not a math constant")
        base = self.eval(node.value)
        if isinstance(base, dict) and not _is_namespace(base):
            if node.attr in base:
                return base[node.attr]
            raise self.refuse(f"no key {node.attr!r}")
        if _is_namespace(base) and not _is_builtin_namespace(base):
            try:
                value = base[node.attr]
            except KeyError:
                raise self.refuse(f"no property {node.attr!r}") from None
            if isinstance(value, VALUES) or _is_namespace(value):
                return value
        raise self.refuse(f"the attribute {node.attr!r} (only math.<constant>, a namespace's property, a YAML key)")


def _is_namespace(value: object) -> bool:
    """True for xacro's symbol tables (a ``Table``: an included file's namespace, ``math``, ``python``, ``xacro``)."""
    return type(value).__name__ in ("Table", "NameSpace")


def _is_builtin_namespace(value: object) -> bool:
    """True for xacro's own namespaces (``python``, ``math``, ``xacro``): their functions are not values."""
    return isinstance(value, dict) and any(callable(v) for v in dict.values(value))


def evaluate(
    text: str,
    symbols: Mapping[str, Any],
    load_yaml: Callable[[str], Any] | None = None,
    args: Mapping[str, str] | None = None,
) -> Any:
    """The value of xacro expression ``text`` (the inside of ``${...}``) over ``symbols``.

    Raises:
        ExpressionError: a syntax error, a construct not allowed, an unknown name, or a bound exceeded.
    """
    text = text.strip()
    if len(text) > MAX_TEXT:
        raise ExpressionError(f"a xacro expression of {len(text)} characters (over {MAX_TEXT})")
    try:
        tree = ast.parse(text, mode="eval")
    except SyntaxError as exc:
        raise ExpressionError(f"xacro expression {text[:80]!r} does not parse: {exc.msg}") from None
    except (RecursionError, MemoryError):
        raise ExpressionError(f"xacro expression {text[:80]!r} is nested too deeply") from None
    depth = _depth(tree)
    if depth > MAX_DEPTH:
        raise ExpressionError(f"xacro expression {text[:80]!r} is nested {depth} levels deep (over {MAX_DEPTH})")
    _check(tree, text)
    evaluator = Evaluator(symbols, text, load_yaml, args or {})
    value = evaluator.eval(tree)
    if _items(value) > MAX_LENGTH:  # lists of lists: each bounded, their product not
        raise evaluator.refuse(f"a result of over {MAX_LENGTH} items (nested)")
    return value


def _items(value: Any, limit: int = MAX_LENGTH) -> int:
    """How many items ``value`` holds, nested lists, tuples and dicts counted through (stops past ``limit``)."""
    if not isinstance(value, list | tuple | dict):
        return 1
    count = 0
    for item in value.values() if isinstance(value, dict) else value:
        count += _items(item, limit - count)
        if count > limit:
            break
    return count


def _depth(tree: ast.AST) -> int:
    """The depth of an expression tree (iterative: a deep tree costs no recursion)."""
    deepest, stack = 0, [(tree, 1)]
    while stack:
        node, level = stack.pop()
        deepest = max(deepest, level)
        stack.extend((child, level + 1) for child in ast.iter_child_nodes(node))
    return deepest
