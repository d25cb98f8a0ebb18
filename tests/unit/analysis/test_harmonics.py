"""Harmonic ratio of a sensor signal (peridyn.analysis.harmonics) on synthetic signals whose
spectra are known in closed form."""

import numpy as np
import pytest

from peridyn.analysis.harmonics import second_harmonic_ratio
from peridyn.errors import InputError

F0 = 200e3
DT = 1e-8
#: Sidelobe level of a 5-cycle Hann burst's spectrum 0.8 f0 from its carrier (measured 2.4e-3).
LEAKAGE = 4e-3


def burst(t, f, cycles=5):
    """Hann-windowed tone burst of ``cycles`` cycles of f0 (Hz) carrying frequency f, centred
    in the 60 us record (as a transmitted burst at a sensor is)."""
    tau = cycles / F0
    s = t - 0.5 * (t[-1] - tau)
    env = np.where((s > 0) & (s < tau), 0.5 * (1 - np.cos(2 * np.pi * s / tau)), 0.0)
    return env * np.sin(2 * np.pi * f * s)


def test_ratio_of_a_known_second_harmonic():
    """Same envelope at f0 and 2 f0 with amplitude a: the peaks are in the ratio a, up to the
    fundamental's own leakage into the 2 f0 band (LEAKAGE, see the next test)."""
    t = DT * np.arange(6000)
    for a in (0.3, 0.03):
        signal = burst(t, F0) + a * burst(t, 2 * F0)
        assert second_harmonic_ratio(signal, DT, F0) == pytest.approx(a, abs=LEAKAGE)


def test_linear_burst_has_no_second_harmonic():
    """A linear 5-cycle Hann burst has no second harmonic: only the Hann sidelobes (decaying as
    1/f^3) reach 2 f0 - 0.2 f0, 0.8 f0 from the carrier, at the few-1e-3 level."""
    t = DT * np.arange(6000)
    assert second_harmonic_ratio(burst(t, F0), DT, F0) < LEAKAGE


def test_bad_signal_input():
    with pytest.raises(InputError, match="at least 4 samples"):
        second_harmonic_ratio(np.zeros(2), DT, F0)
    with pytest.raises(InputError, match="sampling interval must be positive"):
        second_harmonic_ratio(np.ones(100), 0.0, F0)
    with pytest.raises(InputError, match="above the Nyquist"):
        second_harmonic_ratio(np.ones(100), 2e-6, F0)
