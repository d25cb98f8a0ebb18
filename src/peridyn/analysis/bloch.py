"""Bloch-wave dispersion of the discrete peridynamic model, exactly as the solver builds it.

A periodic cell (one lattice point of a block; one column of all the layers of a
plate, periodic in x and y, free at the faces) is tiled often enough that every
point of the central tile has its whole family. The solver's own body, bonds and
material model are built on the tiles, and ``stiffness.assemble_stiffness`` gives
the Hessian ``K_c`` of the energy of the central tile's points only (so the LPS
dilatation coupling of neighbours of neighbours comes from the energy, not from
copied forces). For a Bloch field ``u_i = U_{c(i)} exp(i k . x_i)``, ``c(i)`` the cell
point of tiled point ``i``, the energy per cell is ``U^H D(k) U / 2`` with the
Hermitian dynamical matrix (3 m, 3 m), N/m,

    D_ab(k) = sum_{c(i) = a, c(j) = b} K_c[i, j] exp(i k . (x_j - x_i)),

and the branches are ``D(k) U = omega^2 M U``, ``M = rho V`` (lumped mass, kg).

Plates: straight-crested waves along x (k_y = 0). The mid-plane mirror
(z -> -z, u_z -> -u_z) and the y mirror (u_y -> -u_y) leave D invariant, so D
splits into symmetric (S: u_x even, u_z odd), antisymmetric (A: u_x odd, u_z even)
and shear-horizontal (SH: u_y, even for SH0) blocks.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.optimize import brentq

from peridyn.discretization import geometry
from peridyn.discretization.bonds import find_bonds
from peridyn.errors import InputError
from peridyn.linalg.stiffness import assemble_stiffness
from peridyn.physics.materials import make_model

#: Plate subspaces: (name, parity of u_x, u_y, u_z under the mid-plane mirror; None: absent).
PLATE_FAMILIES = {"S": (1, None, -1), "A": (-1, None, 1), "SH": (None, 1, None)}

#: Wavenumbers sampled per branch when bracketing a root (up to the zone edge).
_SCAN_POINTS = 64


@dataclass(frozen=True)
class BlochLattice:
    """What the Bloch cell needs of a case: grid, horizon, material.

    spacing : in-plane grid spacing dx = dy, m
    horizon : m
    kind : "block" (simple cubic lattice) or "plate" (layers through ``thickness``)
    thickness, layers, layer_placement : plate only (see ``geometry.plate``)
    model, E, nu, density, surface_correction : as ``materials.make_model`` (Pa, kg/m^3)
    """

    spacing: float
    horizon: float
    model: str
    E: float
    nu: float | None
    density: float
    kind: str = "block"
    influence: str = "constant"
    partial_volumes: bool = True
    surface_correction: str = "none"
    thickness: float | None = None
    layers: int | None = None
    layer_placement: str = "cell"

    @classmethod
    def from_case(cls, case) -> BlochLattice:
        """The discretisation of a validated ``io.case.Case`` (``box`` or ``plate`` geometry)."""
        g, d, mat = case.geometry, case.discretization, case.material
        if mat is None:
            raise InputError(f"Bloch analysis needs a body of one material, got blocks {sorted(case.blocks)}")
        if g.type not in ("box", "plate"):
            raise InputError(f"Bloch analysis needs a box or plate case, got geometry.type {g.type!r}")
        spacing = np.atleast_1d(np.asarray(d.spacing if d.spacing is not None else [], float))
        if spacing.size == 0 or np.ptp(spacing) > 1e-12 * spacing.max():
            raise InputError(
                f"Bloch analysis needs one grid spacing (a cubic lattice), got "
                f"discretization.spacing = {d.spacing!r}"
            )
        horizon = d.horizon_metres(float(spacing[0]))
        plate = g.type == "plate"
        return cls(
            spacing=float(spacing[0]),
            horizon=float(horizon),
            model=mat.model,
            E=mat.E,
            nu=mat.nu,
            density=mat.density,
            kind=g.type if plate else "block",
            influence=d.influence,
            partial_volumes=bool(d.partial_volumes),
            surface_correction=mat.surface_correction,
            thickness=float(g.size[2]) if plate else None,
            layers=int(g.layers) if plate else None,
            layer_placement=g.layer_placement if plate else "cell",
        )


@dataclass(frozen=True)
class BlochCell:
    """The dynamical matrix of a periodic cell as a sum over (cell dof pair, shift) terms.

    Attributes
    ----------
    points : (m, 3) float64, m
        Positions of the cell points (central tile).
    mass : (m,) float64, kg
        Lumped mass rho V of each cell point.
    rows, cols : (n_terms,) int64
        Cell dofs (3 a + component) of each term.
    values : (n_terms,) float64, N/m
        Summed stiffness entries of the term.
    shifts : (n_terms, 3) float64, m
        x_j - x_i of the term (the Bloch phase is exp(i k . shift)).
    bonds_per_point : float
        Mean family size of the cell points.
    critical_time_step : float, s
        The solver's stable step bound of the cell points (``Model.critical_time_step``).
    """

    points: np.ndarray
    mass: np.ndarray
    rows: np.ndarray
    cols: np.ndarray
    values: np.ndarray
    shifts: np.ndarray
    bonds_per_point: float
    critical_time_step: float

    @property
    def n_dofs(self) -> int:
        return 3 * len(self.points)

    def dynamical_matrix(self, k) -> np.ndarray:
        """D(k) (3 m, 3 m) complex Hermitian, N/m, for the wave vector ``k`` (3,) rad/m."""
        phase = np.exp(1j * (self.shifts @ np.asarray(k, dtype=np.float64)))
        n = self.n_dofs
        flat = np.bincount(
            self.rows * n + self.cols, weights=(self.values * phase).real, minlength=n * n
        ) + 1j * np.bincount(self.rows * n + self.cols, weights=(self.values * phase).imag, minlength=n * n)
        return flat.reshape(n, n)

    def mass_normalised(self, k) -> np.ndarray:
        """H(k) = M^-1/2 D(k) M^-1/2 (3 m, 3 m), 1/s^2: its eigenvalues are omega^2."""
        s = 1.0 / np.sqrt(np.repeat(self.mass, 3))
        return s[:, None] * self.dynamical_matrix(k) * s[None, :]

    def frequencies(self, k, basis: np.ndarray | None = None) -> np.ndarray:
        """Angular frequencies omega (rad/s) of all branches at ``k``, ascending.

        ``basis`` ((3 m, r) orthonormal): restrict to an invariant subspace (plate families).
        """
        h = self.mass_normalised(k)
        if basis is not None:
            h = basis.T @ h @ basis
        lam = np.linalg.eigvalsh(0.5 * (h + h.conj().T))
        return np.sqrt(np.clip(lam, 0.0, None))

    def dynamical_matrix_derivative(self, k, direction) -> np.ndarray:
        """dD/dk along the unit vector ``direction`` at ``k`` (3 m, 3 m) complex, N rad^-1."""
        n = np.asarray(direction, dtype=np.float64)
        n = n / np.linalg.norm(n)
        weights = (
            1j
            * (self.shifts @ n)
            * self.values
            * np.exp(1j * (self.shifts @ np.asarray(k, dtype=np.float64)))
        )
        idx = self.rows * self.n_dofs + self.cols
        size = self.n_dofs**2
        flat = np.bincount(idx, weights=weights.real, minlength=size) + 1j * np.bincount(
            idx, weights=weights.imag, minlength=size
        )
        return flat.reshape(self.n_dofs, self.n_dofs)

    def branches(self, k, direction=(1.0, 0.0, 0.0), basis: np.ndarray | None = None):
        """(omega (rad/s), group velocity (m/s)) of all branches at ``k`` (3,), ascending.

        Group velocity d omega / dk along ``direction`` by the Hellmann-Feynman theorem:
        2 omega d omega = v^H (dH/dk) v for the unit eigenvector v of H = M^-1/2 D M^-1/2
        (exact for simple eigenvalues; a degenerate pair gets the pair's mean).
        """
        s = 1.0 / np.sqrt(np.repeat(self.mass, 3))
        h = s[:, None] * self.dynamical_matrix(k) * s[None, :]
        dh = s[:, None] * self.dynamical_matrix_derivative(k, direction) * s[None, :]
        if basis is not None:
            h, dh = basis.T @ h @ basis, basis.T @ dh @ basis
        lam, vec = np.linalg.eigh(0.5 * (h + h.conj().T))
        omega = np.sqrt(np.clip(lam, 0.0, None))
        slope = np.einsum("ib,ij,jb->b", vec.conj(), dh, vec).real
        with np.errstate(divide="ignore", invalid="ignore"):
            group = np.where(omega > 0, slope / (2.0 * omega), 0.0)
        return omega, group

    def long_wave_tensor(self, direction) -> np.ndarray:
        """(3, 3) N/m: -sum_terms K (n . shift)^2 / 2; omega^2 = k^2 eig / mass (one-point cells).

        The k^2 coefficient of D(k) along the unit vector ``direction`` (the k^0 and k^1
        terms vanish for a centro-symmetric one-point lattice).
        """
        if len(self.points) != 1:
            raise InputError("long_wave_tensor needs a one-point cell (a block lattice)")
        n = np.asarray(direction, dtype=np.float64)
        n = n / np.linalg.norm(n)
        weights = -0.5 * self.values * (self.shifts @ n) ** 2
        return np.bincount(self.rows * 3 + self.cols, weights=weights, minlength=9).reshape(3, 3)

    def long_wave_speeds(self, direction) -> np.ndarray:
        """(3,) m/s: the long-wave phase speeds along ``direction``, ascending (one-point cells)."""
        lam = np.linalg.eigvalsh(self.long_wave_tensor(direction))
        return np.sqrt(np.clip(lam, 0.0, None) / self.mass[0])


def _tiles(disc: BlochLattice) -> int:
    """Tiles on each side of the central one so that its points' families are complete."""
    reach = disc.horizon * (1 + 1e-9)
    if disc.partial_volumes:
        reach += 0.5 * disc.spacing * math.sqrt(3.0)
    return int(math.ceil(reach / disc.spacing))


def tiled_model(disc: BlochLattice, repeat: int = 1):
    """The solver's model on enough tiles around a central row of ``repeat`` cells along x.

    Returns (model, central, cell_index): ``central`` ((n,) bool) marks the points of the
    ``repeat`` central cells; ``cell_index`` ((n,) int64) numbers every tiled point by its
    image in a periodic supercell of ``repeat`` cells (layer + layers * (x tile mod repeat)
    for plates, x tile mod repeat for blocks).
    """
    _check(disc)
    t = _tiles(disc)
    n = 2 * t + 1
    h = disc.spacing
    if disc.kind == "plate":
        body = geometry.plate(
            (n + repeat - 1) * h, n * h, disc.thickness, h, disc.layers, layer_placement=disc.layer_placement
        )
        per_cell = disc.layers
        layer = body.layer_index
        tile = np.rint(body.points[:, :2] / h - 0.5).astype(np.int64)
    else:
        body = geometry.box(((n + repeat - 1) * h, n * h, n * h), h)
        per_cell = 1
        layer = np.zeros(body.n_points, dtype=np.int64)
        tile = np.rint(body.points / h - 0.5).astype(np.int64)
    central = (tile[:, 0] >= t) & (tile[:, 0] < t + repeat) & np.all(tile[:, 1:] == t, axis=1)
    cell_index = layer + per_cell * np.mod(tile[:, 0] - t, repeat)
    bonds = find_bonds(body, disc.horizon, disc.influence, disc.partial_volumes)
    model = make_model(
        disc.model,
        body,
        bonds,
        E=disc.E,
        nu=disc.nu,
        density=disc.density,
        surface_correction=disc.surface_correction,
    )
    return model, central, cell_index


#: Peak bytes per bond of the tiled model that ``bloch_cell`` builds (the bond search, the
#: model and the stiffness assembly): 68-110 B measured with ``tracemalloc`` for horizons of 3
#: and 4 spacings (block and 4-layer plate), taken with the family sizes of ``cell_bytes``.
CELL_BOND_BYTES = 100.0


def cell_bytes(disc: BlochLattice) -> float:
    """Peak bytes of ``bloch_cell(disc)``, estimated before anything is built: the tiled
    model's points times the family of a point (the horizon's ball in spacings, a plate's
    through its layers) times ``CELL_BOND_BYTES``."""
    t = _tiles(disc)
    n, reach = 2 * t + 1, disc.horizon / disc.spacing + 0.5
    if disc.kind == "plate":
        layers = float(disc.layers or 1)
        points, family = n * n * layers, math.pi * reach**2 * min(layers, 2.0 * reach)
    else:
        points, family = float(n) ** 3, 4.0 / 3.0 * math.pi * reach**3
    return CELL_BOND_BYTES * points * family


def check_cell_fits(disc: BlochLattice) -> None:
    """Refuse, before building it, a periodic cell whose tiled model would not fit in memory
    (:func:`cell_bytes` against ``geometry.memory_limit``).

    Raises
    ------
    InputError
        Naming the horizon in spacings, the bytes needed and those available.
    """
    needed, available = cell_bytes(disc), geometry.memory_limit()
    if needed > available:
        raise InputError(
            f"the Bloch cell of a horizon of {disc.horizon / disc.spacing:.3g} spacings needs its tiled "
            f"model, about {needed / 1e9:.3g} GB, more than the {available / 1e9:.3g} GB of this "
            "machine: a smaller horizon (in spacings)"
        )


def bloch_cell(disc: BlochLattice) -> BlochCell:
    """The periodic cell of ``disc`` built with the solver's own model (module docstring);
    refused first when it would not fit in memory (``check_cell_fits``)."""
    _check(disc)
    check_cell_fits(disc)
    model, central, cell_index = tiled_model(disc)
    k_c = assemble_stiffness(model, energy_of=central).tocoo()
    x = model.body.points
    i, j = k_c.row // 3, k_c.col // 3
    rows = 3 * cell_index[i] + k_c.row % 3
    cols = 3 * cell_index[j] + k_c.col % 3
    shifts = x[j] - x[i]
    # merge terms with the same dofs and shift (shifts are multiples of the spacing in x, y)
    quantum = 1e-6 * disc.spacing
    key = np.column_stack([rows, cols, np.rint(shifts / quantum).astype(np.int64)])
    unique, inverse = np.unique(key, axis=0, return_inverse=True)
    values = np.bincount(inverse.ravel(), weights=k_c.data, minlength=len(unique))
    keep = values != 0.0
    order = np.argsort(cell_index[central], kind="stable")
    points = x[central][order]
    density = np.broadcast_to(model.density, (model.body.n_points,))
    mass = (density * model.body.volumes)[central][order]
    return BlochCell(
        points=points,
        mass=mass,
        rows=unique[keep, 0],
        cols=unique[keep, 1],
        values=values[keep],
        shifts=unique[keep, 2:] * quantum,
        bonds_per_point=float(np.mean(np.diff(model.bonds.offsets)[central])),
        critical_time_step=model.critical_time_step(points=central),
    )


def _check(disc: BlochLattice) -> None:
    if not (disc.spacing > 0 and disc.horizon > 0):
        raise InputError(
            f"spacing and horizon must be positive, got {disc.spacing!r} m and {disc.horizon!r} m"
        )
    if disc.kind not in ("block", "plate"):
        raise InputError(f"kind must be 'block' or 'plate', got {disc.kind!r}")
    if disc.kind == "plate" and not (disc.thickness and disc.layers):
        raise InputError("a plate needs its thickness and number of layers")


# -- plates --------------------------------------------------------------------------------


def plate_basis(cell: BlochCell, family: str, parity: int = 1) -> np.ndarray:
    """Orthonormal basis (3 m, r) of a plate family's dofs under the mid-plane mirror.

    ``family``: "S", "A" or "SH"; for "SH", ``parity`` +1 (SH0, SH2, ...) or -1.
    """
    if family not in PLATE_FAMILIES:
        raise InputError(f"plate family must be one of {sorted(PLATE_FAMILIES)}, got {family!r}")
    z = cell.points[:, 2]
    mirror = np.array([int(np.argmin(np.abs(z - (z.min() + z.max() - zz)))) for zz in z])
    parities = list(PLATE_FAMILIES[family])
    if family == "SH":
        parities[1] = parity
    vectors = []
    for comp, sign in enumerate(parities):
        if sign is None:
            continue
        for a, b in enumerate(mirror):
            if b < a or (a == b and sign < 0):
                continue
            v = np.zeros(cell.n_dofs)
            v[3 * a + comp] += 1.0
            v[3 * b + comp] += sign
            vectors.append(v / np.linalg.norm(v))
    return np.array(vectors).T


def zone_edge(cell: BlochCell) -> float:
    """pi / dx, rad/m: the Brillouin-zone edge along x of the cell's lattice."""
    dx = np.min(np.abs(cell.shifts[:, 0])[np.abs(cell.shifts[:, 0]) > 0])
    return float(np.pi / dx)


def branch_wavenumber(
    cell: BlochCell, omega: float, basis: np.ndarray | None = None, branch: int = 0
) -> float | None:
    """Smallest k (rad/m, along x) where branch ``branch`` of the subspace reaches ``omega`` (rad/s).

    Brackets by a scan up to the zone edge, refines by Brent's method (1e-12 relative);
    None if the branch stays below ``omega``.
    """
    k_edge = zone_edge(cell)

    def f(k):
        return cell.frequencies((k, 0.0, 0.0), basis)[branch] - omega

    grid = np.linspace(0.0, k_edge, _SCAN_POINTS + 1)[1:]
    lo, f_lo = 0.0, f(0.0)
    for k in grid:
        f_k = f(k)
        if f_lo < 0 <= f_k:
            return float(brentq(f, lo, k, xtol=1e-12 * k, rtol=1e-12))
        lo, f_lo = k, f_k
    return None


def negative_group_velocity_from(
    cell: BlochCell, basis: np.ndarray | None = None, branch: int = 0, points: int = 400
) -> float | None:
    """First wavenumber (rad/m, along x, sampled on ``points`` up to the zone edge) where
    branch ``branch`` of the subspace has a negative group velocity; None if it never has."""
    for k in np.linspace(0.0, zone_edge(cell), points + 1)[1:]:
        if cell.branches((k, 0.0, 0.0), basis=basis)[1][branch] < 0:
            return float(k)
    return None


def plate_wavenumbers(cell: BlochCell, frequencies) -> list[dict]:
    """Discrete wavenumbers of S0, A0 and SH0 at each frequency (Hz): dicts with mode,
    frequency_hz and wavenumber_rad_m (None above the zone edge)."""
    bases = {"S0": plate_basis(cell, "S"), "A0": plate_basis(cell, "A"), "SH0": plate_basis(cell, "SH", 1)}
    return _mode_wavenumbers(cell, frequencies, bases)


def block_wavenumbers(cell: BlochCell, frequencies) -> list[dict]:
    """Discrete wavenumbers along x of the P (u_x) and S (u_y) bulk waves at each frequency (Hz)."""
    bases = {"P": np.eye(3)[:, [0]], "S": np.eye(3)[:, [1]]}
    return _mode_wavenumbers(cell, frequencies, bases)


def _mode_wavenumbers(cell: BlochCell, frequencies, bases: dict) -> list[dict]:
    """For each frequency (Hz) and each named polarisation basis, the branch's wavenumber."""
    out = []
    for f in np.atleast_1d(np.asarray(frequencies, dtype=np.float64)):
        for mode, basis in bases.items():
            out.append(
                {
                    "mode": mode,
                    "frequency_hz": float(f),
                    "wavenumber_rad_m": branch_wavenumber(cell, 2 * np.pi * f, basis),
                }
            )
    return out
