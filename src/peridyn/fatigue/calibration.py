"""Calibration of the remaining-life parameters (Freimanis 2019, eqs. 7.7-7.14).

Phase I: the strain-life data eps(N) are fitted with (eps - eps_inf) = a N^b (eq. 7.9 gives
eps_inf: the value that makes log(eps - eps_inf) against log N straightest), then m_I = -1 / b
(eq. 7.7) and A_I = 1 / a^m_I (eq. 7.8), so that N = 1 / (A_I (eps - eps_inf)^m_I).

Phase II: m_II is the Paris exponent M of da/dN = c dK^M (eq. 7.10). A trial run with A_II' gives
the crack growth rates (da/dN)' at the crack lengths' jumps (eq. 7.14); with dK from
K = sigma sqrt(pi a) F(a/b) (eqs. 7.12-7.13, dK = (1 - R) K_max) the experimental rate at each
simulated dK gives A_II = A_II' (da/dN) / (da/dN)' (eq. 7.11), averaged as in the thesis.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from peridyn.errors import InputError


@dataclass(frozen=True)
class PhaseOneFit:
    """Phase I parameters and the fit's coefficient of determination (log-log)."""

    A_I: float
    m_I: float
    eps_inf: float
    r_squared: float


def _line_fit(x: np.ndarray, y: np.ndarray) -> tuple[float, float, float]:
    """Least-squares y = slope x + intercept; returns slope, intercept, R^2."""
    slope, intercept = np.polyfit(x, y, 1)
    resid = y - (slope * x + intercept)
    total = np.sum((y - y.mean()) ** 2)
    return float(slope), float(intercept), float(1.0 - np.sum(resid**2) / total) if total > 0 else 1.0


def fit_phase_one(cycles, strain, eps_inf: float | None = None) -> PhaseOneFit:
    """Fit A_I, m_I (and eps_inf unless given) to strain-life data (eqs. 7.7-7.9).

    Parameters
    ----------
    cycles : (n,) cycles to failure
    strain : (n,) cyclic strain of each test (the model's eps)
    eps_inf : fatigue limit, or None to fit it (eq. 7.9, a scan below the smallest strain)
    """
    n = np.asarray(cycles, dtype=float)
    eps = np.asarray(strain, dtype=float)
    if n.shape != eps.shape or n.size < 3:
        raise InputError("strain-life data need at least 3 (cycles, strain) pairs of equal length")
    if np.any(n <= 0) or np.any(eps <= 0):
        raise InputError("strain-life data need positive cycles and strains")
    if eps_inf is None:
        candidates = np.linspace(0.0, eps.min(), 2001)[:-1]
        scores = [_line_fit(np.log(n), np.log(eps - e))[2] for e in candidates]
        eps_inf = float(candidates[int(np.argmax(scores))])
    if np.any(eps <= eps_inf):
        raise InputError(f"every strain must exceed the fatigue limit eps_inf = {eps_inf:g}")
    b, log_a, r2 = _line_fit(np.log(n), np.log(eps - eps_inf))
    if b >= 0:
        raise InputError("strain-life data must have strain falling with life (fitted slope >= 0)")
    m_I = -1.0 / b
    return PhaseOneFit(A_I=float(np.exp(-log_a) ** m_I), m_I=m_I, eps_inf=eps_inf, r_squared=r2)


def geometry_factor(a_over_b):
    """F(a/b) of a single-edge-notch specimen in tension (eq. 7.13)."""
    r = np.asarray(a_over_b, dtype=float)
    return 1.122 - 0.231 * r + 10.550 * r**2 - 21.710 * r**3 + 30.382 * r**4


def stress_intensity(stress: float, crack_length, width: float):
    """K_I = sigma sqrt(pi a) F(a/b), Pa sqrt(m) (eq. 7.12)."""
    a = np.asarray(crack_length, dtype=float)
    return stress * np.sqrt(np.pi * a) * geometry_factor(a / width)


def growth_rates(cycles, crack_length) -> tuple[np.ndarray, np.ndarray]:
    """Crack growth rates between successive jumps of the crack length (eq. 7.14).

    Returns (a_mid, da/dN): the mean crack length (m) and the rate (m/cycle) of each jump,
    (a_n - a_m) / (N_n - N_m) with m the previous jump.
    """
    n = np.asarray(cycles, dtype=float)
    a = np.asarray(crack_length, dtype=float)
    jumps = np.flatnonzero(np.diff(a) > 0) + 1
    if jumps.size < 2:
        return np.empty(0), np.empty(0)
    a_j, n_j = a[jumps], n[jumps]
    return 0.5 * (a_j[1:] + a_j[:-1]), np.diff(a_j) / np.diff(n_j)


def paris_fit(delta_k, rate) -> tuple[float, float]:
    """Paris law da/dN = c dK^M fitted in log-log; returns (M, c).

    Raises
    ------
    InputError
        Fewer than two rates, a dK or rate not positive and finite, or every dK the same (a
        line through points at one abscissa has no slope: a fit gave an exponent of -0.571).
    """
    dk = np.asarray(delta_k, dtype=float)
    r = np.asarray(rate, dtype=float)
    if dk.size < 2:
        raise InputError("a Paris fit needs at least two crack growth rates")
    if dk.shape != r.shape:
        raise InputError(f"a Paris fit needs one rate per dK, got {dk.size} dK and {r.size} rates")
    bad = ~(np.isfinite(dk) & np.isfinite(r) & (dk > 0) & (r > 0))
    if bad.any():
        i = int(np.flatnonzero(bad)[0])
        raise InputError(
            f"a Paris fit needs positive, finite dK and rates: point {i} has dK = {dk[i]:.4g}, "
            f"rate {r[i]:.4g}"
        )
    if np.ptp(np.log(dk)) <= 1e-12 * max(1.0, float(np.abs(np.log(dk)).max())):
        raise InputError(
            f"a Paris fit needs crack growth rates at two or more different dK: all {dk.size} are "
            f"at dK = {dk[0]:.6g} Pa m^0.5"
        )
    slope, intercept, _ = _line_fit(np.log(dk), np.log(r))
    return slope, float(np.exp(intercept))


def calibrate_A_II(A_trial: float, delta_k_sim, rate_sim, delta_k_exp, rate_exp) -> float:
    """A_II = A_II' (da/dN) / (da/dN)' (eq. 7.11), averaged over the experimental dK inside the
    simulated range (simulated rates interpolated in log-log)."""
    dk_s, r_s = np.asarray(delta_k_sim, float), np.asarray(rate_sim, float)
    dk_e, r_e = np.asarray(delta_k_exp, float), np.asarray(rate_exp, float)
    order = np.argsort(dk_s)
    dk_s, r_s = dk_s[order], r_s[order]
    inside = (dk_e >= dk_s[0]) & (dk_e <= dk_s[-1])
    if not inside.any():
        raise InputError(
            f"no experimental dK lies in the simulated range {dk_s[0]:.3g}-"
            f"{dk_s[-1]:.3g} Pa m^0.5: run the trial longer or give more data"
        )
    r_at = np.exp(np.interp(np.log(dk_e[inside]), np.log(dk_s), np.log(r_s)))
    return float(A_trial * np.mean(r_e[inside] / r_at))
