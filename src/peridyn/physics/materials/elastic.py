"""Isotropic elastic constants and the peridynamic integrals of influence functions."""

from __future__ import annotations

import numpy as np

from peridyn.discretization.bonds import influence_function
from peridyn.errors import InputError


def check_elastic(E, nu, rho) -> None:
    """Raise InputError unless 0 < E, -1 < nu < 1/2 and 0 < rho (SI units); each a number or,
    for a body of several blocks, an (n_points,) array checked point by point; ``nu`` None
    (not given) is not checked."""
    for name, value in (("E", E), ("rho", rho)):
        bad = ~(np.isfinite(value) & (np.asarray(value) > 0))
        if np.any(bad):
            raise InputError(f"material {name} must be positive and finite, got {_first(value, bad)!r}")
    if nu is None:
        return
    bad = ~(np.isfinite(nu) & (np.asarray(nu) > -1.0) & (np.asarray(nu) < 0.5))
    if np.any(bad):
        raise InputError(f"material nu must lie in (-1, 0.5), got {_first(nu, bad)!r}")


def _first(value, bad):
    """``value`` if a number, else its first entry where ``bad``."""
    return value if np.ndim(value) == 0 else float(np.asarray(value)[np.flatnonzero(bad)[0]])


def bulk_modulus(E: float, nu: float) -> float:
    """3D bulk modulus K = E / (3 (1 - 2 nu)), Pa."""
    return E / (3.0 * (1.0 - 2.0 * nu))


def shear_modulus(E: float, nu: float) -> float:
    """Shear modulus mu = E / (2 (1 + nu)), Pa."""
    return E / (2.0 * (1.0 + nu))


def plane_bulk_modulus(E: float, nu: float, plane: str) -> float:
    """2D (in-plane) bulk modulus, Pa: E / (2 (1 - nu)) in plane stress, lambda + mu in plane strain."""
    if plane == "stress":
        return E / (2.0 * (1.0 - nu))
    if plane == "strain":
        return E / (2.0 * (1.0 + nu) * (1.0 - 2.0 * nu))
    raise InputError(f"plane must be 'stress' or 'strain', got {plane!r}")


def dilatational_modulus(E, nu, dim: int, plane: str | None = None):
    """kappa of a dim-dimensional LPS, Pa: the bulk modulus K (3D), the in-plane one (2D, plane
    ``"stress"`` or ``"strain"``), E (1D: a bar of unit cross-section)."""
    if dim == 3:
        return bulk_modulus(E, nu)
    if dim == 2:
        return plane_bulk_modulus(E, nu, plane)
    return E


def radial_moment(influence: str, horizon: float, power: int) -> float:
    """Integral of omega(r) r^power over [0, horizon] (m^(power+1))."""
    omega = influence_function(influence)
    from scipy.integrate import quad  # here: scipy.integrate loads scipy.optimize, 15 MB

    value, _ = quad(lambda r: float(omega(np.array(r), horizon)) * r**power, 0.0, horizon, limit=200)
    return value


def radial_moments(influence: str, horizon, power: int):
    """``radial_moment`` of a horizon (m): a float for a float, else (n,) for (n,) horizons (one
    quadrature per distinct value: a body whose blocks have different horizons)."""
    if np.ndim(horizon) == 0:
        return radial_moment(influence, horizon, power)
    values, index = np.unique(horizon, return_inverse=True)
    return np.array([radial_moment(influence, float(v), power) for v in values])[index]


def mean_fourth_power(dim: int) -> float:
    """Integral of n_x^4 over the unit sphere (3D: 4 pi / 5) or circle (2D: 3 pi / 4)."""
    return 4.0 * np.pi / 5.0 if dim == 3 else 3.0 * np.pi / 4.0
