"""A small, safe arithmetic language: a sweep's ``derived:`` values and the values of boundary
conditions given as expressions in x, y, z (m) and t (s) (``SpaceTime``, e.g. a Peridigm
deck's ``"0.001*y*t/1.0e-8"``).

An expression is numbers, names, ``+ - * / **``, unary minus, brackets, list indexing by a whole
number (``geometry.size[0]``) and the functions ``min``, ``max``, ``abs``, ``sqrt``, ``round``,
``sin``, ``cos``, ``exp``, ``log``; names may stand for NumPy arrays, and the whole
expression is then evaluated element by element (``min``/``max`` of arrays element-wise).
A name is a dotted path (``discretization.spacing``, ``crack_cells``; ``precracks[0].end[1]``
for ``precracks.0.end.1``): ``lookup(path)`` gives its value (a varied parameter, or a case
entry). Nothing else is accepted: the text is parsed with :mod:`ast` and only these nodes are
evaluated, so no Python code ever runs.

An expression is bounded, so that no text can take the machine's memory or time: at most
``MAX_LENGTH`` characters and ``MAX_NODES`` syntax nodes, whole-number powers whose result
stays within ``MAX_INT_BITS`` bits (``9**9**9`` is refused at once; a float power overflows
to an error), and at most ``TIME_LIMIT_S`` seconds of evaluation.

>>> evaluate("3 * discretization.spacing + 1", {"discretization.spacing": 0.5}.__getitem__)
2.5
>>> evaluate("max(size[1], 2) ** 2", {"size": [1.0, 3.0]}.__getitem__)
9.0
"""

from __future__ import annotations

import ast
import math
import operator
import time
from dataclasses import dataclass

import numpy as np

from peridyn.errors import InputError

#: The longest expression text, in characters.
MAX_LENGTH = 2000
#: The most syntax nodes of an expression.
MAX_NODES = 500
#: The largest whole number a power may give, in bits (a float's range is 2**1024).
MAX_INT_BITS = 1024
#: The longest evaluation of an expression, in seconds.
TIME_LIMIT_S = 10.0


def _power(base, exponent):
    """``base ** exponent``, refusing a whole-number power beyond ``MAX_INT_BITS`` bits
    (Python would compute it exactly, for hours, in unbounded memory)."""
    if (
        isinstance(base, int)
        and isinstance(exponent, int)
        and abs(base) > 1
        and exponent > 0
        and exponent * math.log2(abs(base)) > MAX_INT_BITS
    ):
        raise OverflowError(
            f"a whole-number power of about {exponent * math.log2(abs(base)):.3g} bits, more than "
            f"{MAX_INT_BITS}"
        )
    return operator.pow(base, exponent)


_BINARY = {
    ast.Add: operator.add,
    ast.Sub: operator.sub,
    ast.Mult: operator.mul,
    ast.Div: operator.truediv,
    ast.Pow: _power,
}


def _either(scalar, array):
    """A function that is ``scalar`` on plain numbers (their values and types unchanged) and
    ``array`` as soon as one argument is a NumPy array."""

    def call(*args):
        if any(isinstance(a, np.ndarray) for a in args):
            return array(*args)
        return scalar(*args)

    return call


def _elementwise(reduce):
    return lambda *args: reduce(np.broadcast_arrays(*args), axis=0)


_FUNCTIONS = {
    "min": _either(min, _elementwise(np.min)),
    "max": _either(max, _elementwise(np.max)),
    "abs": _either(abs, np.abs),
    "sqrt": _either(math.sqrt, np.sqrt),
    "round": _either(round, np.round),
    "sin": _either(math.sin, np.sin),
    "cos": _either(math.cos, np.cos),
    "exp": _either(math.exp, np.exp),
    "log": _either(math.log, np.log),
}


def evaluate(text: str, lookup):
    """The value of the expression ``text``.

    Parameters
    ----------
    text : str
        The expression.
    lookup : callable(path: str) -> value
        The value of a dotted name; raises ``KeyError`` for an unknown one.

    Raises
    ------
    InputError
        A syntax error, a construct outside the language, an unknown name, an arithmetic
        error (division by zero, a power too large...) or an expression over the bounds
        (``MAX_LENGTH``, ``MAX_NODES``, ``TIME_LIMIT_S``), naming the expression.
    """
    text = str(text)
    shown = text if len(text) <= 80 else text[:77] + "..."
    if len(text) > MAX_LENGTH:
        raise InputError(f"expression {shown!r}: {len(text)} characters, more than {MAX_LENGTH}")
    try:
        tree = ast.parse(text, mode="eval")
    except SyntaxError as exc:
        raise InputError(f"expression {shown!r}: not valid ({exc.msg})") from None
    except (RecursionError, MemoryError):
        raise InputError(f"expression {shown!r}: nested too deeply") from None
    nodes = sum(1 for _ in ast.walk(tree))
    if nodes > MAX_NODES:
        raise InputError(f"expression {shown!r}: {nodes} terms, more than {MAX_NODES}")
    deadline = time.monotonic() + TIME_LIMIT_S
    try:
        return _eval(tree.body, lookup, text, deadline)
    except (ArithmeticError, TypeError, ValueError, IndexError) as exc:
        raise InputError(f"expression {shown!r}: {type(exc).__name__}: {exc}") from None


def _path(node) -> str | None:
    """The dotted path of a chain of names, attributes and whole-number indices
    (``precracks[0].end[1]`` -> ``precracks.0.end.1``), else None."""
    if isinstance(node, ast.Name):
        return node.id
    if isinstance(node, ast.Attribute):
        head = _path(node.value)
        return None if head is None else f"{head}.{node.attr}"
    if (
        isinstance(node, ast.Subscript)
        and isinstance(node.slice, ast.Constant)
        and type(node.slice.value) is int
    ):
        head = _path(node.value)
        return None if head is None else f"{head}.{node.slice.value}"
    return None


def _eval(node, lookup, text, deadline):
    if time.monotonic() > deadline:
        raise InputError(f"expression {text!r}: not evaluated within {TIME_LIMIT_S:g} s")
    if (
        isinstance(node, ast.Constant)
        and isinstance(node.value, int | float)
        and not isinstance(node.value, bool)
    ):
        return node.value
    path = _path(node)
    if path is not None:
        try:
            return lookup(path)
        except KeyError:
            if not isinstance(node, ast.Subscript):  # else: the list, then its item
                raise InputError(
                    f"expression {text!r}: unknown name {path!r} (a varied parameter or a case entry)"
                ) from None
    if isinstance(node, ast.BinOp) and type(node.op) in _BINARY:
        return _BINARY[type(node.op)](
            _eval(node.left, lookup, text, deadline), _eval(node.right, lookup, text, deadline)
        )
    if isinstance(node, ast.UnaryOp) and isinstance(node.op, ast.USub | ast.UAdd):
        value = _eval(node.operand, lookup, text, deadline)
        return -value if isinstance(node.op, ast.USub) else +value
    if isinstance(node, ast.Subscript):
        index = _eval(node.slice, lookup, text, deadline)
        if not isinstance(index, int):
            raise InputError(f"expression {text!r}: a list index must be a whole number, got {index!r}")
        return _eval(node.value, lookup, text, deadline)[index]
    if (
        isinstance(node, ast.Call)
        and isinstance(node.func, ast.Name)
        and node.func.id in _FUNCTIONS
        and not node.keywords
    ):
        return _FUNCTIONS[node.func.id](*(_eval(a, lookup, text, deadline) for a in node.args))
    raise InputError(
        f"expression {text!r}: {ast.unparse(node)!r} is not allowed (numbers, names, + - * / **, "
        f"[index] and {', '.join(_FUNCTIONS)} only)"
    )


@dataclass(frozen=True)
class SpaceTime:
    """A value given by an expression ``text`` in the coordinates x, y, z (m) of a point and
    the time t (s), e.g. a prescribed displacement ``0.001*y*t/1.0e-8`` (m).

    >>> SpaceTime("2*x + t").at(np.array([[1.0, 0, 0], [3.0, 0, 0]]), 0.5).tolist()
    [2.5, 6.5]
    """

    text: str

    def __post_init__(self):
        self.at(np.zeros((1, 3)), 0.0)  # refuses a bad expression or an unknown name now

    def at(self, points: np.ndarray, t: float) -> np.ndarray:
        """(n,) values at the points (n, 3), m, at time ``t`` (s)."""
        names = {"x": points[:, 0], "y": points[:, 1], "z": points[:, 2], "t": float(t)}

        def lookup(name):
            if name not in names:
                raise InputError(f"expression {self.text!r}: unknown name {name!r}; use x, y, z and t")
            return names[name]

        with np.errstate(all="ignore"):
            value = np.broadcast_to(np.asarray(evaluate(self.text, lookup), dtype=float), len(points))
        if not np.all(np.isfinite(value)):
            raise InputError(f"expression {self.text!r}: not finite at t = {t:g} s on some points")
        return value

    def derivative(self, points: np.ndarray, t: float, dt: float) -> np.ndarray:
        """(n,) central difference in time, (f(t + dt/2) - f(t - dt/2)) / dt, as time functions have."""
        return (self.at(points, t + 0.5 * dt) - self.at(points, t - 0.5 * dt)) / dt
