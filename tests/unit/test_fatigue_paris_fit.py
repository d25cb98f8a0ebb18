"""Paris slope of a fatigue run's crack-length staircase (V5: thesis seed 002 eqs. 7.10-7.14).

A synthetic history is made from a known Paris law da/dN = c dK^4 whose dK grows with the crack
as K = K_0 (a / a_0)^1.57 (the compliance K of the thesis's 50 x 8 mm specimen, 2D 0.2 mm: see
test_fatigue_paris_specimen), recorded the way the model records it: the crack length jumps by
one spacing (1 mm) at the cycle the true crack passes the next column, with steps in between.
"""

import numpy as np
import pytest

from peridyn.fatigue.calibration import stress_intensity
from peridyn.fatigue.loop import FatigueResult
from peridyn.io.case import load_case
from peridyn.jobs.fatigue import paris_rates, paris_slope

M, C, A0, K0, GROWTH = 4.0, 1e-38, 5e-3, 23e6, 1.57


def _k_true(a):
    return K0 * (np.asarray(a) / A0) ** GROWTH


def _cycles_to(a):
    """N(a) = int_a0^a da / (c dK^M), dK = 0.95 K (R = 0.05), in closed form for the power law."""
    p = 1.0 - M * GROWTH
    scale = C * (0.95 * K0) ** M * A0 ** (-M * GROWTH)
    return (np.asarray(a) ** p - A0**p) / (p * scale)


def _staircase(spacing=1e-3, a_end=20e-3, steps_between=3):
    """Cycles and crack lengths of a run: jumps of one spacing, ``steps_between`` quiet steps."""
    columns = np.arange(A0, a_end + 0.5 * spacing, spacing)
    n_jump = _cycles_to(columns)
    cycles, lengths = [0.0], [0.0]  # the pre-crack is not cracked through at the start
    for i, (n, a) in enumerate(zip(n_jump, columns, strict=True)):
        if i > 0:
            quiet = np.linspace(n_jump[i - 1], n, steps_between + 2)[1:-1]
            cycles += quiet.tolist()
            lengths += [columns[i - 1]] * steps_between
        cycles.append(n)
        lengths.append(a)
    n = len(cycles)
    return FatigueResult(np.array(cycles), np.array(lengths), np.zeros(n, np.int64), None, None, None)


@pytest.fixture(scope="module")
def sen_case():
    return load_case("cases/sen_fatigue.yaml")


def test_staircase_with_the_specimen_k_gives_m_back(sen_case):
    """Eq. 7.14 rates between 1 mm jumps, each at the mean of its two lengths, against the
    specimen's K: the fitted slope is M = 4 within 2 % (midpoint error of one-spacing jumps)."""
    history = _staircase()
    grid = np.arange(A0, 21e-3, 1e-3)
    slope = paris_slope(sen_case, history, (grid, _k_true(grid)))
    assert slope == pytest.approx(M, rel=0.02)
    dk, rate = paris_rates(sen_case, history, (grid, _k_true(grid)))
    # every rate on the Paris line, not just the fit: a jump's rate is the harmonic mean over its
    # interval, put at its midpoint, a second-order error largest on the shortest crack (6.5 % at
    # a = 5.5 mm, h / a = 0.18; 2.7 % at 8.5 mm), under 2 % from a = 10.5 mm on
    assert rate == pytest.approx(C * dk**M, rel=0.08)
    assert rate[5:] == pytest.approx(C * dk[5:] ** M, rel=0.02)


def test_fit_range_keeps_only_the_rates_inside_it(sen_case):
    """``paris.fit_range`` (phase II window) drops the rates whose mean crack length is outside."""
    history = _staircase()
    case = sen_case.model_copy(deep=True)
    case.fatigue.paris.fit_range = (8e-3, 15e-3)
    grid = np.arange(A0, 21e-3, 1e-3)
    dk, rate = paris_rates(case, history, (grid, _k_true(grid)))
    mids = np.arange(A0 + 1.5e-3, 20e-3, 1e-3)  # rates start between the first two jumps
    expected = mids[(mids >= 8e-3) & (mids <= 15e-3)]
    assert rate.size == expected.size
    assert dk == pytest.approx(0.95 * _k_true(expected), rel=1e-9)


def test_eq_7_12_on_a_specimen_with_another_k_bends_the_slope(sen_case):
    """Plotted against eq. 7.12 (K growing as a^0.82 over a = 6-14 mm at b = 50 mm) instead of
    the specimen's a^1.57, the same Paris law of exponent 4 shows a slope near 4 x 1.57 / 0.82,
    7.6: the 1 mm run's 6.5-7.5 comes from the K, not from the model."""
    history = _staircase(a_end=15e-3)
    slope = paris_slope(sen_case, history)  # k_curve None: eq. 7.12
    a = np.linspace(6e-3, 14e-3, 9)
    k_growth = np.polyfit(np.log(a), np.log(stress_intensity(50e6, a, 0.05)), 1)[0]
    assert slope == pytest.approx(M * GROWTH / k_growth, rel=0.05)
    assert slope > 1.5 * M


def test_fit_range_must_be_increasing():
    from peridyn.errors import CaseFileError

    with pytest.raises(CaseFileError, match=r"paris.fit_range must be \[shortest, longest\]"):
        load_case("cases/sen_fatigue.yaml", ["fatigue.paris.fit_range=[0.02, 0.01]"])
