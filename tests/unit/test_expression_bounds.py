"""Expressions are bounded (peridyn.physics.expressions): ``9**9**9`` hung for hours and
ignored SIGTERM (the power ran in one C call); every such text is now refused at once."""

import time

import pytest

from peridyn.errors import InputError
from peridyn.physics.expressions import MAX_NODES, evaluate


@pytest.mark.parametrize(
    "text, message",
    [
        ("9**9**9", "a whole-number power of about 1.23e\\+09 bits, more than 1024"),
        ("-(10**400)", "a whole-number power of about 1.33e\\+03 bits"),
        ("(2**1000)**2", "a whole-number power of about 2e\\+03 bits"),
        ("2.0**5000", "OverflowError"),
        ("+".join(["1"] * 300), f"899 terms, more than {MAX_NODES}"),  # 300 numbers, 299 sums and their +
        ("x" * 3000, "3000 characters, more than 2000"),
        ("(" * 300 + "1" + ")" * 300, "not valid|nested too deeply"),
    ],
    ids=["tower", "negated", "squared", "float", "long sum", "long text", "nested"],
)
def test_unbounded_expressions_are_refused_at_once(text, message):
    start = time.perf_counter()
    with pytest.raises(InputError, match=message):
        evaluate(text, {}.__getitem__)
    assert time.perf_counter() - start < 1.0


def test_bounded_powers_are_exact():
    assert evaluate("2**1000", {}.__getitem__) == 2**1000  # 1001 bits: within the bound
    assert evaluate("1**(10**300)", {}.__getitem__) == 1
    assert evaluate("0.5**2000", {}.__getitem__) == 0.5**2000


def test_the_time_limit_stops_an_evaluation(monkeypatch):
    import peridyn.physics.expressions as expressions

    monkeypatch.setattr(expressions, "TIME_LIMIT_S", -1.0)  # the deadline already past
    with pytest.raises(InputError, match="not evaluated within -1 s"):
        evaluate("1 + 2", {}.__getitem__)
