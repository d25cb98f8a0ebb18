"""Dispersion of plane waves in linear peridynamic media (PMB and LPS; 1D, 2D, 3D).

A plane wave ``u(x, t) = U exp(i (k d.x - omega t))`` travelling along the unit
vector ``d`` solves the linearised equation of motion of an infinite,
homogeneous peridynamic medium when ``rho omega^2 U = D(k) U``. The acoustic
tensor ``D(k)`` (dim x dim, Pa/m^2) is a sum over the family of one point, with
``x = d.xi``, ``n = xi/|xi|``, ``w = omega(|xi|) V`` and ``1 - cos(k x)``
evaluated as ``2 sin^2(k x / 2)`` (no cancellation at small k):

PMB (bond-based; force ``c0 omega s n`` per unit volume squared)::

    D(k) = sum c0 omega / |xi| V n n^T (1 - cos k x)

LPS (state-based; energy ``kappa theta^2/2 + (alpha/2) sum w (e - theta |xi|/dim)^2``,
``alpha = dim (dim + 2) mu / m``: 15 mu/m in 3D, 8 mu/m in 2D, 3 mu/m in 1D;
``theta = (dim/m) sum w |xi| e``; ``m = sum w |xi|^2``)::

    D(k) = 2 alpha sum w n n^T (1 - cos k x) + (kappa - alpha m / dim^2) g g^T,
    g(k) = (dim/m) sum w |xi| n sin(k x)

The first term is the pair part; the second the rank-one dilatation part
(``g -> k d`` as ``k -> 0``). Long waves: ``D -> k^2 C`` with the classical
acoustic tensor of an isotropic solid whenever the family is isotropic to
fourth order, i.e. exactly for the continuous relations and for every
influence function: 3D LPS ``rho cL^2 = K + 4 mu / 3``, ``rho cS^2 = mu``.

Constants are those of the running code, given by each material class
(``Model.plane_wave_coefficients``, ``peridyn.physics.materials``): PMB
``c0 = pmb_micromodulus(E, ...)`` (3D and 2D; it implies nu = 1/4, or 1/3 in
plane stress, so a PMB's long-wave speeds are those of (E, that nu)); LPS
``kappa = K`` (3D) or the in-plane bulk modulus (2D, plane stress or strain).
1D analogues, defined here for a bar of unit cross-section with Young's
modulus E: PMB ``c0 = E / int_0^delta omega r dr`` (``2 E / delta^2`` for a
constant omega, Silling 2000); LPS ``kappa = E`` and ``alpha = 3 mu / m``
(``dim (dim + 2)``; the deviatoric part vanishes for homogeneous strains in
1D, so it sets dispersion but not the long-wave speed ``sqrt(E / rho)``).

Families:

- continuous: Gauss-Legendre in ``|xi|`` (and in ``cos`` of the polar angle
  about ``d`` in 3D) times the trapezoidal rule in the azimuth, aligned with
  ``d`` so that the pure-mode symmetry is exact; enough nodes to resolve
  ``k_max delta``;
- discrete: the family of the centre point of a block of a simple cubic
  (square) lattice of spacing ``h``, found by :func:`peridyn.discretization.bonds.find_bonds`
  exactly as in a run (same neighbours, influence values and partial-volume
  factors ``beta``, ``V = beta h^dim``); ``m`` is the discrete sum. 1D has no
  body in the engine: its lattice family is ``xi = j h``, with partial volumes
  the exact length fraction of each cell inside ``[-delta, delta]``
  (:func:`peridyn.discretization.bonds.cell_fraction_in_ball`).

Branches are labelled by polarisation: ``longitudinal`` along ``d``;
``shear_1`` along ``z x d`` (in-plane; ``x`` when ``d`` is ``z``), ``shear_2``
along ``d x shear_1``. Along lattice symmetry axes (x, xy, xyz) and in the
continuum these are exact eigenvectors of ``D(k)`` (see
:func:`branch_eigenvalues` for the small asymmetry of partial volumes);
off those axes the modes are quasi-longitudinal and quasi-shear, each
eigenvector going to the polarisation it overlaps most, so a branch may jump
where two of them cross. Group velocities are analytic:
``d omega/dk = v^T D'(k) v / (2 rho omega)`` (Hellmann-Feynman) with ``D'`` the
exact derivative of the sums above.

:func:`study` runs the dispersion study's parameter study (influence functions, horizons,
grid spacings) and tabulates long-wave errors, accurate bands and the onsets of
negative group velocity; ``docs/dispersion.md`` holds the results.
"""

from __future__ import annotations

import functools
import itertools
from dataclasses import dataclass, field

import numpy as np

from peridyn.discretization import geometry
from peridyn.discretization.body import in_sphere
from peridyn.discretization.bonds import HORIZON_RTOL, cell_fraction_in_ball, find_bonds, influence_function
from peridyn.errors import InputError
from peridyn.physics.materials.elastic import check_elastic, dilatational_modulus, shear_modulus
from peridyn.physics.materials.family import PointFamily
from peridyn.physics.materials.registry import model_class

__all__ = [
    "BRANCHES",
    "MARAGING_STEEL",
    "Branch",
    "DispersionRelation",
    "Family",
    "LinearModel",
    "Medium",
    "Study",
    "acoustic_tensor",
    "branch_eigenvalues",
    "continuum_family",
    "dispersion_relation",
    "lattice_family",
    "linear_model",
    "parse_direction",
    "polarisations",
    "study",
]

#: Branch names, in the order of the polarisation basis (longitudinal first).
BRANCHES = ("longitudinal", "shear_1", "shear_2")
#: Wavenumber (times the horizon) of the long-wave limit: D(k)/k^2 is exact to O((k delta)^2).
_LONG_WAVE_K_DELTA = 1e-6
#: Group velocities below this fraction of the long-wave speed count as negative
#: (the lattice group velocity is zero, to round-off, at the zone edge).
_NEGATIVE_TOL = 1e-8
#: Off-diagonal part of D (relative) below which the polarisations count as pure modes.
_PURE_MODE_TOL = 1e-3
#: Quadrature nodes of the continuous families beyond k_max * delta.
_EXTRA_NODES = 32
#: Bytes held per wavenumber and family bond by ``acoustic_tensor``: the phases, their sines and
#: cosines and the products with the bond terms (32.4 B measured with ``tracemalloc``, 3D
#: continuum, 400 wavenumbers, 7 056 quadrature bonds).
TENSOR_BYTES = 36.0
#: Bytes per bond of the lattice block searched by ``lattice_family`` (``find_bonds``: the
#: neighbour index, the volume factor and the search's temporaries; about 14 B measured for a
#: horizon of 6 spacings in 3D).
SEARCH_BYTES = 16.0


@dataclass(frozen=True)
class Medium:
    """An isotropic elastic medium.

    Attributes
    ----------
    E : float, Pa
        Young's modulus.
    nu : float
        Poisson's ratio.
    density : float, kg/m^3
    """

    E: float
    nu: float
    density: float

    def __post_init__(self):
        check_elastic(self.E, self.nu, self.density)

    @classmethod
    def from_moduli(cls, bulk: float, shear: float, density: float) -> Medium:
        """The medium of bulk modulus ``bulk`` and shear modulus ``shear`` (Pa)."""
        for name, value in (("bulk modulus", bulk), ("shear modulus", shear)):
            if not (np.isfinite(value) and value > 0):
                raise InputError(f"the {name} must be positive and finite, got {value!r} Pa")
        return cls(
            E=9.0 * bulk * shear / (3.0 * bulk + shear),
            nu=(3.0 * bulk - 2.0 * shear) / (2.0 * (3.0 * bulk + shear)),
            density=density,
        )

    @property
    def shear(self) -> float:
        """Shear modulus mu, Pa."""
        return shear_modulus(self.E, self.nu)

    def dilatational_modulus(self, dim: int, plane: str = "stress") -> float:
        """kappa of a dim-dimensional LPS, Pa: K (3D), in-plane bulk modulus (2D), E (1D)."""
        return dilatational_modulus(self.E, self.nu, dim, plane)

    def as_modelled(self, model: str, dim: int, plane: str = "stress") -> Medium:
        """The medium a ``model`` represents: a bond-based material keeps E and takes the
        Poisson ratio it implies (``Model.implied_poisson_ratio``: PMB 1/4; 1/3 in plane
        stress; 1D has none)."""
        implied = None if dim == 1 else model_class(model).implied_poisson_ratio(dim, plane)
        if implied is None:
            return self
        return Medium(self.E, implied, self.density)

    def classical_speeds(self, dim: int, plane: str = "stress") -> tuple[float, float]:
        """Classical (longitudinal, shear) speeds, m/s; 1D: the bar speed and 0.

        3D ``sqrt((K + 4 mu/3)/rho)``, 2D ``sqrt((kappa + mu)/rho)``, shear ``sqrt(mu/rho)``.
        """
        if dim == 1:
            return float(np.sqrt(self.E / self.density)), 0.0
        mu = self.shear
        kappa = self.dilatational_modulus(dim, plane)
        p_modulus = kappa + (4.0 * mu / 3.0 if dim == 3 else mu)
        return float(np.sqrt(p_modulus / self.density)), float(np.sqrt(mu / self.density))


#: Maraging steel of the dispersion study (docs/reference-cases.md, V3): K = 132.77 GPa, mu = 81.92 GPa,
#: rho = 8000 kg/m^3 (classical cL = 5500 m/s, cS = 3200 m/s).
MARAGING_STEEL = Medium.from_moduli(132.77e9, 81.92e9, 8000.0)


@dataclass(frozen=True)
class Family:
    """The family of one point of an infinite homogeneous medium.

    Attributes
    ----------
    xi : (n, 3) float64, m
        Bond vectors (z = 0 in 2D, y = z = 0 in 1D).
    volume : (n,) float64, m^3 (m^2 in 1D: unit cross-section)
        Volume of each neighbour times its partial-volume factor, or the
        quadrature weight of a continuous family.
    influence : (n,) float64
        ``omega(|xi|)``.
    dim : int
    horizon : float, m
    influence_name : str
    thickness : float or None, m
        Out-of-plane thickness of a 2D family (its volumes include it).
    """

    xi: np.ndarray
    volume: np.ndarray
    influence: np.ndarray
    dim: int
    horizon: float
    influence_name: str
    thickness: float | None = None

    @property
    def length(self) -> np.ndarray:
        """(n,) ``|xi|``, m."""
        return np.linalg.norm(self.xi, axis=1)

    @property
    def weighted_volume(self) -> float:
        """``m = sum omega V |xi|^2`` (m^5 in 3D)."""
        return float(np.sum(self.influence * self.volume * self.length**2))


@dataclass(frozen=True)
class LinearModel:
    """Coefficients of the acoustic tensor of a family (see the module docstring).

    Attributes
    ----------
    pair : (n,) float64, Pa/m^2
        Per-bond coefficient of ``n n^T (1 - cos k x)``: PMB ``c0 omega V / |xi|``,
        LPS ``2 alpha omega V``.
    dilatation : (n,) float64, 1/m
        Per-bond weight of ``g``: ``(dim/m) omega V |xi|`` (zeros for PMB).
    dilatation_modulus : float, Pa
        Coefficient of ``g g^T``: ``kappa - alpha m / dim^2`` (0 for PMB).
    """

    pair: np.ndarray
    dilatation: np.ndarray
    dilatation_modulus: float


def linear_model(model: str, family: Family, medium: Medium, plane: str = "stress") -> LinearModel:
    """The linearised ``model`` (a registered material name) of ``medium`` on ``family``, as
    the material class gives it (``Model.plane_wave_coefficients``)."""
    point = PointFamily(
        family.length,
        family.influence * family.volume,
        family.dim,
        family.horizon,
        family.influence_name,
        plane,
        family.thickness,
    )
    return LinearModel(*model_class(model).plane_wave_coefficients(point, medium.E, medium.nu))


# -- directions and polarisations ---------------------------------------------------------


def parse_direction(direction, dim: int) -> np.ndarray:
    """Unit vector (3,) of a propagation direction.

    Parameters
    ----------
    direction : str or 3 floats
        Axis letters ("x", "xy", "xyz": the sum of those unit vectors) or a vector.
    dim : {1, 2, 3}
        1D allows only x, 2D only directions in the x-y plane.
    """
    if isinstance(direction, str):
        letters = direction.strip().lower()
        if not letters or set(letters) - set("xyz") or len(set(letters)) != len(letters):
            raise InputError(
                f"direction {direction!r}: expected axis letters such as x, xy or "
                "xyz, or a vector of 3 numbers"
            )
        vector = np.array([float(a in letters) for a in "xyz"])
    else:
        vector = np.asarray(direction, dtype=float).ravel()
        if vector.shape != (3,) or not np.all(np.isfinite(vector)) or not vector.any():
            raise InputError(f"direction {direction!r}: expected a non-zero vector of 3 numbers")
    unit = vector / np.linalg.norm(vector)
    if np.any(np.abs(unit[dim:]) > 1e-12):
        allowed = "x" if dim == 1 else "directions in the x-y plane"
        raise InputError(f"direction {direction!r}: a {dim}D medium allows only {allowed}")
    return unit


def polarisations(direction: np.ndarray, dim: int) -> np.ndarray:
    """(dim, 3) polarisation basis: longitudinal, shear_1 (along z x d), shear_2 (d x shear_1)."""
    d = np.asarray(direction, dtype=float)
    s1 = np.cross([0.0, 0.0, 1.0], d)
    s1 = s1 / np.linalg.norm(s1) if np.linalg.norm(s1) > 1e-12 else np.array([1.0, 0.0, 0.0])
    return np.stack([d, s1, np.cross(d, s1)])[:dim]


# -- families ---------------------------------------------------------------------------


def continuum_family(
    horizon: float, influence: str, dim: int, direction: np.ndarray, k_max: float, thickness: float = 1.0
) -> Family:
    """Quadrature family of the continuous horizon (segment, disc or ball), aligned with ``direction``.

    Gauss-Legendre in ``|xi|`` on [0, delta] (mirrored in 1D) and, in 3D, in the
    cosine of the polar angle about ``direction``; trapezoidal rule in the
    azimuth (4 nodes in 3D, where the integrand is a trigonometric polynomial
    of degree 2 in it; as many as the radial nodes in 2D). The node count grows
    with ``k_max * horizon`` so that ``sin(k d.xi)`` is resolved up to ``k_max``.
    """
    omega = influence_function(influence)
    n = int(np.ceil(k_max * horizon)) + _EXTRA_NODES
    t, wt = np.polynomial.legendre.leggauss(n)
    r, wr = 0.5 * horizon * (t + 1.0), 0.5 * horizon * wt
    basis = polarisations(direction, 3)
    if dim == 1:
        xi = np.concatenate([r, -r])[:, None] * basis[0]
        volume = np.concatenate([wr, wr])
    elif dim == 2:
        phi = 2.0 * np.pi * np.arange(n) / n
        rr, pp = np.meshgrid(r, phi, indexing="ij")
        xi = (rr * np.cos(pp)).ravel()[:, None] * basis[0] + (rr * np.sin(pp)).ravel()[:, None] * basis[1]
        volume = np.repeat(wr * r, n) * (2.0 * np.pi / n) * thickness
    else:
        phi = 2.0 * np.pi * np.arange(4) / 4
        rr, mu, pp = np.meshgrid(r, t, phi, indexing="ij")
        sine = np.sqrt(1.0 - mu**2)
        xi = sum(
            (rr * c).ravel()[:, None] * b
            for c, b in zip((mu, sine * np.cos(pp), sine * np.sin(pp)), basis, strict=True)
        )
        volume = np.einsum("i,j->ij", wr * r**2, wt)[:, :, None].repeat(4, axis=2).ravel() * (np.pi / 2)
    length = np.linalg.norm(xi, axis=1)
    return Family(
        xi, volume, omega(length, horizon), dim, float(horizon), influence, thickness if dim == 2 else None
    )


def lattice_family(
    spacing: float, horizon: float, influence: str = "constant", dim: int = 3, partial_volumes: bool = True
) -> Family:
    """Family of a point of an infinite simple cubic (square, 1D: uniform) lattice.

    In 2D and 3D the family of the centre point of a ball-shaped block of
    lattice points, found by :func:`peridyn.discretization.bonds.find_bonds` as in a run (2D:
    thickness = spacing). The geometry (bonds and partial volumes) does not
    depend on the influence function and is cached, so studies over influence
    functions and models search each lattice once.
    """
    omega = influence_function(influence)
    if dim == 1:
        xi, volume = _chain_geometry(float(spacing), float(horizon), bool(partial_volumes))
    else:
        xi, volume = _lattice_geometry(float(spacing), float(horizon), int(dim), bool(partial_volumes))
    return Family(
        xi,
        volume,
        omega(np.linalg.norm(xi, axis=1), horizon),
        dim,
        float(horizon),
        influence,
        spacing if dim == 2 else None,
    )


@functools.lru_cache(maxsize=32)
def _lattice_geometry(
    spacing: float, horizon: float, dim: int, partial_volumes: bool
) -> tuple[np.ndarray, np.ndarray]:
    """Bond vectors (n, 3) and volumes (n,) of the centre point of a lattice block (read-only)."""
    reach = horizon + spacing * (np.sqrt(dim) / 2.0 + 1.0)
    n = 2 * int(np.ceil(reach / spacing)) + 1
    side = n * spacing
    if dim == 3:
        body = geometry.box((side,) * 3, spacing, origin=(-side / 2,) * 3)
    else:
        body = geometry.rectangle(side, side, spacing, thickness=spacing, origin=(-side / 2,) * 2)
    body = body.remove(lambda x: ~in_sphere((0.0, 0.0, 0.0), reach)(x))
    bonds = find_bonds(body, horizon, partial_volumes=partial_volumes)
    centre = int(np.argmin(np.linalg.norm(body.points, axis=1)))
    family = slice(bonds.offsets[centre], bonds.offsets[centre + 1])
    nbr = bonds.neighbours[family]
    return _read_only(body.points[nbr] - body.points[centre], body.volumes[nbr] * bonds.volume_factor[family])


def _read_only(*arrays: np.ndarray) -> tuple[np.ndarray, ...]:
    for a in arrays:
        a.setflags(write=False)
    return arrays


@functools.lru_cache(maxsize=32)
def _chain_geometry(spacing: float, horizon: float, partial_volumes: bool) -> tuple[np.ndarray, np.ndarray]:
    """1D lattice family ``xi = j h`` (unit cross-section): bond vectors and volumes."""
    reach = horizon * (1 + HORIZON_RTOL) + (0.5 * spacing if partial_volumes else 0.0)
    j = np.arange(1, int(np.floor(reach / spacing)) + 1)
    if not len(j):
        raise InputError(
            f"horizon {horizon:g} m is too small for the spacing {spacing:g} m: the family is empty"
        )
    xi = np.zeros((2 * len(j), 3))
    xi[:, 0] = np.concatenate([j, -j]) * spacing
    beta = np.ones(len(xi))
    if partial_volumes:
        beta = cell_fraction_in_ball(
            xi, np.tile([spacing, 0.0, 0.0], (len(xi), 1)), horizon * (1 + HORIZON_RTOL)
        )
    return _read_only(xi, beta * spacing)


# -- acoustic tensor and branches ---------------------------------------------------------


def acoustic_tensor(
    lin: LinearModel, family: Family, basis: np.ndarray, k: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """D(k) and dD/dk in the polarisation basis.

    Parameters
    ----------
    lin : LinearModel
    family : Family
    basis : (dim, 3) float64
        Polarisations; ``basis[0]`` is the propagation direction.
    k : (n_k,) float64, rad/m

    Returns
    -------
    D, dD : (n_k, dim, dim) float64, Pa/m^2 and Pa/m
    """
    x = family.xi @ basis[0]
    n = (family.xi @ basis.T) / family.length[:, None]
    dim = len(basis)
    nn = (n[:, :, None] * n[:, None, :]).reshape(len(x), dim * dim)
    phase = np.outer(k, x)
    sin = np.sin(phase)
    pair = (2.0 * np.sin(0.5 * phase) ** 2 * lin.pair) @ nn
    dpair = (sin * (lin.pair * x)) @ nn
    g = (sin * lin.dilatation) @ n
    dg = (np.cos(phase) * (lin.dilatation * x)) @ n
    c = lin.dilatation_modulus
    D = pair.reshape(-1, dim, dim) + c * g[:, :, None] * g[:, None, :]
    dD = dpair.reshape(-1, dim, dim) + c * (dg[:, :, None] * g[:, None, :] + g[:, :, None] * dg[:, None, :])
    return D, dD


def branch_eigenvalues(D: np.ndarray, dD: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Eigenvalues of D and their k-derivatives, column b for polarisation b.

    When D is diagonal in the polarisation basis to within ``_PURE_MODE_TOL``
    (relative) at every k, the polarisations are taken as the eigenvectors and
    the diagonal is used as is: exact along symmetry axes and in the continuum
    (where it also covers degenerate shear branches); along xy and xyz with
    partial volumes the lattice family is cubic only to about 5e-4 (the
    partial-volume quadrature is exact along x only), and the diagonal then
    follows each polarisation through the crossings of branches, with an error
    of second order in that asymmetry elsewhere. Otherwise each eigenvector goes
    to the polarisation it overlaps most (best permutation per k) and its slope
    is ``v^T dD v``.
    """
    diag = np.diagonal(D, axis1=1, axis2=2)
    off = D - diag[:, :, None] * np.eye(D.shape[1])
    if np.max(np.abs(off), initial=0.0) <= _PURE_MODE_TOL * np.max(np.abs(diag)):
        return diag.copy(), np.diagonal(dD, axis1=1, axis2=2).copy()
    lam, vec = np.linalg.eigh(D)
    slope = np.einsum("kib,kij,kjb->kb", vec, dD, vec)
    perms = np.array(list(itertools.permutations(range(D.shape[1]))))
    overlap = vec**2  # [k, polarisation, eigenvector]
    score = overlap[:, np.arange(D.shape[1]), perms].sum(axis=2)  # [k, perm]
    best = perms[np.argmax(score, axis=1)]  # eigenvector of each polarisation
    rows = np.arange(len(D))[:, None]
    return lam[rows, best], slope[rows, best]


# -- results ------------------------------------------------------------------------------


@dataclass(frozen=True)
class Branch:
    """One branch omega(k) of a dispersion relation.

    Attributes
    ----------
    name : str
        "longitudinal", "shear_1" or "shear_2".
    polarisation : (3,) float64
    wavenumber : (n_k,) float64, rad/m
    frequency : (n_k,) float64, rad/s
        Angular frequency omega(k).
    phase_velocity : (n_k,) float64, m/s
    group_velocity : (n_k,) float64, m/s
        Analytic d omega/dk.
    long_wave_limit : float, m/s
    negative_group_velocity_from : float or None, rad/m
        First wavenumber where the group velocity turns negative (None if it
        does not up to the largest sampled wavenumber).
    """

    name: str
    polarisation: np.ndarray
    wavenumber: np.ndarray
    frequency: np.ndarray
    phase_velocity: np.ndarray
    group_velocity: np.ndarray
    long_wave_limit: float
    negative_group_velocity_from: float | None

    def accuracy_band(self, reference: float, tolerance: float) -> float:
        """Largest sampled wavenumber (rad/m) up to which every phase velocity lies within
        ``tolerance`` (relative) of ``reference`` (m/s); 0 when the first sample does not."""
        bad = np.flatnonzero(np.abs(self.phase_velocity / reference - 1.0) > tolerance)
        if not len(bad):
            return float(self.wavenumber[-1])
        return float(self.wavenumber[bad[0] - 1]) if bad[0] > 0 else 0.0

    def to_dict(self) -> dict:
        """JSON-ready summary with units in the keys."""
        return {
            "polarisation": self.polarisation.tolist(),
            "long_wave_limit_m_s": self.long_wave_limit,
            "negative_group_velocity_from_rad_m": self.negative_group_velocity_from,
            "wavenumber_rad_m": self.wavenumber.tolist(),
            "frequency_rad_s": self.frequency.tolist(),
            "phase_velocity_m_s": self.phase_velocity.tolist(),
            "group_velocity_m_s": self.group_velocity.tolist(),
        }


@dataclass(frozen=True)
class DispersionRelation:
    """omega(k) of every branch of one medium, model and discretisation.

    Attributes
    ----------
    model : str
    dim : int
    direction : (3,) float64
    discrete : bool
    partial_volumes : bool
    horizon, spacing : float, m
    influence : str
    nyquist : float, rad/m
        pi / spacing.
    zone_edge : float, rad/m
        Edge of the lattice's Brillouin zone along the direction, pi / (h max|d_i|).
    classical : (longitudinal, shear) float, m/s
        Classical speeds of the medium as modelled (:meth:`Medium.as_modelled`:
        a PMB's are those of E with the Poisson ratio it implies).
    branches : dict of str to Branch
    group_velocity_method : str
    """

    model: str
    dim: int
    direction: np.ndarray
    discrete: bool
    partial_volumes: bool
    horizon: float
    spacing: float
    influence: str
    nyquist: float
    zone_edge: float
    classical: tuple[float, float]
    branches: dict = field(default_factory=dict)
    group_velocity_method: str = "analytic (Hellmann-Feynman: v^T dD/dk v / (2 rho omega))"

    def shear_branches(self) -> list[Branch]:
        """The shear branches (none in 1D)."""
        return [b for name, b in self.branches.items() if name != "longitudinal"]

    def to_dict(self) -> dict:
        """JSON-ready summary (``peridyn dispersion --json``), units in the keys.

        ``"shear"`` is shear_1 for the long-wave limit and the earliest of the
        shear branches for the negative group velocity.
        """
        shear = self.shear_branches()
        onsets = [b.negative_group_velocity_from for b in shear if b.negative_group_velocity_from is not None]
        long = self.branches["longitudinal"]
        limits = {"longitudinal": long.long_wave_limit, "shear": shear[0].long_wave_limit if shear else None}
        if len(shear) == 2:
            limits["shear_2"] = shear[1].long_wave_limit
        return {
            "model": self.model,
            "dimension": self.dim,
            "direction": self.direction.tolist(),
            "discrete": self.discrete,
            "partial_volumes": self.partial_volumes,
            "horizon_m": self.horizon,
            "spacing_m": self.spacing,
            "influence": self.influence,
            "long_wave_limit_m_s": limits,
            "classical_speeds_m_s": {
                "longitudinal": self.classical[0],
                "shear": self.classical[1] if self.dim > 1 else None,
            },
            "negative_group_velocity_from_rad_m": {
                "longitudinal": long.negative_group_velocity_from,
                "shear": min(onsets) if onsets else None,
            },
            "nyquist_rad_m": self.nyquist,
            "zone_edge_rad_m": self.zone_edge,
            "group_velocity_method": self.group_velocity_method,
            "branches": {name: b.to_dict() for name, b in self.branches.items()},
        }


# -- the relation ---------------------------------------------------------------------------


def dispersion_relation(
    model: str,
    medium: Medium,
    horizon: float,
    spacing: float,
    influence: str = "constant",
    dim: int = 3,
    direction="x",
    discrete: bool = False,
    partial_volumes: bool = True,
    wavenumbers=None,
    k_max: float | None = None,
    points: int = 400,
    plane: str = "stress",
) -> DispersionRelation:
    """omega(k), phase and group velocities of every branch.

    Parameters
    ----------
    model : str
        A registered material ("pmb", "lps", "linear_lps", ...): the class gives its
        linearisation (``Model.plane_wave_coefficients``).
    medium : Medium
    horizon : float, m
    spacing : float, m
        Grid spacing h: the lattice of the discrete relation, and the Nyquist
        wavenumber pi/h of both.
    influence : {"constant", "inverse", "gaussian", "conical"}
    dim : {1, 2, 3}
    direction : str or 3 floats
        See :func:`parse_direction`.
    discrete : bool
        Lattice sum (as the simulation) instead of the integral over the horizon.
    partial_volumes : bool
        Discrete only: weigh neighbours by the fraction of their cell inside the horizon.
    wavenumbers : (n_k,) array, rad/m, optional
        Where to evaluate (positive, increasing); default ``points`` values up to ``k_max``.
    k_max : float, rad/m, optional
        Default: the Brillouin-zone edge of the lattice along ``direction``.
    points : int
    plane : {"stress", "strain"}
        2D only.

    Returns
    -------
    DispersionRelation
    """
    _check_arguments(horizon, spacing, dim, points)
    d = parse_direction(direction, dim)
    zone_edge = float(np.pi / (spacing * np.max(np.abs(d))))
    k = None if wavenumbers is None else _wavenumbers(wavenumbers, k_max or zone_edge, points)
    n_k, largest = (int(points), k_max or zone_edge) if k is None else (len(k), k[-1])
    if np.isfinite(largest) and largest > 0:  # else _wavenumbers refuses it
        check_relation_fits(horizon, spacing, dim, n_k, bool(discrete), float(largest))
    k = _wavenumbers(wavenumbers, k_max or zone_edge, points) if k is None else k
    if discrete:
        family = lattice_family(spacing, horizon, influence, dim, partial_volumes)
    else:
        family = continuum_family(horizon, influence, dim, d, float(k.max()), thickness=spacing)
    lin = linear_model(model, family, medium, plane)
    basis = polarisations(d, dim)

    def eigen(kk: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        return branch_eigenvalues(*acoustic_tensor(lin, family, basis, kk))

    lam, slope = eigen(k)
    if np.any(lam < -1e-12 * np.max(np.abs(lam))):
        bad = np.flatnonzero(np.any(lam < 0, axis=1))[0]
        raise InputError(
            f"the linearised {model} of this medium is unstable: rho omega^2 < 0 at "
            f"k = {k[bad]:g} rad/m (check the elastic constants)"
        )
    k0 = np.array([_LONG_WAVE_K_DELTA / horizon])
    limits = np.sqrt(eigen(k0)[0][0] / medium.density) / k0[0]
    branches = {
        name: _branch(name, b, basis[b], k, lam[:, b], slope[:, b], limits[b], medium.density, eigen)
        for b, name in enumerate(BRANCHES[:dim])
    }
    return DispersionRelation(
        model,
        dim,
        d,
        bool(discrete),
        bool(partial_volumes and discrete),
        float(horizon),
        float(spacing),
        influence,
        float(np.pi / spacing),
        zone_edge,
        medium.as_modelled(model, dim, plane).classical_speeds(dim, plane),
        branches,
    )


def _branch(
    name: str,
    b: int,
    polarisation: np.ndarray,
    k: np.ndarray,
    lam: np.ndarray,
    slope: np.ndarray,
    limit: float,
    rho: float,
    eigen,
) -> Branch:
    """Branch ``b`` from its eigenvalues ``lam`` = rho omega^2 and slopes d lam / dk.

    ``eigen(k)`` recomputes (eigenvalues, slopes) at other wavenumbers, for the
    onset of negative group velocity: where ``d omega/dk = slope / (2 rho omega)``
    first falls below ``-_NEGATIVE_TOL`` times the long-wave speed (sampled,
    then refined by Brent's method).
    """
    omega = np.sqrt(np.maximum(lam, 0.0) / rho)
    group = slope / (2.0 * rho * np.where(omega > 0, omega, np.inf))
    tol = _NEGATIVE_TOL * limit
    negative = np.flatnonzero(group < -tol)
    onset = None
    if len(negative):
        i = int(negative[0])
        onset = float(k[i])
        if i > 0:

            def shifted_group(kk: float) -> float:
                lam_k, slope_k = eigen(np.array([kk]))
                return slope_k[0, b] / (2.0 * np.sqrt(rho * max(lam_k[0, b], 1e-300))) + tol

            # imported here: scipy.optimize costs a process 15 MB (an explicit run solves for no root)
            from scipy.optimize import brentq

            onset = float(brentq(shifted_group, k[i - 1], k[i], xtol=1e-10 * k[i]))
    return Branch(name, polarisation, k, omega, omega / k, group, float(limit), onset)


def relation_bytes(horizon: float, spacing: float, dim: int, n_k: int, discrete: bool, k_max: float) -> float:
    """Peak bytes of :func:`dispersion_relation` for ``n_k`` wavenumbers up to ``k_max`` (rad/m),
    estimated before anything is allocated: the acoustic tensor (``TENSOR_BYTES`` per wavenumber
    and family bond) and, for the lattice, the bond search of its block (``SEARCH_BYTES``)."""
    ball = (2.0, np.pi, 4.0 / 3.0 * np.pi)[dim - 1]
    if discrete:
        family = ball * (horizon / spacing + 0.5) ** dim
        reach = horizon / spacing + np.sqrt(dim) / 2.0 + 1.0
        block = ball * reach**dim if dim > 1 else 0.0  # 1D: the chain, no search
        search = SEARCH_BYTES * block * family
    else:
        nodes = np.ceil(k_max * horizon) + _EXTRA_NODES
        family, search = (2.0 * nodes, nodes**2, 4.0 * nodes**2)[dim - 1], 0.0
    return TENSOR_BYTES * float(n_k) * family + search


def check_relation_fits(horizon: float, spacing: float, dim: int, n_k: int, discrete: bool, k_max: float):
    """Refuse, before allocating, a relation whose arrays would not fit in memory
    (:func:`relation_bytes` against ``geometry.memory_limit``).

    Raises
    ------
    InputError
        Naming the wavenumbers, the family's bonds, the bytes needed and those available.
    """
    needed, available = relation_bytes(horizon, spacing, dim, n_k, discrete, k_max), geometry.memory_limit()
    if needed > available:
        raise InputError(
            f"the dispersion relation at {n_k:.3g} wavenumbers with a horizon of {horizon / spacing:.3g} "
            f"spacings needs about {needed / 1e9:.3g} GB, more than the {available / 1e9:.3g} GB of this "
            "machine: fewer points (--points), a smaller horizon or a larger spacing"
        )


def _check_arguments(horizon: float, spacing: float, dim: int, points: int) -> None:
    for name, value in (("horizon", horizon), ("spacing", spacing)):
        if not (np.isfinite(value) and value > 0):
            raise InputError(f"{name} must be positive and finite, got {value!r} m")
    if dim not in (1, 2, 3):
        raise InputError(f"dimension must be 1, 2 or 3, got {dim!r}")
    if int(points) != points or points < 2:
        raise InputError(f"points must be an integer of at least 2, got {points!r}")


def _wavenumbers(wavenumbers, k_max: float, points: int) -> np.ndarray:
    if wavenumbers is None:
        if not (np.isfinite(k_max) and k_max > 0):
            raise InputError(f"k_max must be positive and finite, got {k_max!r} rad/m")
        return np.linspace(k_max / points, k_max, int(points))
    k = np.asarray(wavenumbers, dtype=float).ravel()
    if k.size == 0 or not np.all(np.isfinite(k)) or np.any(k <= 0) or np.any(np.diff(k) <= 0):
        raise InputError("wavenumbers must be positive, finite and increasing (rad/m)")
    return k


# -- parameter studies (the dispersion study, figures 4-6 and 10-12) -------------------------------------

#: Influence functions of the dispersion study's study: constant, 1/|xi| and Gaussian.
SEED_INFLUENCES = ("constant", "inverse", "gaussian")
#: the dispersion study's horizons (m) at a 1 mm grid.
SEED_HORIZONS = (2e-3, 3e-3, 5e-3, 7e-3)
#: Grid spacings (m) of the mesh study at a 3 mm horizon (2 to 6 spacings per horizon).
SEED_SPACINGS = (0.5e-3, 0.75e-3, 1e-3, 1.5e-3)
#: Relative phase-velocity error that bounds the accurate band of a study's table.
BAND_TOLERANCE = 0.01


@dataclass(frozen=True)
class Study:
    """Dispersion relations over influence functions, horizons and grid spacings.

    Attributes
    ----------
    relations : dict of (influence, horizon m, spacing m) to DispersionRelation
    base_horizon, base_spacing : float, m
        The horizon of the spacing sweep and the spacing of the horizon sweep.
    """

    relations: dict
    base_horizon: float
    base_spacing: float

    @property
    def table(self) -> list[dict]:
        """One row per relation: parameters, long-wave limits and their errors against the
        classical speeds, the wavenumbers up to which the phase velocity stays within
        ``BAND_TOLERANCE`` of the classical speed, and the onsets of negative group
        velocity (None: none up to the zone edge)."""
        rows = []
        for (influence, horizon, spacing), rel in self.relations.items():
            onsets = rel.to_dict()["negative_group_velocity_from_rad_m"]
            row = {
                "influence": influence,
                "horizon_m": horizon,
                "spacing_m": spacing,
                "horizon_over_spacing": horizon / spacing,
            }
            studied = [("longitudinal", rel.branches["longitudinal"], rel.classical[0])]
            studied += [("shear", b, rel.classical[1]) for b in rel.shear_branches()[:1]]
            for prefix, branch, reference in studied:
                row[f"{prefix}_m_s"] = branch.long_wave_limit
                row[f"{prefix}_error"] = branch.long_wave_limit / reference - 1.0
                row[f"{prefix}_band_rad_m"] = branch.accuracy_band(reference, BAND_TOLERANCE)
            row["negative_longitudinal_rad_m"] = onsets["longitudinal"]
            row["negative_shear_rad_m"] = onsets["shear"]
            row["nyquist_rad_m"] = rel.nyquist
            rows.append(row)
        return rows

    def sweep(self, parameter: str) -> dict:
        """Relations of one figure of the dispersion study, labelled: ``"influence"`` (base
        horizon and spacing), ``"horizon"`` (base spacing) or ``"spacing"`` (base horizon), constant influence
        function first when several are present."""
        influences = list(dict.fromkeys(key[0] for key in self.relations))
        base = influences[0]
        chosen = {
            "influence": lambda i, d, h: d == self.base_horizon and h == self.base_spacing,
            "horizon": lambda i, d, h: i == base and h == self.base_spacing,
            "spacing": lambda i, d, h: i == base and d == self.base_horizon,
        }[parameter]
        label = {
            "influence": lambda i, d, h: i,
            "horizon": lambda i, d, h: f"delta = {d * 1e3:g} mm",
            "spacing": lambda i, d, h: f"h = {h * 1e3:g} mm",
        }[parameter]
        return {label(*key): rel for key, rel in self.relations.items() if chosen(*key)}

    def negative_group_velocity_summary(self) -> str:
        """Which choices give a negative group velocity below the grid's zone edge."""
        lines = []
        for row in self.table:
            hits = [
                f"{name} from {row[key]:.0f} rad/m ({row[key] * row['spacing_m']:.2f}/h)"
                for name, key in (("P", "negative_longitudinal_rad_m"), ("S", "negative_shear_rad_m"))
                if row[key] is not None
            ]
            lines.append(
                f"{row['influence']:>8}, delta {row['horizon_m'] * 1e3:g} mm, "
                f"h {row['spacing_m'] * 1e3:g} mm ({row['horizon_over_spacing']:.2f} h): "
                + ("; ".join(hits) if hits else "none")
            )
        return "\n".join(lines)


def study(
    model: str = "lps",
    medium: Medium = MARAGING_STEEL,
    influences=SEED_INFLUENCES,
    horizons=SEED_HORIZONS,
    spacings=SEED_SPACINGS,
    base_horizon: float = 3e-3,
    base_spacing: float = 1e-3,
    discrete: bool = True,
    partial_volumes: bool = True,
    dim: int = 3,
    direction="x",
    points: int = 400,
) -> Study:
    """Dispersion relations of the dispersion study's parameter study (maraging steel by default).

    For every influence function: the horizons ``horizons`` at ``base_spacing``
    and the spacings ``spacings`` at ``base_horizon``; each relation runs to the
    zone edge of its own grid. Other arguments as in :func:`dispersion_relation`.
    """
    keys = [(i, float(d), float(base_spacing)) for i in influences for d in horizons]
    keys += [(i, float(base_horizon), float(h)) for i in influences for h in spacings]
    relations = {
        key: dispersion_relation(
            model,
            medium,
            key[1],
            key[2],
            key[0],
            dim=dim,
            direction=direction,
            discrete=discrete,
            partial_volumes=partial_volumes,
            points=points,
        )
        for key in dict.fromkeys(keys)
    }
    return Study(relations, float(base_horizon), float(base_spacing))
