"""A small, safe evaluator for the entries of model-structure matrices.

Entries are numbers, parameter names, trim constants, or arithmetic on them
(``-g*cos(theta0)``, ``1/T_a``, ``Z_q + U0``). The text is parsed with
:mod:`ast` and compiled into nested closures; only numbers, names, ``+ - * /
**``, unary ``+ -`` and the functions ``sin cos tan exp sqrt`` are accepted.
Nothing is ever passed to ``eval``. Every operation is analytic, so an
expression evaluated at a complex parameter gives exact complex-step
derivatives.
"""

from __future__ import annotations

import ast
import operator
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field

import numpy as np

from flightlogs.errors import ModelError

__all__ = ["Expression", "parse_expression", "FUNCTIONS"]

Value = float | complex
_Compiled = Callable[[Mapping[str, Value]], Value]

#: Functions an expression may call (all analytic, so complex-step derivatives are exact).
FUNCTIONS: Mapping[str, Callable[[Value], Value]] = {
    "sin": np.sin,
    "cos": np.cos,
    "tan": np.tan,
    "exp": np.exp,
    "sqrt": np.sqrt,
}
_BINARY: dict[type, Callable[[Value, Value], Value]] = {
    ast.Add: operator.add,
    ast.Sub: operator.sub,
    ast.Mult: operator.mul,
    ast.Div: operator.truediv,
    ast.Pow: operator.pow,
}
_UNARY: dict[type, Callable[[Value], Value]] = {ast.UAdd: operator.pos, ast.USub: operator.neg}
_MAX_LENGTH = 200


@dataclass(frozen=True, slots=True)
class Expression:
    """A parsed matrix entry.

    Parameters
    ----------
    text : str
        The source text, e.g. ``"-g*cos(theta0)"``.
    names : frozenset of str
        Parameter and constant names it reads.
    function : callable
        ``function(values) -> value``: the compiled expression; `values` maps
        every name in `names` to a float or complex number.

    Examples
    --------
    >>> e = parse_expression("-g*cos(theta0) + 2*X_u")
    >>> sorted(e.names)
    ['X_u', 'g', 'theta0']
    >>> float(e({"g": 9.81, "theta0": 0.0, "X_u": -0.5}))
    -10.81
    """

    text: str
    names: frozenset[str]
    function: _Compiled = field(repr=False, compare=False)

    def __call__(self, values: Mapping[str, Value]) -> Value:
        """Value of the expression.

        Parameters
        ----------
        values : Mapping[str, float or complex]
            A value for every name the expression reads.
        """
        try:
            return self.function(values)
        except KeyError as err:
            raise ModelError(f"expression {self.text!r} reads {err.args[0]!r}, which has no value") from None
        except (ZeroDivisionError, OverflowError) as err:
            raise ModelError(f"expression {self.text!r} cannot be evaluated ({err})") from err

    @property
    def constant(self) -> bool:
        """True when the expression reads no name."""
        return not self.names


def parse_expression(text: str | float | int, *, where: str = "") -> Expression:
    """Parse one matrix entry into an :class:`Expression`.

    Parameters
    ----------
    text : str or float or int
        The entry as written in the structure file.
    where : str, optional
        Where it was written (e.g. ``"F[u, theta]"``), for error messages.

    Returns
    -------
    Expression

    Raises
    ------
    ModelError
        If the text is not a number, a name or arithmetic on them.

    Examples
    --------
    >>> parse_expression("1/T_a")({"T_a": 0.05})
    20.0
    >>> parse_expression("__import__('os')")
    Traceback (most recent call last):
    ...
    flightlogs.errors.ModelError: entry __import__('os'): only numbers, names, + - * / ** and sin cos tan exp sqrt are allowed, not a call of __import__
    """
    label = f"{where} " if where else ""
    if isinstance(text, bool) or not isinstance(text, (str, int, float)):
        raise ModelError(f"{label}entry {text!r} must be a number or a text expression")
    if not isinstance(text, str):
        value = float(text)
        return Expression(repr(value), frozenset(), lambda _values: value)
    if len(text) > _MAX_LENGTH:
        raise ModelError(f"{label}entry {text[:40]!r}... is longer than {_MAX_LENGTH} characters")
    try:
        tree = ast.parse(text.strip(), mode="eval")
    except SyntaxError as err:
        raise ModelError(f"{label}entry {text!r} is not a valid expression ({err.msg})") from err
    names: set[str] = set()
    function = _compile(tree.body, text, label, names)
    return Expression(text, frozenset(names), function)


def _compile(node: ast.AST, text: str, label: str, names: set[str]) -> _Compiled:
    """Turn an AST node into a closure, refusing anything outside the small grammar."""
    if isinstance(node, ast.Constant) and isinstance(node.value, (int, float)) and not isinstance(node.value, bool):
        number = float(node.value)
        return lambda _values: number
    if isinstance(node, ast.Name):
        name = node.id
        names.add(name)
        return lambda values: values[name]
    if isinstance(node, ast.BinOp) and type(node.op) in _BINARY:
        op, left, right = (
            _BINARY[type(node.op)],
            _compile(node.left, text, label, names),
            _compile(node.right, text, label, names),
        )
        return lambda values: op(left(values), right(values))
    if isinstance(node, ast.UnaryOp) and type(node.op) in _UNARY:
        unary, operand = _UNARY[type(node.op)], _compile(node.operand, text, label, names)
        return lambda values: unary(operand(values))
    if (
        isinstance(node, ast.Call)
        and isinstance(node.func, ast.Name)
        and node.func.id in FUNCTIONS
        and len(node.args) == 1
        and not node.keywords
    ):
        function, argument = FUNCTIONS[node.func.id], _compile(node.args[0], text, label, names)
        return lambda values: function(argument(values))
    what = (
        f"a call of {node.func.id}"
        if isinstance(node, ast.Call) and isinstance(node.func, ast.Name)
        else (f"{type(node).__name__}")
    )
    raise ModelError(
        f"{label}entry {text}: only numbers, names, + - * / ** and sin cos tan exp sqrt are allowed, not {what}"
    )
