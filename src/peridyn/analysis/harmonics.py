"""Harmonic content of a sensor signal (nonlinear ultrasonics).

The amplitude spectrum is |FFT| of the Hann-windowed record, zero-padded ``pad`` times.
A_n is its largest value within n f0 +- 0.2 f0; the second-harmonic ratio A2/A1 measures
the nonlinearity met by a tone burst of centre frequency f0 (e.g. a clapping crack).
The band has the same half-width (0.2 f0) around every harmonic: a band of +-20 % of
2 f0 would reach down to 1.6 f0, into the skirt of the fundamental itself (the main lobe of
a 5-cycle Hann burst spans f0 +- 0.4 f0), and would then measure the linear signal.
"""

from __future__ import annotations

import numpy as np

from peridyn.errors import InputError

#: Half-width of the band searched around each harmonic, as a fraction of f0.
BAND = 0.2


def amplitude_spectrum(signal: np.ndarray, dt: float, pad: int = 8) -> tuple[np.ndarray, np.ndarray]:
    """Frequencies (Hz) and amplitude spectrum (signal units x s) of a sampled ``signal``.

    Parameters
    ----------
    signal : (n_samples,) float
    dt : float, s
        Sampling interval.
    pad : int
        Zero padding factor.
    """
    signal = np.asarray(signal, dtype=float)
    if signal.ndim != 1 or len(signal) < 4:
        raise InputError(f"a spectrum needs a 1D signal of at least 4 samples, got shape {signal.shape}")
    if not dt > 0:
        raise InputError(f"sampling interval must be positive, got {dt!r} s")
    n = pad * len(signal)
    spectrum = np.abs(np.fft.rfft(signal * np.hanning(len(signal)), n)) * dt
    return np.fft.rfftfreq(n, dt), spectrum


def harmonic_amplitude(freq: np.ndarray, spectrum: np.ndarray, f0: float, order: int) -> float:
    """Largest spectrum value within ``order`` f0 +- BAND f0 (Hz)."""
    target = order * f0
    band = (freq > target - BAND * f0) & (freq < target + BAND * f0)
    if not band.any():
        raise InputError(
            f"harmonic {order} of {f0:g} Hz lies above the Nyquist frequency {freq[-1]:g} Hz of the signal"
        )
    return float(spectrum[band].max())


def second_harmonic_ratio(signal: np.ndarray, dt: float, f0: float) -> float:
    """A2 / A1 of a signal driven at ``f0`` (Hz)."""
    freq, spectrum = amplitude_spectrum(signal, dt)
    return harmonic_amplitude(freq, spectrum, f0, 2) / harmonic_amplitude(freq, spectrum, f0, 1)
