"""Richardson extrapolation of a quantity computed at several resolutions.

A quantity f(h) computed on grids of spacing h (or, in a delta-convergence study, at
horizons delta) is modelled, in the asymptotic range, by

    f(h) = f_inf + C h^p                                   (Freimanis 2019, eqs. 6.3 and 6.5)

with f_inf the value at zero spacing (the continuum value), p the observed order of
convergence and C a constant (eq. 6.4: C = |f_inf - f(h)| / h^p).

- Three resolutions h1 < h2 < h3 (any refinement ratios): p solves

      (f3 - f2) / (f2 - f1) = (h3^p - h2^p) / (h2^p - h1^p),

  which for a constant ratio r = h2/h1 = h3/h2 is p = ln((f3 - f2)/(f2 - f1)) / ln r
  (Roache 1998, chapter 5; the varying-ratio form as in Celik et al. 2008).
  Then C = (f2 - f1) / (h2^p - h1^p) and f_inf = f1 - C h1^p.
- More than three: least-squares fit of (f_inf, C, p) to all points, as the thesis
  fitted its four meshes (Freimanis 2019, section 6.1: "minimizing the difference between the
  left-hand side and the right-hand side in (6.3)"), started from the three finest.
- Grid convergence index of the finest grid (Roache 1994; Roache 1998, chapter 5):

      GCI = F_s |(f2 - f1) / f1| / (r^p - 1),   r = h2 / h1,   F_s = 1.25

  an error band on f1 (the thesis reports p and Delta_C instead; the GCI is given for
  comparison with the CFD literature).

Richardson extrapolation assumes monotone convergence: successive differences
f(h_k+1) - f(h_k) of one sign, shrinking as h decreases. Oscillating or diverging
sequences raise :class:`ConvergenceError` instead of returning a meaningless fit.

References: P. J. Roache, Perspective: a method for uniform reporting of grid refinement
studies, J. Fluids Eng. 116 (1994) 405-413; P. J. Roache, Verification and Validation in
Computational Science and Engineering, Hermosa, 1998; I. B. Celik et al., Procedure for
estimation and reporting of uncertainty due to discretization in CFD applications,
J. Fluids Eng. 130 (2008) 078001.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.optimize import brentq, least_squares

from peridyn.errors import InputError

#: Roache's factor of safety for a GCI from three or more grids.
SAFETY_FACTOR = 1.25
#: Spacings closer than this (relative) count as equal.
EQUAL_SPACING = 1e-9
#: Search interval for the observed order p.
ORDER_BOUNDS = (1e-6, 50.0)


class ConvergenceError(InputError):
    """The values do not converge monotonically: no Richardson extrapolation exists."""


@dataclass(frozen=True)
class Extrapolation:
    """Result of :func:`richardson`.

    Attributes
    ----------
    spacings : (n,) float64
        Resolutions, finest first (m, or whatever unit was given).
    values : (n,) float64
        The quantity at each resolution, same order.
    value : float
        Extrapolated value f_inf at zero spacing.
    order : float
        Observed order of convergence p.
    coefficient : float
        C in f = f_inf + C h^p.
    gci : float
        Grid convergence index of the finest value (relative, 0.01 = 1 %).
    rms_residual : float
        Root-mean-square misfit of the fit (0 for three points), same unit as values.
    """

    spacings: np.ndarray
    values: np.ndarray
    value: float
    order: float
    coefficient: float
    gci: float
    rms_residual: float

    def predict(self, h) -> np.ndarray:
        """f_inf + C h^p at spacings ``h``."""
        return self.value + self.coefficient * np.asarray(h, dtype=float) ** self.order

    def to_dict(self) -> dict:
        return {
            "spacings": self.spacings.tolist(),
            "values": self.values.tolist(),
            "value": self.value,
            "order": self.order,
            "coefficient": self.coefficient,
            "gci": self.gci,
            "rms_residual": self.rms_residual,
        }


def richardson(spacings, values, safety_factor: float = SAFETY_FACTOR) -> Extrapolation:
    """Extrapolate ``values`` computed at ``spacings`` to zero spacing.

    Parameters
    ----------
    spacings : (n,) float, n >= 3
        Positive, distinct resolutions in any order (m, or horizons in m).
    values : (n,) float
        The quantity at each resolution.
    safety_factor : float
        F_s of the GCI (Roache: 1.25 for three or more grids).

    Raises
    ------
    InputError
        Fewer than three points, non-finite numbers, non-positive or equal spacings.
    ConvergenceError
        Oscillating (differences change sign), stagnating (a zero difference) or
        diverging (differences do not shrink with the spacing) values.
    """
    h, f = _checked(spacings, values)
    _check_monotone(h, f)
    p = _three_point_order(h[:3], f[:3])
    c = (f[1] - f[0]) / (h[1] ** p - h[0] ** p)
    f_inf = f[0] - c * h[0] ** p
    if len(h) > 3:
        f_inf, c, p = _least_squares(h, f, (f_inf, c, p))
    rms = float(np.sqrt(np.mean((f_inf + c * h**p - f) ** 2)))
    gci = safety_factor * abs((f[1] - f[0]) / f[0]) / ((h[1] / h[0]) ** p - 1.0)
    return Extrapolation(h, f, float(f_inf), float(p), float(c), float(gci), rms)


def _checked(spacings, values) -> tuple[np.ndarray, np.ndarray]:
    h = np.asarray(spacings, dtype=float).ravel()
    f = np.asarray(values, dtype=float).ravel()
    if h.shape != f.shape:
        raise InputError(f"richardson: {h.size} spacings but {f.size} values")
    if h.size < 3:
        raise InputError(f"richardson: needs at least three resolutions, got {h.size}")
    if not (np.all(np.isfinite(h)) and np.all(np.isfinite(f))):
        raise InputError(
            f"richardson: spacings and values must be finite numbers, got {h.tolist()} and {f.tolist()}"
        )
    if np.any(h <= 0):
        raise InputError(f"richardson: spacings must be positive, got {h.tolist()}")
    order = np.argsort(h)
    h, f = h[order], f[order]
    close = np.diff(h) <= EQUAL_SPACING * h[1:]
    if np.any(close):
        k = int(np.argmax(close))
        raise InputError(f"richardson: spacings must differ, got {h[k]:g} twice (each resolution once)")
    return h, f


def _check_monotone(h: np.ndarray, f: np.ndarray) -> None:
    """Differences of one sign, none zero (h sorted finest first)."""
    d = np.diff(f)
    listing = ", ".join(f"{v:.6g} at {s:g}" for s, v in zip(h, f, strict=True))
    if np.any(d == 0):
        raise ConvergenceError(
            f"stagnating: two resolutions give the same value ({listing}); the "
            "order of convergence is undefined"
        )
    if not (np.all(d > 0) or np.all(d < 0)):
        raise ConvergenceError(
            f"oscillating convergence: the values go up and down as the spacing "
            f"shrinks ({listing}); Richardson extrapolation needs a monotone "
            "sequence (refine further, into the asymptotic range)"
        )


def _three_point_order(h: np.ndarray, f: np.ndarray) -> float:
    """p with (f3 - f2)/(f2 - f1) = (h3^p - h2^p)/(h2^p - h1^p), h1 < h2 < h3."""
    target = (f[2] - f[1]) / (f[1] - f[0])  # > 0 for a monotone sequence
    x = h / h[0]  # scaled: x1 = 1, powers stay finite

    def mismatch(p):
        return np.log((x[2] ** p - x[1] ** p) / (x[1] ** p - 1.0)) - np.log(target)

    lo, hi = ORDER_BOUNDS
    if mismatch(lo) >= 0:
        listing = ", ".join(f"{v:.6g} at {s:g}" for s, v in zip(h, f, strict=True))
        raise ConvergenceError(
            f"diverging: the differences do not shrink with the spacing ({listing}); observed order p <= 0"
        )
    if mismatch(hi) <= 0:
        raise ConvergenceError(
            f"the observed order exceeds {hi:g}: the finer values barely change (converged to round-off?)"
        )
    return float(brentq(mismatch, lo, hi, xtol=1e-15, rtol=4 * np.finfo(float).eps))


def _least_squares(h: np.ndarray, f: np.ndarray, start) -> tuple[float, float, float]:
    """Fit f = f_inf + C h^p to every point (scaled to O(1) unknowns)."""
    h0, scale = h[0], np.ptp(f)
    f_inf0, c0, p0 = start
    x = h / h0

    def residuals(q):
        a, b, p = q
        return a + b * x**p - (f - f_inf0) / scale

    fit = least_squares(
        residuals,
        [0.0, c0 * h0**p0 / scale, p0],
        bounds=([-np.inf, -np.inf, ORDER_BOUNDS[0]], [np.inf, np.inf, ORDER_BOUNDS[1]]),
        xtol=1e-15,
        ftol=1e-15,
        gtol=1e-15,
    )
    a, b, p = fit.x
    return f_inf0 + a * scale, b * scale / h0**p, float(p)
