"""Transfer-function structures: ``p/delta_lat = b2*s^2/(s^4 + a3*s^3 + a2*s^2 + a1*s + a0)``.

The numerator and the denominator are polynomials in ``s`` written out as
sums of terms; each term is a number, a parameter, or a number times a
parameter, times a power of ``s``. Every coefficient is then linear in the
parameters, which gives the fit its deterministic start (a linear
least-squares fit of the measured response, :mod:`sysid.fit.transfer`). A
term without a parameter (the ``s^4`` of a monic denominator) fixes the
scale; without one, numerator and denominator could be scaled together.
The text is parsed with :mod:`ast` and walked; nothing is evaluated.
"""

from __future__ import annotations

import ast
import re
from dataclasses import dataclass

import numpy as np

from flightlogs.errors import ModelError

__all__ = ["Term", "TransferStructure", "parse_transfer_function"]

_FORM = (
    "write it as OUTPUT/INPUT = numerator/denominator, each a sum of terms like 2.5*b1*s^2, a0 or s^4 "
    "(a number, a parameter or a number times a parameter, times a power of s)"
)
_NAME = re.compile(r"^[A-Za-z_][A-Za-z0-9_]*$")


@dataclass(frozen=True, slots=True)
class Term:
    """One term of a polynomial in s: ``factor * parameter * s^power``.

    Parameters
    ----------
    factor : float
        The number multiplying it.
    parameter : str or None
        The parameter it carries, or None for a fixed term.
    power : int
        The power of s, >= 0.
    """

    factor: float
    parameter: str | None
    power: int


@dataclass(frozen=True, slots=True, kw_only=True)
class TransferStructure:
    """A transfer function of one pair with linear-in-parameter polynomial coefficients.

    Parameters
    ----------
    text : str
        The expression as given.
    output, input : str
        The pair's signals (``p``, ``delta_lat``).
    numerator, denominator : tuple of Term
        The polynomials' terms.
    parameters : tuple of str
        Parameter names, in order of first appearance.
    """

    text: str
    output: str
    input: str
    numerator: tuple[Term, ...]
    denominator: tuple[Term, ...]
    parameters: tuple[str, ...]

    @property
    def pair(self) -> str:
        """``output/input``."""
        return f"{self.output}/{self.input}"

    def parameter_units(self, output_unit: str, input_unit: str) -> dict[str, str]:
        """Each parameter's unit, from the response's units and the power of s it multiplies.

        The fixed term (the ``s^n`` of a monic denominator) sets the scale:
        with it in the denominator, a denominator coefficient of ``s^k`` is in
        s^(k-n) (``a0`` of ``s^2 + a1 s + a0`` in 1/s^2) and a numerator one in
        output per input times s^(k-n); with it in the numerator, the other way round.

        Parameters
        ----------
        output_unit, input_unit : str
            The response's units ("rad/s", "normalised (-1..1)").

        Returns
        -------
        dict of str to str
            By parameter name; a parameter met at two powers is ``"mixed"``.

        Examples
        --------
        >>> tf = parse_transfer_function("p/delta_lat = b0/(s^2 + a1*s + a0)")
        >>> tf.parameter_units("rad/s", "normalised")
        {'b0': 'rad/s per normalised, s^-2', 'a1': 's^-1', 'a0': 's^-2'}
        """
        fixed_in_denominator = any(t.parameter is None for t in self.denominator)
        reference = max(
            t.power for t in (self.denominator if fixed_in_denominator else self.numerator) if t.parameter is None
        )
        ratio = f"{output_unit or '1'} per {input_unit or '1'}"
        inverse = f"{input_unit or '1'} per {output_unit or '1'}"
        units: dict[str, str] = {}
        for terms, scaled in ((self.numerator, fixed_in_denominator), (self.denominator, not fixed_in_denominator)):
            for term in terms:
                if term.parameter is None:
                    continue
                time = f"s^{term.power - reference}" if term.power != reference else ""
                base = (ratio if fixed_in_denominator else inverse) if scaled else ""
                unit = ", ".join(part for part in (base, time) if part) or "1"
                units[term.parameter] = unit if units.get(term.parameter, unit) == unit else "mixed"
        return {name: units[name] for name in self.parameters}

    def coefficients(self, values: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Numerator and denominator coefficients, highest power first (numpy.polyval order).

        Parameters
        ----------
        values : ndarray, shape (n_parameters,)
            Parameter values, in :attr:`parameters` order.

        Returns
        -------
        numerator, denominator : ndarray
            Shapes (order + 1,).
        """
        return self._polynomial(self.numerator, values), self._polynomial(self.denominator, values)

    def basis(self, s: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """Each polynomial as ``fixed(s) + basis(s) @ values``: both linear in the parameters.

        Parameters
        ----------
        s : ndarray of complex, shape (n_points,)
            Laplace variable, ``1j omega``.

        Returns
        -------
        numerator_fixed, denominator_fixed : ndarray of complex, shape (n_points,)
        numerator_basis, denominator_basis : ndarray of complex, shape (n_points, n_parameters)
        """
        out = []
        for terms in (self.numerator, self.denominator):
            fixed = np.zeros(s.shape, dtype=complex)
            basis = np.zeros((s.size, len(self.parameters)), dtype=complex)
            for term in terms:
                value = term.factor * s**term.power
                if term.parameter is None:
                    fixed += value
                else:
                    basis[:, self.parameters.index(term.parameter)] += value
            out += [fixed, basis]
        return out[0], out[2], out[1], out[3]

    def _polynomial(self, terms: tuple[Term, ...], values: np.ndarray) -> np.ndarray:
        order = max(t.power for t in terms)
        coefficients = np.zeros(order + 1)
        for t in terms:
            weight = 1.0 if t.parameter is None else float(values[self.parameters.index(t.parameter)])
            coefficients[order - t.power] += t.factor * weight
        return coefficients


def parse_transfer_function(text: str) -> TransferStructure:
    """Parse ``OUTPUT/INPUT = numerator/denominator``.

    Parameters
    ----------
    text : str
        E.g. ``"p/delta_lat = b2*s^2/(s^4 + a3*s^3 + a2*s^2 + a1*s + a0)"``
        (``^`` or ``**`` for powers).

    Returns
    -------
    TransferStructure

    Raises
    ------
    ModelError
        One sentence naming what is not of the form.

    Examples
    --------
    >>> tf = parse_transfer_function("p/delta_lat = b2*s^2/(s^4 + a3*s^3 + a0)")
    >>> tf.pair, tf.parameters
    ('p/delta_lat', ('b2', 'a3', 'a0'))
    >>> [c.tolist() for c in tf.coefficients(np.array([2.0, 3.0, 4.0]))]
    [[2.0, 0.0, 0.0], [1.0, 3.0, 0.0, 0.0, 4.0]]
    """
    pair, equals, expression = text.partition("=")
    output, slash, signal = pair.strip().partition("/")
    if not equals or not slash or not _NAME.match(output.strip()) or not _NAME.match(signal.strip()):
        raise ModelError(f"transfer function {text!r}: no OUTPUT/INPUT = ... pair; {_FORM}")
    try:
        tree = ast.parse(expression.strip().replace("^", "**"), mode="eval").body
    except SyntaxError:
        raise ModelError(f"transfer function {text!r}: not an expression; {_FORM}") from None
    if isinstance(tree, ast.BinOp) and isinstance(tree.op, ast.Div) and _is_sum(tree.right):
        numerator, denominator = _terms(tree.left, text), _terms(tree.right, text)
    else:
        numerator, denominator = _terms(tree, text), (Term(1.0, None, 0),)
    names = tuple(dict.fromkeys(t.parameter for t in (*numerator, *denominator) if t.parameter is not None))
    if not names:
        raise ModelError(f"transfer function {text!r}: no parameter to fit")
    if all(t.parameter is not None for t in (*numerator, *denominator)):
        raise ModelError(
            f"transfer function {text!r}: every term carries a parameter, so numerator and denominator "
            "scale together; fix one term (a monic denominator: s^4 + a3*s^3 + ...)"
        )
    return TransferStructure(
        text=text.strip(),
        output=output.strip(),
        input=signal.strip(),
        numerator=numerator,
        denominator=denominator,
        parameters=names,
    )


def _is_sum(node: ast.AST) -> bool:
    """Whether `node` can be a polynomial (not a term of the numerator divided by a number)."""
    return not isinstance(node, ast.Constant)


def _terms(node: ast.AST, text: str) -> tuple[Term, ...]:
    """The terms of a sum, each with its sign."""
    if isinstance(node, ast.BinOp) and isinstance(node.op, (ast.Add, ast.Sub)):
        right = _terms(node.right, text)
        if isinstance(node.op, ast.Sub):
            right = tuple(Term(-t.factor, t.parameter, t.power) for t in right)
        return (*_terms(node.left, text), *right)
    return (_term(node, text),)


def _term(node: ast.AST, text: str) -> Term:
    """``number * parameter * s^k`` from a product of factors."""
    factor, parameter, power = 1.0, None, 0
    for item in _factors(node, text):
        if isinstance(item, float):
            factor *= item
        elif isinstance(item, int):
            power += item
        elif parameter is None:
            parameter = item
        else:
            raise ModelError(f"transfer function {text!r}: {parameter}*{item} is a product of parameters; {_FORM}")
    return Term(factor, parameter, power)


def _factors(node: ast.AST, text: str) -> list[float | int | str]:
    """A product's factors: floats (numbers), ints (powers of s) and strs (parameters)."""
    if isinstance(node, ast.BinOp) and isinstance(node.op, ast.Mult):
        return [*_factors(node.left, text), *_factors(node.right, text)]
    if isinstance(node, ast.UnaryOp) and isinstance(node.op, (ast.USub, ast.UAdd)):
        inner = _factors(node.operand, text)
        return [-1.0, *inner] if isinstance(node.op, ast.USub) else inner
    if isinstance(node, ast.Constant) and isinstance(node.value, (int, float)) and not isinstance(node.value, bool):
        return [float(node.value)]
    if isinstance(node, ast.Name):
        return [1] if node.id == "s" else [node.id]
    if (
        isinstance(node, ast.BinOp)
        and isinstance(node.op, ast.Pow)
        and isinstance(node.left, ast.Name)
        and node.left.id == "s"
        and isinstance(node.right, ast.Constant)
        and isinstance(node.right.value, int)
        and node.right.value >= 0
    ):
        return [int(node.right.value)]
    raise ModelError(f"transfer function {text!r}: {ast.unparse(node)!r} is not a term; {_FORM}")
