"""The small arithmetic language of a sweep's ``derived:`` values.

An expression is numbers, names, ``+ - * / **``, unary minus, brackets, list indexing by a whole
number (``geometry.size[0]``) and the functions ``min``, ``max``, ``abs``, ``sqrt``, ``round``.
A name is a dotted path (``discretization.spacing``, ``crack_cells``; ``precracks[0].end[1]``
for ``precracks.0.end.1``): ``lookup(path)`` gives its value (a varied parameter, or a case
entry). Nothing else is accepted: the text is parsed with :mod:`ast` and only these nodes are
evaluated, so no Python code ever runs.

>>> evaluate("3 * discretization.spacing + 1", {"discretization.spacing": 0.5}.__getitem__)
2.5
>>> evaluate("max(size[1], 2) ** 2", {"size": [1.0, 3.0]}.__getitem__)
9.0
"""

from __future__ import annotations

import ast
import math
import operator

from peridyn.errors import InputError

_BINARY = {
    ast.Add: operator.add,
    ast.Sub: operator.sub,
    ast.Mult: operator.mul,
    ast.Div: operator.truediv,
    ast.Pow: operator.pow,
}
_FUNCTIONS = {"min": min, "max": max, "abs": abs, "sqrt": math.sqrt, "round": round}


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
        A syntax error, a construct outside the language, an unknown name or an arithmetic
        error (division by zero...), naming the expression.
    """
    try:
        tree = ast.parse(str(text), mode="eval")
    except SyntaxError as exc:
        raise InputError(f"expression {text!r}: not valid ({exc.msg})") from None
    try:
        return _eval(tree.body, lookup, text)
    except (ArithmeticError, TypeError, ValueError, IndexError) as exc:
        raise InputError(f"expression {text!r}: {type(exc).__name__}: {exc}") from None


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


def _eval(node, lookup, text):
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
        return _BINARY[type(node.op)](_eval(node.left, lookup, text), _eval(node.right, lookup, text))
    if isinstance(node, ast.UnaryOp) and isinstance(node.op, ast.USub | ast.UAdd):
        value = _eval(node.operand, lookup, text)
        return -value if isinstance(node.op, ast.USub) else +value
    if isinstance(node, ast.Subscript):
        index = _eval(node.slice, lookup, text)
        if not isinstance(index, int):
            raise InputError(f"expression {text!r}: a list index must be a whole number, got {index!r}")
        return _eval(node.value, lookup, text)[index]
    if (
        isinstance(node, ast.Call)
        and isinstance(node.func, ast.Name)
        and node.func.id in _FUNCTIONS
        and not node.keywords
    ):
        return _FUNCTIONS[node.func.id](*(_eval(a, lookup, text) for a in node.args))
    raise InputError(
        f"expression {text!r}: {ast.unparse(node)!r} is not allowed (numbers, names, + - * / **, "
        f"[index] and {', '.join(_FUNCTIONS)} only)"
    )
