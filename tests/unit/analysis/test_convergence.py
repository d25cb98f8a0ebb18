"""Richardson extrapolation (peridyn.analysis.convergence) against data built from its own model.

Source of the formulas: seed 002 eqs. 6.3-6.5 (f = f_inf + C h^p), Roache 1998 ch. 5 and
Celik et al. 2008 (three grids, any refinement ratio), Roache 1994 (GCI).
"""

import numpy as np
import pytest

from peridyn.analysis.convergence import ConvergenceError, richardson
from peridyn.errors import InputError

#: f = a + b h^p: the continuum value of issue 9's FE (1st bending, Hz), an order in the
#: thesis's range (table 6.1: 1 < p < 2) and a slope giving a few-% error at 1 mm.
A, P, B = 1706.1, 1.7, 3.0e7


def _exact(h):
    return A + B * np.asarray(h) ** P


@pytest.mark.parametrize(
    "spacings",
    [
        [1e-3, 1.5e-3, 2.25e-3],  # constant ratio 1.5
        [0.4e-3, 0.667e-3, 1e-3],  # varying ratio (the thesis's 625k, 135k, 40k grids)
        [2.25e-3, 1e-3, 1.5e-3],  # any order in
    ],
)
def test_three_points_recover_order_and_limit_exactly(spacings):
    fit = richardson(spacings, _exact(spacings))
    assert abs(fit.order - P) < 1e-10
    assert abs(fit.value - A) / A < 1e-10
    assert abs(fit.coefficient - B) / B < 1e-8
    assert fit.spacings[0] == min(spacings)  # finest first


def test_more_points_least_squares_recover_order_and_limit_exactly():
    h = np.array([0.4e-3, 0.5e-3, 0.667e-3, 1e-3, 1.3e-3])
    fit = richardson(h, _exact(h))
    assert abs(fit.order - P) < 1e-10
    assert abs(fit.value - A) / A < 1e-10
    assert fit.rms_residual < 1e-8


def test_decreasing_sequence_and_high_order():
    # f approaching from above and below are the same problem: p = 2 from below
    h = np.array([1.0, 2.0, 4.0])
    fit = richardson(h, 10.0 - 0.5 * h**2)
    assert abs(fit.order - 2.0) < 1e-10 and abs(fit.value - 10.0) < 1e-10


def test_gci_of_constant_ratio_matches_roache_formula():
    # Roache 1994: GCI = 1.25 |(f2 - f1)/f1| / (r^p - 1); for exact data the true
    # relative error of f1, |f1 - A|/f1 = |f2 - f1| / f1 / (r^p - 1), times 1.25.
    h = np.array([1e-3, 2e-3, 4e-3])
    f = _exact(h)
    fit = richardson(h, f)
    assert abs(fit.gci - 1.25 * abs(f[0] - A) / f[0]) < 1e-12


def test_noisy_data_within_propagated_error():
    # Relative noise 1e-5 on six grids. First-order propagation through the two finest
    # (r = 1.25, p = 1.7, f2 - f1 = 23 Hz): with p known, |df_inf| <~ (1 + 2/(r^p - 1)) * 1e-5
    # = 5e-5 of A; the noise also moves p by ~ 2 * 1.7e-2 Hz / 23 Hz / ln r = 7e-3, which
    # moves f_inf by 36 Hz per unit p: 1.5e-4 of A in all. Bounds: twice these (3e-4, 0.015);
    # the least-squares fit over six grids does better (measured 2.3e-5 and 2.5e-4).
    rng = np.random.default_rng(9)
    h = np.array([0.4e-3, 0.5e-3, 0.667e-3, 1e-3, 1.3e-3, 2e-3])
    f = _exact(h) * (1 + 1e-5 * rng.standard_normal(h.size))
    fit = richardson(h, f)
    assert abs(fit.value - A) / A < 3e-4
    assert abs(fit.order - P) < 0.015


def test_oscillating_values_are_refused():
    # seed 002 section 6.2: a sequence that goes up and down has no Richardson limit
    with pytest.raises(ConvergenceError, match="oscillating"):
        richardson([1e-3, 2e-3, 3e-3], [10.0, 11.0, 10.5])


def test_diverging_values_are_refused():
    # differences that grow as h shrinks: observed order p < 0
    with pytest.raises(ConvergenceError, match="diverging"):
        richardson([1.0, 2.0, 4.0], [0.0, 3.0, 4.0])


def test_stagnating_values_are_refused():
    with pytest.raises(ConvergenceError, match="stagnating"):
        richardson([1.0, 2.0, 4.0], [5.0, 5.0, 6.0])


@pytest.mark.parametrize(
    "spacings, values, message",
    [
        ([1.0, 2.0], [1.0, 2.0], "at least three resolutions, got 2"),
        ([1.0, 2.0, 2.0], [1.0, 2.0, 3.0], "spacings must differ, got 2 twice"),
        ([1.0, -2.0, 3.0], [1.0, 2.0, 3.0], "spacings must be positive"),
        ([1.0, 2.0, 3.0], [1.0, np.nan, 3.0], "finite numbers"),
        ([1.0, 2.0, 3.0], [1.0, 2.0], "3 spacings but 2 values"),
    ],
)
def test_bad_input_is_named(spacings, values, message):
    with pytest.raises(InputError, match=message):
        richardson(spacings, values)
