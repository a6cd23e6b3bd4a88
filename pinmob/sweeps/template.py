"""Placeholders of a mechanism-file template: ``{parameter}`` or ``{expression}`` filled with a design's values.

A placeholder is text between braces that holds a name and no ``=`` (so that
TOML inline tables such as ``{ A_slider = 0.1 }`` are left alone): a parameter
name (``{link}``) or an arithmetic expression of parameters (``{sqrt(link**2 -
(R - r)**2)}``) with ``+ - * / **``, parentheses, numbers, ``pi`` and the
functions of ``FUNCTIONS`` [rad for angles]. Expressions are evaluated on their
syntax tree, never with ``eval``. The value is written with 17 significant digits.
"""

from __future__ import annotations

import ast
import math
import operator
import re
from collections.abc import Callable, Mapping

from pinmob.exceptions import ConfigurationError
from pinmob.name_matching import choices

#: ``{...}``: letters, digits, spaces and arithmetic, at least one letter, no '=' nor quotes.
PLACEHOLDER = re.compile(r"\{([0-9A-Za-z_ .+\-*/(),]*[A-Za-z_][0-9A-Za-z_ .+\-*/(),]*)\}")

FUNCTIONS: dict[str, Callable[..., float]] = {
    "sqrt": math.sqrt,
    "sin": math.sin,
    "cos": math.cos,
    "tan": math.tan,
    "asin": math.asin,
    "acos": math.acos,
    "atan": math.atan,
    "atan2": math.atan2,
    "radians": math.radians,
    "degrees": math.degrees,
    "abs": abs,
    "min": min,
    "max": max,
}
CONSTANTS = {"pi": math.pi}
_BINARY: dict[type, Callable[[float, float], float]] = {
    ast.Add: operator.add,
    ast.Sub: operator.sub,
    ast.Mult: operator.mul,
    ast.Div: operator.truediv,
    ast.Pow: operator.pow,
}


def placeholders(text: str) -> list[str]:
    """The expressions of the placeholders of a text, in order of appearance (repeats kept once)."""
    return list(dict.fromkeys(m.group(1).strip() for m in PLACEHOLDER.finditer(text)))


def names_used(expression: str, where: str) -> set[str]:
    """The parameter names an expression uses (functions and ``pi`` excluded).

    Raises:
        ConfigurationError: the expression is not arithmetic of names, numbers and ``FUNCTIONS``.
    """
    tree = _parse(expression, where)
    out = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Name) and node.id not in FUNCTIONS and node.id not in CONSTANTS:
            out.add(node.id)
    return out


def fill(text: str, values: Mapping[str, float], where: str) -> str:
    """The text with each placeholder replaced by its value.

    Raises:
        ConfigurationError: a placeholder uses a name with no value, or cannot be evaluated (e.g. sqrt of a
            negative number, or a fractional power of one, which is complex): the message names the
            placeholder and the file.
    """

    def value(match: re.Match[str]) -> str:
        expr = match.group(1).strip()
        try:
            result = _evaluate(_parse(expr, where).body, values, expr, where)
        except (ValueError, ZeroDivisionError, OverflowError, TypeError) as exc:
            raise ConfigurationError(f"{where}: placeholder {{{expr}}} cannot be evaluated here: {exc}") from None
        if not math.isfinite(result):
            raise ConfigurationError(f"{where}: placeholder {{{expr}}} is not finite here ({result})")
        return f"{result:.17g}"

    return PLACEHOLDER.sub(value, text)


def _parse(expression: str, where: str) -> ast.Expression:
    try:
        tree = ast.parse(expression, mode="eval")
    except SyntaxError:
        raise ConfigurationError(f"{where}: placeholder {{{expression}}} is not an arithmetic expression") from None
    for node in ast.walk(tree):
        ok = isinstance(node, (ast.Expression, ast.BinOp, ast.UnaryOp, ast.Name, ast.Load, ast.Call, ast.Constant))
        ok = ok or type(node) in _BINARY or isinstance(node, (ast.USub, ast.UAdd))
        if isinstance(node, ast.Call) and not (isinstance(node.func, ast.Name) and node.func.id in FUNCTIONS):
            ok = False
        if isinstance(node, ast.Constant) and not isinstance(node.value, (int, float)):
            ok = False
        if not ok:
            raise ConfigurationError(
                f"{where}: placeholder {{{expression}}}: only numbers, parameter names, + - * / **, parentheses, "
                f"pi and the functions {choices(FUNCTIONS)} are allowed"
            )
    return tree


def _evaluate(node: ast.AST, values: Mapping[str, float], expr: str, where: str) -> float:
    if isinstance(node, ast.Constant):
        return float(node.value)  # type: ignore[arg-type]  # a number: checked by _parse
    if isinstance(node, ast.Name):
        if node.id in values:
            return float(values[node.id])
        if node.id in CONSTANTS:
            return CONSTANTS[node.id]
        raise ConfigurationError(
            f"{where}: template placeholder {{{expr}}} uses {node.id!r}, which has no value; give it in [parameters] "
            f"or [design.parameters] (parameters with a value: {choices(values)})"
        )
    if isinstance(node, ast.UnaryOp):
        x = _evaluate(node.operand, values, expr, where)
        return -x if isinstance(node.op, ast.USub) else x
    if isinstance(node, ast.BinOp):
        left = _evaluate(node.left, values, expr, where)
        return _real(_BINARY[type(node.op)](left, _evaluate(node.right, values, expr, where)))
    assert isinstance(node, ast.Call) and isinstance(node.func, ast.Name)  # checked by _parse
    return _real(FUNCTIONS[node.func.id](*(_evaluate(a, values, expr, where) for a in node.args)))


def _real(value: object) -> float:
    """``value`` as a float; a complex number (``(-1) ** 0.5``) is a ValueError, caught by :func:`fill`."""
    if isinstance(value, complex):
        raise ValueError(f"its value is not a real number ({value:.6g})")
    return float(value)  # type: ignore[arg-type]  # a number: the operators and FUNCTIONS return numbers
