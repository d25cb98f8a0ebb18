"""Time windows around the first arrivals of a tone burst on a path.

The direct S0 and A0 wave packets of a burst of duration ``T`` sent at ``t = 0`` reach a sensor
``d`` away between ``d / c_g,max`` and ``d / c_g,min + T`` (group velocities ``c_g`` of the
fundamental Lamb modes at the burst's centre frequency, ``peridyn.analysis.lamb``). A window over
that span, widened by ``padding`` burst durations at its end, holds the direct arrivals and the
scattering of damage near the path, before the reflections from the plate's edges arrive.
"""

from __future__ import annotations

import numpy as np

from peridyn.analysis.lamb import lamb_modes
from peridyn.errors import InputError

__all__ = ["arrival_windows", "fundamental_group_velocities", "window_masks"]


def fundamental_group_velocities(E: float, nu: float, rho: float, thickness: float, frequency: float) -> dict:
    """``{"S0": c_g, "A0": c_g}`` (m/s) of an isotropic plate (Pa, -, kg/m^3, m) at ``frequency`` (Hz).

    Examples
    --------
    >>> v = fundamental_group_velocities(68.9e9, 0.33, 2700.0, 0.002, 150e3)
    >>> v["S0"] > v["A0"]
    True
    """
    modes = lamb_modes(E, nu, rho, thickness, frequency, max_order=0)
    return {m.mode: m.group_velocity_m_s for m in modes}


def arrival_windows(distances, velocities, burst_duration: float, padding: float = 0.5) -> np.ndarray:
    """Start and end (s) of each path's first-arrival window.

    Parameters
    ----------
    distances : (n_paths,) array_like, m
        Actuator-sensor distances.
    velocities : sequence of float, m/s
        Group velocities of the modes to hold (e.g. the values of
        :func:`fundamental_group_velocities`).
    burst_duration : float, s
        Length of the excitation (cycles / frequency).
    padding : float >= 0
        Extra length after the slowest packet, in burst durations.

    Returns
    -------
    (n_paths, 2) float64, s
    """
    d = np.asarray(distances, dtype=float)
    v = np.asarray(list(velocities), dtype=float)
    if d.ndim != 1 or np.any(d <= 0):
        raise InputError(f"path distances must be a 1-D array of positive lengths, got {d}")
    if v.size == 0 or np.any(v <= 0):
        raise InputError(f"group velocities must be positive, got {v}")
    if not burst_duration > 0 or not padding >= 0:
        raise InputError(f"burst duration must be > 0 and padding >= 0, got {burst_duration}, {padding}")
    return np.column_stack([d / v.max(), d / v.min() + (1.0 + padding) * burst_duration])


def window_masks(times, windows) -> np.ndarray:
    """(n_paths, n_t) bool: the samples of ``times`` (s, (n_t,)) inside each window ((n_paths, 2), s)."""
    t = np.asarray(times, dtype=float)
    w = np.asarray(windows, dtype=float)
    return (t[None, :] >= w[:, :1]) & (t[None, :] <= w[:, 1:])
