"""Damage indices of one path's signal against its baseline, and seeded sensor noise.

A path is an actuator-sensor pair; its signal ``s(t)`` is compared with the baseline ``b(t)``
recorded on the structure before damage, over a time window (``peridyn.analysis.shm.windows``):

- residual energy index ``sum (s - b)^2 / sum b^2`` (the energy of the scattered field relative
  to the baseline's; Torkamani et al. 2014, "A novel damage index for damage identification
  using guided waves", the signal difference coefficient family);
- correlation index ``1 - rho`` with ``rho`` Pearson's correlation coefficient of ``s`` and ``b``
  (Zhao et al. 2007, "Active health monitoring of an aircraft wing with embedded piezoelectric
  sensor/actuator network", the index that RAPID images).

Both are 0 for an unchanged signal and grow with the change.
"""

from __future__ import annotations

import numpy as np

from peridyn.errors import InputError

__all__ = ["correlation_index", "direct_peaks", "residual_energy_index", "with_noise"]


def _pair(baseline, current, mask) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The windowed baseline and current signals (zero outside the window) and the window."""
    b = np.asarray(baseline, dtype=float)
    s = np.asarray(current, dtype=float)
    if b.shape != s.shape or b.ndim < 1:
        raise InputError(f"baseline and current signals must have one shape, got {b.shape} and {s.shape}")
    if mask is not None:
        mask = np.asarray(mask, dtype=bool)
        if mask.shape != b.shape:
            raise InputError(f"window mask must have the signals' shape {b.shape}, got {mask.shape}")
        if not mask.any(axis=-1).all():
            raise InputError("a window holds no sample of its signal")
    else:
        mask = np.ones(b.shape, dtype=bool)
    return np.where(mask, b, 0.0), np.where(mask, s, 0.0), mask


def residual_energy_index(baseline, current, mask=None) -> np.ndarray:
    """``sum (s - b)^2 / sum b^2`` over the last axis (the samples in ``mask``).

    Parameters
    ----------
    baseline, current : (..., n_t) array_like
        Signals of the same paths, any unit.
    mask : (..., n_t) bool array_like or None
        The samples of each path's window (None: all).

    Returns
    -------
    (...) float64 array, dimensionless
    """
    b, s, _ = _pair(baseline, current, mask)
    energy = np.sum(b * b, axis=-1)
    if np.any(energy <= 0):
        raise InputError("a baseline signal is zero over its window: no residual energy index")
    return np.sum((s - b) ** 2, axis=-1) / energy


def correlation_index(baseline, current, mask=None) -> np.ndarray:
    """``1 - rho`` (Pearson's correlation coefficient of the windowed signals), in [0, 2].

    Parameters and returns as :func:`residual_energy_index`.
    """
    b, s, mask = _pair(baseline, current, mask)
    n = mask.sum(axis=-1)
    mb = np.sum(b, axis=-1) / n
    ms = np.sum(s, axis=-1) / n
    db = np.where(mask, b - mb[..., None], 0.0)
    ds = np.where(mask, s - ms[..., None], 0.0)
    norm = np.sqrt(np.sum(db * db, axis=-1) * np.sum(ds * ds, axis=-1))
    if np.any(norm <= 0):
        raise InputError("a signal is constant over its window: no correlation index")
    return 1.0 - np.sum(db * ds, axis=-1) / norm


def direct_peaks(signals, mask) -> np.ndarray:
    """Peak ``|s|`` of each path's signal within its first-arrival window.

    Parameters
    ----------
    signals : (..., n_t) array_like
    mask : (..., n_t) bool array_like

    Returns
    -------
    (...) float64, the signals' unit
    """
    s = np.asarray(signals, dtype=float)
    mask = np.broadcast_to(np.asarray(mask, dtype=bool), s.shape)
    return np.max(np.where(mask, np.abs(s), 0.0), axis=-1)


def with_noise(signals, level: float, peaks, seed: int) -> np.ndarray:
    """``signals`` plus Gaussian white noise whose standard deviation is ``level`` times each
    path's ``peaks`` (e.g. 0.01 of the direct arrival's peak), drawn from ``seed``.

    Parameters
    ----------
    signals : (..., n_t) array_like
    level : float >= 0
        Noise standard deviation as a fraction of the peak.
    peaks : (...) array_like
        Each path's reference peak (:func:`direct_peaks` of its baseline).
    seed : int
        Seed of ``numpy.random.default_rng``: the same seed gives the same noise.

    Returns
    -------
    (..., n_t) float64
    """
    if not level >= 0:
        raise InputError(f"noise level must be >= 0, got {level!r}")
    s = np.asarray(signals, dtype=float)
    peaks = np.asarray(peaks, dtype=float)
    rng = np.random.default_rng(seed)
    return s + rng.standard_normal(s.shape) * (level * peaks)[..., None]
