"""Calibration formulas of thesis seed 002 eqs. 7.7-7.14 (V5)."""

import numpy as np
import pytest

from peridyn.errors import InputError
from peridyn.fatigue.calibration import (
    calibrate_A_II,
    fit_phase_one,
    geometry_factor,
    growth_rates,
    paris_fit,
    stress_intensity,
)


def test_phase_one_fit_recovers_the_parameters_of_exact_strain_life_data():
    """Eqs. 7.7-7.8 invert N = 1 / (A_I (eps - eps_inf)^m_I) exactly (V5: 426, 2.77, 0.00186)."""
    eps = np.linspace(0.0025, 0.012, 8)
    n = 1.0 / (426.0 * (eps - 0.00186) ** 2.77)
    fit = fit_phase_one(n, eps, eps_inf=0.00186)
    assert fit.A_I == pytest.approx(426.0, rel=1e-9) and fit.m_I == pytest.approx(2.77, rel=1e-12)
    free = fit_phase_one(n, eps)  # eq. 7.9: the fatigue limit that straightens the log-log line
    assert free.eps_inf == pytest.approx(0.00186, abs=2e-6)
    assert free.m_I == pytest.approx(2.77, rel=0.01)


def test_sen_geometry_factor_and_stress_intensity():
    """Eq. 7.13 at a/b = 0 is 1.122 (edge crack in a half-plane); eq. 7.12 at a/b = 0.5:
    F = 1.122 - 0.1155 + 2.6375 - 2.71375 + 1.898875 = 2.829125."""
    assert geometry_factor(0.0) == pytest.approx(1.122)
    assert geometry_factor(0.5) == pytest.approx(2.829125)
    k = stress_intensity(50e6, 0.025, 0.05)
    assert k == pytest.approx(50e6 * np.sqrt(np.pi * 0.025) * 2.829125)


def test_growth_rates_use_the_cycles_between_jumps():
    """Eq. 7.14: (a_n - a_m) / (N_n - N_m) between successive jumps of the crack length."""
    cycles = [0, 10, 20, 30, 40, 60]
    a = [1.0, 1.0, 2.0, 2.0, 2.0, 4.0]
    mid, rate = growth_rates(cycles, a)
    assert mid.tolist() == [3.0] and rate.tolist() == [pytest.approx(2.0 / 40)]


def test_paris_fit_and_A_II_ratio():
    """Eq. 7.10 fitted in log-log gives M back; eq. 7.11 scales A_II' by the rate ratio."""
    dk = np.array([10e6, 15e6, 20e6, 30e6])
    assert paris_fit(dk, 3e-30 * dk**4)[0] == pytest.approx(4.0)
    a2 = calibrate_A_II(1e6, dk, 2e-30 * dk**4, dk[1:3], 1e-30 * dk[1:3] ** 4)
    assert a2 == pytest.approx(0.5e6)
    with pytest.raises(InputError, match="no experimental dK lies in the simulated range"):
        calibrate_A_II(1e6, dk, dk, np.array([1e9]), np.array([1.0]))
