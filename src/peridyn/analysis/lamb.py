"""Rayleigh-Lamb theory of guided waves in a free isotropic elastic plate.

The plate fills ``-h <= z <= h`` (``h`` the half thickness, m) and waves travel
along ``x`` as ``exp(i (k x - omega t))``. With ``p**2 = omega**2/cL**2 - k**2``
and ``q**2 = omega**2/cT**2 - k**2`` (negative for evanescent partial waves) the
Rayleigh-Lamb equations in determinant form (Rose, *Ultrasonic Guided Waves in
Solid Media*, 2014, ch. 6; Graff, *Wave Motion in Elastic Solids*, 1975, 8.1)
are::

    S:  (q^2 - k^2)^2 cos(ph) sin(qh) + 4 k^2 p q sin(ph) cos(qh) = 0
    A:  (q^2 - k^2)^2 sin(ph) cos(qh) + 4 k^2 p q cos(ph) sin(qh) = 0

Dividing S by ``q`` and A by ``p`` removes the trivial roots ``q = 0`` and
``p = 0`` and leaves, with ``C(x) = cos(sqrt(x) h)`` and
``S(x) = sin(sqrt(x) h) / sqrt(x)`` (``cosh`` and ``sinh`` for ``x < 0``)::

    S:  (q^2 - k^2)^2 C(p^2) S(q^2) + 4 k^2 p^2 S(p^2) C(q^2) = 0
    A:  (q^2 - k^2)^2 S(p^2) C(q^2) + 4 k^2 q^2 C(p^2) S(q^2) = 0

Both are real, entire functions of ``k`` and ``omega`` for real and imaginary
``p, q`` alike: no poles (unlike the ``tan`` forms), so every sign change of a
scan in ``k`` brackets a root, refined by a bracketing secant (Illinois) method
that refines every bracket of every frequency at once. The
group velocity ``d omega / d k = -F_k / F_omega`` comes from implicit
differentiation of these functions, the partial derivatives taken by complex
steps (exact to round-off).

Modes are labelled as branches ``omega_n(k)`` of one symmetry: branch ``n``
(``S n`` or ``A n``) is the ``n``-th lowest frequency at a fixed wavenumber and
starts at the ``n``-th cut-off (:func:`cutoff_frequencies`). Below a
zero-group-velocity (ZGV) point a branch has two roots at one frequency: a
forward wave and a backward wave (negative group velocity), both reported
under the branch's label.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass
from typing import NamedTuple

import numpy as np

from peridyn.discretization import geometry
from peridyn.errors import InputError

__all__ = [
    "DispersionBranch",
    "LambMode",
    "bulk_speeds",
    "cutoff_frequencies",
    "dispersion_curves",
    "lamb_modes",
    "mode_shape",
    "rayleigh_speed",
]

#: Terms of the Taylor series below, enough for round-off at |t| <= 1.
_N_TERMS = 14
#: Coefficients, ascending powers of t = x z^2, of cos(sqrt(t)) and sin(sqrt(t))/sqrt(t).
_COS_TERMS = np.array([(-1) ** n / math.factorial(2 * n) for n in range(_N_TERMS)])
_SIN_TERMS = np.array([(-1) ** n / math.factorial(2 * n + 1) for n in range(_N_TERMS)])
#: Coefficients of X^n Y^m in integral_0^1 S(X; t) S(Y; t) dt (see _cross_term).
_CROSS_TERMS = np.outer(_SIN_TERMS, _SIN_TERMS) / (
    2.0 * np.add.outer(np.arange(_N_TERMS), np.arange(_N_TERMS)) + 3.0
)
#: Relative imaginary step of the complex-step derivatives in _group_velocities.
_COMPLEX_STEP = 1e-30
#: Relative width to which a root's bracket is refined (``_refine``).
ROOT_RTOL = 1e-13
#: Refinement steps after which a root that has not converged is an error (``_refine``).
_MAX_REFINE_STEPS = 200
#: Scan points per radian of the shear phase ``omega h / cT`` (and at least 400).
_SCAN_DENSITY = 32
#: Points of the scan over phase velocities below the shear speed.
_SLOW_SCAN_POINTS = 400
#: Peak bytes held per point of the wavenumber scan of the highest frequency (the scan, the
#: temporaries of the Rayleigh-Lamb function, the brackets and roots): 345-460 B measured
#: with ``tracemalloc`` for 10-100 MHz in a 2 mm steel plate (1 000-6 800 scan points).
SCAN_BYTES = 500.0


@dataclass(frozen=True)
class LambMode:
    """One propagating Lamb wave at one frequency.

    Attributes
    ----------
    mode : str
        Branch label, ``"S0"``, ``"S1"``, ..., ``"A0"``, ``"A1"``, ...
    frequency_hz : float
        Frequency, Hz.
    phase_velocity_m_s : float
        Phase velocity ``omega / k``, m/s.
    group_velocity_m_s : float
        Group velocity ``d omega / d k``, m/s (negative for a backward wave).
    wavenumber_rad_m : float
        Wavenumber ``k``, rad/m.
    """

    mode: str
    frequency_hz: float
    phase_velocity_m_s: float
    group_velocity_m_s: float
    wavenumber_rad_m: float

    def to_dict(self) -> dict:
        """The mode as a plain dict with the attribute names as keys."""
        return asdict(self)


@dataclass(frozen=True, eq=False)
class DispersionBranch:
    """Sampled dispersion curve of one mode, ordered by wavenumber along the branch.

    Attributes
    ----------
    mode : str
        Branch label, e.g. ``"S0"``.
    frequency_hz, wavenumber_rad_m, phase_velocity_m_s, group_velocity_m_s : (m,) float64
        Frequency (Hz), wavenumber (rad/m), phase and group velocity (m/s).
    """

    mode: str
    frequency_hz: np.ndarray
    wavenumber_rad_m: np.ndarray
    phase_velocity_m_s: np.ndarray
    group_velocity_m_s: np.ndarray


class _Plate(NamedTuple):
    """Validated plate: bulk, Rayleigh and plate speeds (m/s), half thickness h (m)."""

    cl: float
    ct: float
    cr: float
    cp: float
    h: float


def bulk_speeds(E: float, nu: float, rho: float) -> tuple[float, float]:
    """Longitudinal and shear bulk wave speeds of an isotropic solid.

    ``cL = sqrt(E (1 - nu) / (rho (1 + nu) (1 - 2 nu)))``,
    ``cT = sqrt(E / (2 rho (1 + nu)))``.

    Parameters
    ----------
    E : float
        Young's modulus, Pa.
    nu : float
        Poisson's ratio, in (-1, 0.5).
    rho : float
        Density, kg/m^3.

    Returns
    -------
    (cL, cT) : tuple of float
        Longitudinal and shear speeds, m/s.

    Examples
    --------
    >>> [round(c, 1) for c in bulk_speeds(68.9e9, 0.33, 2700.0)]
    [6148.9, 3097.3]
    """
    _check_positive("E", E)
    _check_positive("rho", rho)
    if not -1.0 < nu < 0.5:
        raise InputError(f"nu = {nu!r}: Poisson's ratio must lie in (-1, 0.5)")
    cl = math.sqrt(E * (1.0 - nu) / (rho * (1.0 + nu) * (1.0 - 2.0 * nu)))
    ct = math.sqrt(E / (2.0 * rho * (1.0 + nu)))
    return cl, ct


def rayleigh_speed(E: float, nu: float, rho: float) -> float:
    """Speed of Rayleigh surface waves, the root of the Rayleigh equation.

    ``(2 - xi^2)^2 = 4 sqrt(1 - xi^2 cT^2 / cL^2) sqrt(1 - xi^2)`` with
    ``xi = cR / cT`` in (0, 1) (Graff 1975, eq. 6.3.8), solved by bisection.

    Parameters
    ----------
    E : float
        Young's modulus, Pa.
    nu : float
        Poisson's ratio, in (-1, 0.5).
    rho : float
        Density, kg/m^3.

    Returns
    -------
    float
        Rayleigh speed, m/s.
    """
    # imported here: scipy.optimize costs a process 15 MB (an explicit run solves for no root)
    from scipy.optimize import brentq

    cl, ct = bulk_speeds(E, nu, rho)
    kappa2 = (ct / cl) ** 2

    def residual(xi):
        return (2.0 - xi**2) ** 2 - 4.0 * math.sqrt((1.0 - kappa2 * xi**2) * (1.0 - xi**2))

    return ct * brentq(residual, 0.5, 1.0, xtol=1e-15, rtol=1e-15)


def cutoff_frequencies(E: float, nu: float, rho: float, thickness: float, f_max: float) -> dict[str, float]:
    """Cut-off frequencies (``k = 0``) of the higher modes up to ``f_max``.

    At ``k = 0`` the symmetric equation reduces to ``cos(wh/cL) sin(wh/cT) = 0``
    and the antisymmetric one to ``sin(wh/cL) cos(wh/cT) = 0``. With
    ``d = 2h`` the thickness, the cut-offs are therefore

    - S: ``f = (2n - 1) cL / (2d)`` and ``f = n cT / d``,
    - A: ``f = n cL / d`` and ``f = (2n - 1) cT / (2d)``, ``n = 1, 2, ...``,

    and the ``j``-th of each symmetry, in ascending order, starts branch ``j``.

    Parameters
    ----------
    E, nu, rho : float
        Young's modulus (Pa), Poisson's ratio, density (kg/m^3).
    thickness : float
        Plate thickness ``2h``, m.
    f_max : float
        Highest frequency listed, Hz.

    Returns
    -------
    dict of str to float
        ``{"S1": f, "S2": f, ..., "A1": f, ...}``, Hz, ascending within each
        symmetry.
    """
    plate = _plate(E, nu, rho, thickness)
    _check_positive("f_max", f_max)
    d = thickness
    n = np.arange(1, math.ceil(f_max * d / plate.ct) + 2)
    families = {
        "S": np.concatenate([(2 * n - 1) * plate.cl / (2 * d), n * plate.ct / d]),
        "A": np.concatenate([n * plate.cl / d, (2 * n - 1) * plate.ct / (2 * d)]),
    }
    cutoffs = {}
    for family, freqs in families.items():
        kept = np.sort(freqs[freqs <= f_max])
        cutoffs.update({f"{family}{j}": float(f) for j, f in enumerate(kept, start=1)})
    return cutoffs


def lamb_modes(
    E: float,
    nu: float,
    rho: float,
    thickness: float,
    frequencies,
    max_order: int | None = None,
) -> list[LambMode]:
    """Every propagating Lamb mode at each frequency.

    Roots of the Rayleigh-Lamb equations (module docstring) are bracketed by a
    sign-change scan in wavenumber, fine in the shear phase for phase
    velocities above ``cT`` and uniform in phase velocity below it, then
    refined to 1e-13 relative by Brent's method. Pairs of roots closer than
    one scan step (near branch crossings and zero-group-velocity points) are
    found from the dips of ``|F|`` between scan points; a pair so close that
    it leaves no dip on the scan, or an exact double root, is missed.

    Parameters
    ----------
    E, nu, rho : float
        Young's modulus (Pa), Poisson's ratio, density (kg/m^3).
    thickness : float
        Plate thickness ``2h``, m.
    frequencies : float or (n_freq,) array_like
        Frequencies, Hz, all positive.
    max_order : int, optional
        Keep only branches ``S0..S{max_order}`` and ``A0..A{max_order}``.

    Returns
    -------
    list of LambMode
        By frequency (in the given order), then S before A, then branch order,
        then descending wavenumber.

    Examples
    --------
    >>> [m.mode for m in lamb_modes(68.9e9, 0.33, 2700.0, 0.002, 1e6)]
    ['S0', 'A0', 'A1']
    """
    plate = _plate(E, nu, rho, thickness)
    freqs = _check_frequencies(frequencies)
    check_scan_fits(plate, float(freqs.max()), thickness)
    if max_order is not None and (int(max_order) != max_order or max_order < 0):
        raise InputError(f"max_order = {max_order!r}: must be a non-negative integer")
    by_family = {family: _family_modes(plate, freqs, family) for family in "SA"}
    modes = []
    for k in range(len(freqs)):
        for family in "SA":
            modes.extend(m for m in by_family[family][k] if max_order is None or int(m.mode[1:]) <= max_order)
    return modes


def dispersion_curves(
    E: float,
    nu: float,
    rho: float,
    thickness: float,
    f_max: float,
    n: int = 200,
    max_order: int | None = None,
) -> dict[str, DispersionBranch]:
    """Dispersion curves of all modes on ``n`` frequencies up to ``f_max``.

    Parameters
    ----------
    E, nu, rho : float
        Young's modulus (Pa), Poisson's ratio, density (kg/m^3).
    thickness : float
        Plate thickness ``2h``, m.
    f_max : float
        Highest frequency, Hz; the grid is ``linspace(f_max/n, f_max, n)``.
    n : int, default 200
        Number of frequencies.
    max_order : int, optional
        Highest branch order kept in each symmetry.

    Returns
    -------
    dict of str to DispersionBranch
        Keyed by label, S modes then A modes in branch order.
    """
    _check_positive("f_max", f_max)
    if int(n) != n or n < 2:
        raise InputError(f"n = {n!r}: need an integer number of frequencies >= 2")
    freqs = np.linspace(f_max / n, f_max, int(n))
    groups: dict[str, list[LambMode]] = {}
    for m in lamb_modes(E, nu, rho, thickness, freqs, max_order):
        groups.setdefault(m.mode, []).append(m)
    order = sorted(groups, key=lambda label: (label[0] != "S", int(label[1:])))
    return {label: _branch(label, groups[label]) for label in order}


def mode_shape(
    E: float, nu: float, rho: float, thickness: float, mode: LambMode, n_points: int = 101
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Through-thickness displacement profiles of a Lamb mode.

    From the Lamé potentials ``phi = A cos(pz), psi = B sin(qz)`` (S) or
    ``phi = A sin(pz), psi = B cos(qz)`` (A), with ``A/B`` set by the free
    shear traction at ``z = h`` (Rose 2014, sec. 6.3), in a form that stays
    real for imaginary ``p, q``::

        S:  ux = k [(k^2-q^2) S_q(h) C_p(z) + 2 p^2 S_p(h) C_q(z)]
            uz = p^2 [2 k^2 S_p(h) S_q(z) - (k^2-q^2) S_q(h) S_p(z)]
        A:  ux = k [(k^2-q^2) C_q(h) S_p(z) + 2 q^2 C_p(h) S_q(z)]
            uz = (k^2-q^2) C_q(h) C_p(z) - 2 k^2 C_p(h) C_q(z)

    with ``C_p(z) = cos(pz)``, ``S_p(z) = sin(pz)/p``. ``ux`` leads ``uz`` by a
    quarter period; the profiles are the real amplitudes.

    Parameters
    ----------
    E, nu, rho : float
        Young's modulus (Pa), Poisson's ratio, density (kg/m^3).
    thickness : float
        Plate thickness ``2h``, m.
    mode : LambMode
        A mode from :func:`lamb_modes` for the same plate.
    n_points : int, default 101
        Points across the thickness.

    Returns
    -------
    z : (n_points,) float64
        Height above the mid-plane, m, from ``-h`` to ``h``.
    ux, uz : (n_points,) float64
        In-plane and out-of-plane amplitudes, scaled together so that the
        largest of ``|ux|, |uz|`` is 1 (and that value positive).
    """
    plate = _plate(E, nu, rho, thickness)
    h, k = plate.h, mode.wavenumber_rad_m
    omega = 2.0 * math.pi * mode.frequency_hz
    kk, p2, q2 = k * k, (omega / plate.cl) ** 2 - k * k, (omega / plate.ct) ** 2 - k * k
    z = np.linspace(-h, h, int(n_points))
    cpz, spz = _thickness_functions(p2, z, h)
    cqz, sqz = _thickness_functions(q2, z, h)
    cph, sph = _thickness_functions(p2, h, h)
    cqh, sqh = _thickness_functions(q2, h, h)
    if mode.mode.startswith("S"):
        ux = k * ((kk - q2) * sqh * cpz + 2.0 * p2 * sph * cqz)
        uz = p2 * (2.0 * kk * sph * sqz - (kk - q2) * sqh * spz)
    else:
        ux = k * ((kk - q2) * cqh * spz + 2.0 * q2 * cph * sqz)
        uz = (kk - q2) * cqh * cpz - 2.0 * kk * cph * cqz
    both = np.concatenate([ux, uz])
    peak = both[np.argmax(np.abs(both))]
    return z, ux / peak, uz / peak


# --- input checks -----------------------------------------------------------------


def _check_positive(name: str, value) -> None:
    """Raise InputError unless ``value`` is a finite number > 0."""
    if not (isinstance(value, int | float | np.number) and math.isfinite(value) and value > 0):
        raise InputError(f"{name} = {value!r}: must be a positive finite number")


def _plate(E: float, nu: float, rho: float, thickness: float) -> _Plate:
    """Validate the plate and precompute its speeds."""
    cl, ct = bulk_speeds(E, nu, rho)
    _check_positive("thickness", thickness)
    cp = math.sqrt(E / (rho * (1.0 - nu**2)))
    return _Plate(cl, ct, rayleigh_speed(E, nu, rho), cp, thickness / 2.0)


def _check_frequencies(frequencies) -> np.ndarray:
    """Frequencies as a 1-D float array, all finite and > 0, else InputError."""
    try:
        freqs = np.atleast_1d(np.asarray(frequencies, dtype=float))
    except (TypeError, ValueError) as exc:
        raise InputError(f"frequencies = {frequencies!r}: not numbers ({exc})") from None
    bad = freqs[~(np.isfinite(freqs) & (freqs > 0))]
    if freqs.ndim != 1 or freqs.size == 0 or bad.size:
        shown = float(bad[0]) if bad.size else frequencies
        raise InputError(f"frequencies = {shown!r}: need a 1-D list of frequencies > 0 Hz")
    return freqs


# --- Rayleigh-Lamb functions ------------------------------------------------------


def _thickness_functions(x, z, h: float):
    """``C = cos(sqrt(x) z)`` and ``S = sin(sqrt(x) z) / sqrt(x)`` for real ``x``.

    For ``x < 0`` these are ``cosh`` and ``sinh / sqrt(-x)``; for ``|x| h^2 < 1``
    they are summed as Taylor series in ``x z^2`` (to round-off). Both are
    scaled by ``exp(-sqrt(max(-x, 0)) h)`` so that they cannot overflow for
    ``|z| <= h``; the scale is positive and common to every term of the
    Rayleigh-Lamb functions, so it changes neither roots nor signs. ``x, z``
    broadcast; ``x`` may carry an infinitesimal imaginary part (complex step).
    """
    x, z = np.broadcast_arrays(np.asarray(x) + 0.0, np.asarray(z, dtype=float))
    c, s = np.empty(x.shape, x.dtype), np.empty(x.shape, x.dtype)
    small = np.abs(x) * h * h < 1.0
    pos, neg = ~small & (x.real > 0), ~small & (x.real < 0)
    xs, zs = x[small], z[small]
    scale = np.exp(-np.sqrt(np.maximum(-xs.real, 0.0)) * h)
    powers = _powers(xs * zs**2)
    c[small] = scale * (powers @ _COS_TERMS)
    s[small] = scale * zs * (powers @ _SIN_TERMS)
    r = np.sqrt(x[pos])
    c[pos], s[pos] = np.cos(r * z[pos]), np.sin(r * z[pos]) / r
    a, zn = np.sqrt(-x[neg]), np.abs(z[neg])
    grow, decay = np.exp(a * (zn - h)), np.exp(-a * (zn + h))
    c[neg] = (grow + decay) / 2.0
    s[neg] = -np.sign(z[neg]) * grow * np.expm1(-2.0 * a * zn) / (2.0 * a)
    return c, s


def _powers(x: np.ndarray) -> np.ndarray:
    """(len(x), _N_TERMS): ``x**0 .. x**(_N_TERMS - 1)`` of the Taylor series, by repeated
    products (``np.power`` is several times slower; the products round within a few ulps of
    it, far below the series' own truncation)."""
    out = np.empty((len(x), _N_TERMS), dtype=np.result_type(x, 1.0))
    out[:, 0] = 1.0
    for n in range(1, _N_TERMS):
        np.multiply(out[:, n - 1], x, out=out[:, n])
    return out


def _cross_term(p2, q2, gap, h: float, cp, sp, cq, sq):
    """``D = C(p^2) S(q^2) - S(p^2) C(q^2)`` at ``z = h``, free of cancellation.

    ``dD/dh = (q^2 - p^2) S(p^2) S(q^2)`` and ``D(0) = 0``, so
    ``D = (q^2 - p^2) * integral_0^h S(p^2; t) S(q^2; t) dt``, with the
    ``gap = q^2 - p^2 = omega^2 (1/cT^2 - 1/cL^2)`` passed exact. Where both
    ``|p^2| h^2`` and ``|q^2| h^2`` are below 1 (slow, long A0 waves, where the
    two products agree to many digits) the integral is summed as a double
    Taylor series; elsewhere ``D`` is formed directly. Same scaling as the
    thickness functions.
    """
    small = (np.abs(p2) * h * h < 1.0) & (np.abs(q2) * h * h < 1.0)
    direct = cp * sq - sp * cq
    x, y = np.where(small, p2, 0.0) * h * h, np.where(small, q2, 0.0) * h * h
    integral = np.einsum("in,nm,im->i", _powers(x), _CROSS_TERMS, _powers(y)) * h**3
    scale = np.exp(-np.sqrt(np.maximum(-x.real, 0.0)) - np.sqrt(np.maximum(-y.real, 0.0)))
    return np.where(small, gap * scale * integral, direct)


def _lamb_function(plate: _Plate, k, omega, family: str) -> np.ndarray:
    """Scaled Rayleigh-Lamb function of one symmetry at wavenumbers ``k`` (rad/m) and angular
    frequency ``omega`` (rad/s: a number, or an array of ``k``'s shape, one per wavenumber).

    S: ``(q^2 - k^2)^2 C(p^2) S(q^2) + 4 k^2 p^2 S(p^2) C(q^2)``. A: the module's
    form rewritten with ``(q^2 - k^2)^2 = (q^2 + k^2)^2 - 4 k^2 q^2``,
    ``q^2 + k^2 = omega^2 / cT^2``, as
    ``(omega/cT)^4 S(p^2) C(q^2) + 4 k^2 q^2 D`` with ``D`` of
    :func:`_cross_term`, which keeps slow A0 waves accurate (the two terms of
    the plain form cancel to ``O((k h)^4)`` there). Zeros are the Lamb modes.
    """
    h, kk = plate.h, np.atleast_1d(k) ** 2
    p2, q2 = (omega / plate.cl) ** 2 - kk, (omega / plate.ct) ** 2 - kk
    cp, sp = _thickness_functions(p2, h, h)
    cq, sq = _thickness_functions(q2, h, h)
    if family == "S":
        return (q2 - kk) ** 2 * cp * sq + 4.0 * kk * p2 * sp * cq
    gap = omega**2 * (1.0 / plate.ct**2 - 1.0 / plate.cl**2)
    cross = _cross_term(p2, q2, gap, h, cp, sp, cq, sq)
    return (omega / plate.ct) ** 4 * sp * cq + 4.0 * kk * q2 * cross


def _group_velocities(plate: _Plate, k: np.ndarray, omega: np.ndarray, family: str) -> np.ndarray:
    """``d omega / d k = -F_k / F_omega`` at roots ``(k, omega)`` (arrays of one shape).

    Implicit differentiation of the dispersion function ``F``, its partial
    derivatives taken by complex steps, ``F_k = Im F(k + i e) / e``, which is
    exact to round-off (no subtraction). The scale of ``F`` drops out of the
    ratio because ``F = 0`` at the root.
    """
    dk, dw = _COMPLEX_STEP * k, _COMPLEX_STEP * omega
    f_k = _lamb_function(plate, k + 1j * dk, omega, family).imag / dk
    f_w = _lamb_function(plate, k, omega + 1j * dw, family).imag / dw
    return -f_k / f_w


# --- roots and labels -------------------------------------------------------------


def scan_points(plate: _Plate, omega: float) -> int:
    """Points of ``_scan_grid(plate, omega)``, counted without making it."""
    return max(400, int(_SCAN_DENSITY * (omega / plate.ct) * plate.h)) + _SLOW_SCAN_POINTS - 1


def check_scan_fits(plate: _Plate, frequency: float, thickness: float) -> None:
    """Refuse, before allocating, a root search at ``frequency`` (Hz) whose scan would not fit
    in memory (``SCAN_BYTES`` a point against ``geometry.memory_limit``): the modes, and the
    scan points, grow with the frequency-thickness product.

    Raises
    ------
    InputError
        Naming the frequency, the bytes needed and those available.
    """
    points = scan_points(plate, 2.0 * np.pi * frequency)
    needed, available = SCAN_BYTES * points, geometry.memory_limit()
    if needed > available:
        raise InputError(
            f"the Rayleigh-Lamb modes at {frequency:.3g} Hz in a {thickness:.3g} m plate need a scan of "
            f"{points:.3g} wavenumbers, about {needed / 1e9:.3g} GB, more than the {available / 1e9:.3g} "
            "GB of this machine: lower the frequency or the thickness (the modes grow with their product)"
        )


def _scan_grid(plate: _Plate, omega: float) -> np.ndarray:
    """Ascending wavenumbers (rad/m) that bracket every root at ``omega``.

    Above ``cT``: ``k = kT cos(theta)``, uniform in ``theta`` so that the shear
    phase ``q h = kT h sin(theta)`` advances evenly. Below ``cT``: uniform in
    phase velocity down to 0.4 times the slower of the Rayleigh speed and the
    Kirchhoff flexural speed ``sqrt(omega h cp / sqrt(3))``: A0 stays above 0.77
    times that (checked for nu in [-0.8, 0.49] and f h from 0.1 Hz m to 10 kHz m).
    """
    kt = omega / plate.ct
    n_fast = max(400, int(_SCAN_DENSITY * kt * plate.h))
    fast = kt * np.cos(np.linspace(0.5 * np.pi, 0.0, n_fast))
    kirchhoff = math.sqrt(omega * plate.h * plate.cp / math.sqrt(3.0))
    c_low = 0.4 * min(plate.cr, kirchhoff)
    slow = omega / np.linspace(plate.ct, c_low, _SLOW_SCAN_POINTS)
    return np.concatenate([fast, slow[1:]])


def _root_brackets(plate: _Plate, omega: float, family: str) -> list[tuple[float, float]]:
    """Intervals of wavenumber (rad/m) holding one root each of one symmetry at ``omega``."""
    grid = _scan_grid(plate, omega)

    def f(k):
        return float(_lamb_function(plate, k, omega, family)[0])

    return _brackets(grid, _lamb_function(plate, grid, omega, family), f)


def _refine(plate: _Plate, omega: np.ndarray, family: str, lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    """The root (rad/m) in each bracket ``[lo, hi]`` (one sign change of ``F`` at ``omega``), to
    ``ROOT_RTOL`` relative, every bracket at once.

    Illinois steps (a secant through the bracket's ends whose end that stays twice in a row
    has its value halved, which keeps the convergence superlinear), a bisection whenever a step
    would leave the bracket or two steps have not halved it.
    """
    lo, hi = lo.astype(float), hi.astype(float)
    f_lo = _lamb_function(plate, lo, omega, family)
    f_hi = _lamb_function(plate, hi, omega, family)
    root = np.where(f_lo == 0.0, lo, np.where(f_hi == 0.0, hi, np.nan))
    width, side = hi - lo, np.zeros(len(lo), dtype=np.int8)
    for it in range(_MAX_REFINE_STEPS):
        open_ = np.flatnonzero(np.isnan(root))
        if not open_.size:
            return root
        a, b, fa, fb = lo[open_], hi[open_], f_lo[open_], f_hi[open_]
        c = (a * fb - b * fa) / (fb - fa)
        outside = ~((c > a) & (c < b))
        slow = (it % 2 == 1) & (b - a > 0.5 * width[open_])  # two steps have not halved it
        bisect = outside | slow
        c = np.where(bisect, 0.5 * (a + b), c)
        if it % 2 == 1:
            width[open_] = b - a
        fc = _lamb_function(plate, c, omega[open_], family)
        left = np.signbit(fc) == np.signbit(fa)  # the root is in [c, b]: c replaces a
        done = (fc == 0.0) | (np.where(left, b - c, c - a) <= ROOT_RTOL * np.abs(c))
        root[open_[done]] = c[done]
        # Illinois: the end kept twice in a row has its value halved
        s_prev = side[open_]
        f_hi[open_] = np.where(left & (s_prev == 1), 0.5 * fb, fb)
        f_lo[open_] = np.where(~left & (s_prev == -1), 0.5 * fa, fa)
        lo[open_] = np.where(left, c, a)
        f_lo[open_] = np.where(left, fc, f_lo[open_])
        hi[open_] = np.where(left, b, c)
        f_hi[open_] = np.where(left, f_hi[open_], fc)
        side[open_] = np.where(left, 1, -1)
    raise RuntimeError(f"Rayleigh-Lamb roots not refined in {_MAX_REFINE_STEPS} steps")


def _brackets(grid, values, f) -> list[tuple[float, float]]:
    """Intervals of ``grid`` holding one sign change of ``f`` each.

    Besides the sign changes between neighbours, a dip of ``|f|`` at a grid
    point between two of the same sign may hide two roots closer than a step
    (near crossings of branches of one symmetry): the minimum of ``|f|`` around
    it is found, and where ``f`` changes sign there, both halves are kept.
    """
    # imported here: scipy.optimize costs a process 15 MB (an explicit run solves for no root)
    from scipy.optimize import minimize_scalar

    sign, size = np.signbit(values), np.abs(values)
    brackets = [(grid[i], grid[i + 1]) for i in np.flatnonzero(sign[:-1] != sign[1:])]
    same = (sign[:-2] == sign[1:-1]) & (sign[1:-1] == sign[2:])
    dips = np.flatnonzero(same & (size[1:-1] <= size[:-2]) & (size[1:-1] <= size[2:])) + 1
    for i in dips:
        polarity = -1.0 if sign[i] else 1.0
        lo, hi = grid[i - 1], grid[i + 1]
        bottom = minimize_scalar(
            lambda k, p=polarity: p * f(k),
            bounds=(lo, hi),
            method="bounded",
            options={"xatol": 1e-13 * hi},
        ).x
        if polarity * f(bottom) < 0:
            brackets += [(lo, bottom), (bottom, hi)]
    return brackets


def _family_modes(plate: _Plate, frequencies: np.ndarray, family: str) -> list[list[LambMode]]:
    """The modes of one symmetry at each of ``frequencies`` (Hz), labelled by branch.

    In descending ``k`` the branches come in order; a forward root opens the
    next branch and a backward root (``cg < 0``) belongs to the branch of the
    forward root just before it (the two meet at the branch's ZGV point).
    """
    omegas = 2.0 * np.pi * np.asarray(frequencies, dtype=float)
    found = [(i, a, b) for i, omega in enumerate(omegas) for a, b in _root_brackets(plate, omega, family)]
    owner = np.array([i for i, _, _ in found], dtype=np.int64)
    omega = omegas[owner]
    roots = _refine(
        plate, omega, family, np.array([a for _, a, _ in found]), np.array([b for _, _, b in found])
    )
    speeds = _group_velocities(plate, roots, omega, family) if len(roots) else roots
    table = []
    for i, frequency in enumerate(np.asarray(frequencies, dtype=float).tolist()):
        mine = np.flatnonzero(owner == i)
        modes, forward = [], 0
        for r in mine[np.argsort(-roots[mine], kind="stable")]:
            cg = float(speeds[r])
            order = forward - 1 if cg < 0 else forward
            forward += cg >= 0
            modes.append(
                LambMode(f"{family}{order}", frequency, float(omegas[i] / roots[r]), cg, float(roots[r]))
            )
        table.append(sorted(modes, key=lambda m: int(m.mode[1:])))
    return table


def _branch(label: str, modes: list[LambMode]) -> DispersionBranch:
    """Stack the modes of one branch into arrays ordered by wavenumber."""
    modes = sorted(modes, key=lambda m: m.wavenumber_rad_m)
    column = {
        key: np.array([getattr(m, key) for m in modes])
        for key in ("frequency_hz", "wavenumber_rad_m", "phase_velocity_m_s", "group_velocity_m_s")
    }
    return DispersionBranch(label, **column)
