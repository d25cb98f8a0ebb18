"""PMB and LPS on lattice storage (``peridyn.discretization.lattice``): the same laws as
``materials.pmb`` and ``materials.lps``, their coefficients per stencil offset and per grid
point instead of per bond.

A lattice model keeps the displacement of the grid as a (3, n_grid) array: each force
scatters ``u`` (n_points, 3) to the grid and runs the lattice kernels
(``peridyn.kernels.lattice``), which write each grid row's force straight to the body's
points, so that solvers, loads and recorders see the body as with bond lists. It has no bond linearisation
(static, Newton, Newmark, modal runs and the stress output keep bond lists).

What lattice storage takes: one material, the surface corrections of
``LATTICE_SURFACE_CORRECTIONS`` (PMB none; LPS none and shear-factor), float64 and float32;
:func:`lattice_support` says why a case needs bond lists.
"""

from __future__ import annotations

import numpy as np

from peridyn.discretization.body import Body
from peridyn.discretization.lattice import Lattice
from peridyn.errors import InputError
from peridyn.kernels.lattice import (
    lattice_damage_index,
    lattice_energy_sum,
    lattice_lps_dilatation,
    lattice_lps_force,
    lattice_pair_sum,
    lattice_pmb_force,
    lattice_scatter,
    pair_offsets,
)
from peridyn.physics.materials.base import Model
from peridyn.physics.materials.elastic import dilatational_modulus, shear_modulus
from peridyn.physics.materials.lps import LPSModel, shear_correction_factor
from peridyn.physics.materials.pmb import PMBModel, pmb_micromodulus

#: Grid points a time of the LPS energy's last sum (bounds its temporary).
ENERGY_CHUNK = 1 << 20

#: Surface corrections lattice storage computes, per material (the others keep bond lists).
LATTICE_SURFACE_CORRECTIONS = {"pmb": ("none",), "lps": ("none", "shear-factor")}


class LatticeModel(Model):
    """A material law over a :class:`Lattice` (abstract; see the module docstring).

    Attributes beyond ``Model``'s: ``lattice`` (also ``bonds``: what damage, summaries and
    checkpoints read), ``storage`` = "lattice".
    """

    storage = "lattice"
    force_overwrites_out = True  # every body point has a grid point, whose row is written

    def __init__(self, body: Body, lattice: Lattice, E, density, dtype=np.float64):
        if np.ndim(E) or np.ndim(density):
            raise InputError("lattice storage takes one material: E and density must be numbers")
        self.body = body
        self.lattice = self.bonds = lattice
        self.E = float(E)
        self.dtype = np.dtype(dtype)
        self.x = np.ascontiguousarray(body.points, dtype=self.dtype)
        self.density = np.broadcast_to(float(density), (body.n_points,))  # one material: a view
        s = lattice.stencil
        self._cf = self.dtype == np.float32  # the cancellation-free extension in float32
        self._vol = lattice.volume.astype(self.dtype, copy=False)
        self._xi = s.xi.astype(self.dtype)
        self._length = s.length.astype(self.dtype)
        self._ug = np.zeros((3, lattice.n_grid), dtype=self.dtype)  # holes stay 0
        #: the stencil rows the pair kernels run (one of each two opposite offsets) and their slab width
        self._pairs = pair_offsets(s.offsets)
        #: the force kernels' sum of each grid point's pair forces (3, n_grid), N/m^3
        self._grid_f = np.empty((3, lattice.n_grid), dtype=self.dtype)
        #: (n_grid,) the body point of each grid point, -1 for none: where the force kernels write
        self._point_of = np.full(lattice.n_grid, -1, dtype=np.int32 if body.n_points < 2**31 else np.int64)
        self._point_of[lattice.grid_index] = np.arange(body.n_points, dtype=self._point_of.dtype)
        #: the float64 grid displacement of ``grid_displacement``: ``_ug`` itself in float64, else made once
        self._ug64 = self._ug if self.dtype == np.float64 else None
        self._linearisation = None
        self._bond_vectors = None

    def _scatter(self, u: np.ndarray) -> np.ndarray:
        """``u`` (n_points, 3) into the grid's (3, n_grid) displacement (kernel dtype)."""
        return lattice_scatter(np.ascontiguousarray(u), self.lattice.grid_index, self._ug)

    def _force_out(self, out: np.ndarray | None) -> np.ndarray:
        """Where a force goes: ``out`` (n_points, 3), or a new array of the kernel dtype."""
        return np.empty_like(self.x) if out is None else out

    def grid_displacement(self, u: np.ndarray) -> np.ndarray:
        """(3, n_grid) float64 displacement of the grid (energies, set-up sums, bond breaking):
        the model's own grid displacement in float64 (overwritten by the next call or force)."""
        if self._ug64 is None:
            self._ug64 = np.zeros((3, self.lattice.n_grid))  # holes stay 0
        return lattice_scatter(np.ascontiguousarray(u, dtype=np.float64), self.lattice.grid_index, self._ug64)

    def _at_points(self, grid_values: np.ndarray) -> np.ndarray:
        return grid_values[self.lattice.grid_index]

    def bond_vectors_once(self):
        raise InputError("lattice storage keeps no bond list: use discretization.storage: bonds")

    def linearisation(self):
        raise InputError(
            "lattice storage has no bond linearisation (static, Newton, Newmark and modal runs, "
            "the stress and strain outputs): use discretization.storage: bonds"
        )

    def damage_index(self) -> np.ndarray:
        """(n_points,) 1 - intact / total partial-volume-weighted neighbour volume of each family."""
        lat, s = self.lattice, self.lattice.stencil
        phi = np.empty(lat.n_points)
        args = (lat.volume, lat.broken, lat.shape, s.offsets, s.volume_factor)
        return lattice_damage_index(*args, self._point_of, phi)

    def _offset_table(self, values) -> np.ndarray:
        return np.ascontiguousarray(values, dtype=self.dtype)


class LatticePMB(LatticeModel):
    """PMB (``materials.pmb``) on a lattice: bond stiffness c0 omega beta V_j per offset."""

    name = "pmb"
    implied_poisson_ratio = PMBModel.implied_poisson_ratio
    critical_stretch = PMBModel.critical_stretch

    def __init__(self, body, lattice, E, density, nu=None, surface_correction="none", dtype=np.float64):
        PMBModel.check_parameters(E=E, density=density, nu=nu, surface_correction=surface_correction)
        PMBModel.check_nu(nu, body.dim, body.plane)
        check_lattice_correction("pmb", surface_correction)
        super().__init__(body, lattice, E, density, dtype)
        s = lattice.stencil
        self.c0 = pmb_micromodulus(
            E, body.dim, lattice.horizon, lattice.influence_name, body.plane, body.thickness
        )
        self._coef64 = self.c0 * s.influence * s.volume_factor
        self._coef = self._offset_table(self._coef64)
        self._inv_len = self._offset_table(1.0 / s.length)

    def force(self, u, out=None):
        lat = self.lattice
        ug = self._scatter(self._as_state(u))
        s = lat.stencil
        return lattice_pmb_force(
            ug,
            self._vol,
            lat.broken,
            lat.shape,
            s.offsets,
            *self._pairs,
            self._xi,
            self._length,
            self._inv_len,
            self._coef,
            self._cf,
            self._grid_f,
            self._point_of,
            self._force_out(out),
        )

    def energy_density(self, u):
        lat, s = self.lattice, self.lattice.stencil
        w = lattice_energy_sum(
            self.grid_displacement(u), lat.volume, lat.broken, lat.shape, s.offsets, s.xi, s.length,
            0.25 * self._coef64, np.zeros(lat.n_grid), 1.0, np.empty(lat.n_grid),
        )  # fmt: skip
        return self._at_points(w)

    def stiffness_bound(self):
        return self._at_points(2.0 * self.lattice.bond_sum(self._coef64 / self.lattice.stencil.length))


class LatticeLPS(LatticeModel):
    """LPS (``materials.lps``, no surface correction) on a lattice: w = omega beta V_j per
    offset, alpha, theta and P per grid point (the weighted volume m only while set up)."""

    name = "lps"
    critical_stretch = LPSModel.critical_stretch

    def __init__(self, body, lattice, E, density, nu=None, surface_correction="none", dtype=np.float64):
        LPSModel.check_parameters(E=E, density=density, nu=nu, surface_correction=surface_correction)
        check_lattice_correction("lps", surface_correction)
        super().__init__(body, lattice, E, density, dtype)
        dim = body.dim
        s = lattice.stencil
        self.dim, self.nu = dim, float(nu)
        self.shear = shear_modulus(E, nu)
        self.bulk = dilatational_modulus(E, nu, dim, body.plane)
        self._weight64 = s.influence * s.volume_factor
        m = lattice.bond_sum(self._weight64 * s.length**2)
        occupied = lattice.volume > 0
        if np.any(m[lattice.grid_index] <= 0):
            lonely = int(np.flatnonzero(m[lattice.grid_index] <= 0)[0])
            raise InputError(f"point {lonely} has no intact bond: its weighted volume is zero")
        safe = np.where(occupied, m, 1.0)
        self.alpha = np.where(occupied, (15.0 if dim == 3 else 8.0) * self.shear / safe, 0.0)
        self.theta_coef = np.where(occupied, dim / safe, 0.0)
        self.shear_factor = np.broadcast_to(1.0, (body.n_points,))  # read-only: one value
        if surface_correction == "shear-factor":
            self.shear_factor = self._shear_correction_factor(m)
            self.alpha[lattice.grid_index] *= self.shear_factor
        self.p_coef = np.where(occupied, dim * self.bulk / safe - self.alpha / dim, 0.0)
        self._weight = self._offset_table(self._weight64)
        self._alpha = self.alpha.astype(self.dtype, copy=False)
        self._theta_coef = self.theta_coef.astype(self.dtype, copy=False)
        self._p_coef = self.p_coef.astype(self.dtype, copy=False)
        #: the grid's dilatation, then in place P = p_coef theta (``force``)
        self._theta = np.zeros(lattice.n_grid, dtype=self.dtype)

    def _shear_correction_factor(self, m: np.ndarray) -> np.ndarray:
        """``materials.lps.shear_correction_factor`` over the lattice's bonds (float64); ``m``
        (n_grid,) the weighted volume."""
        lat, s = self.lattice, self.lattice.stencil
        table = (lat.volume, lat.broken, lat.shape, s.offsets, s.xi, s.length)

        def dilatation(u):
            ug = self.grid_displacement(u)
            head, tail = table[:4], table[4:]
            theta = lattice_lps_dilatation(
                ug, *head, *self._pairs, *tail, self._weight64, False, self.theta_coef, np.empty(lat.n_grid)
            )
            return self._at_points(theta)

        def deviatoric_norm(u, theta):
            grid_theta = np.zeros(lat.n_grid)
            grid_theta[lat.grid_index] = theta
            coef = self._weight64 * s.length
            norm = lattice_energy_sum(
                self.grid_displacement(u), *table, coef, grid_theta, float(self.dim), np.empty(lat.n_grid)
            )
            return self._at_points(norm)

        m = self._at_points(m)
        return shear_correction_factor(self.body.points, self.dim, m, dilatation, deviatoric_norm)

    def _grid_dilatation(self, ug, vol, theta_coef, out):
        lat, s = self.lattice, self.lattice.stencil
        args = (s.offsets, self._xi, self._length, self._weight, self._cf)
        if ug.dtype == np.float64 and self.dtype != np.float64:
            args = (s.offsets, s.xi, s.length, self._weight64, False)
        return lattice_lps_dilatation(
            ug, vol, lat.broken, lat.shape, s.offsets, *self._pairs, *args[1:], theta_coef, out
        )

    def dilatation(self, u) -> np.ndarray:
        """Dilatation theta (n_points,), dimensionless."""
        ug = self._scatter(self._as_state(u))
        return self._at_points(self._grid_dilatation(ug, self._vol, self._theta_coef, self._theta)).copy()

    def force(self, u, out=None):
        lat, s = self.lattice, self.lattice.stencil
        ug = self._scatter(self._as_state(u))
        p = self._grid_dilatation(ug, self._vol, self._theta_coef, self._theta)
        np.multiply(p, self._p_coef, out=p)
        args = (s.offsets, *self._pairs, self._xi, self._length, self._weight, self._cf, self._alpha, p)
        f = self._force_out(out)
        return lattice_lps_force(ug, self._vol, lat.broken, lat.shape, *args, self._grid_f, self._point_of, f)

    def energy_density(self, u):
        """0.5 K theta^2 + 0.5 alpha sum w (e - theta |xi| / d)^2 (n_points,), J/m^3, at ``u``
        (float64), with no temporary of the grid's size beyond the deviatoric sums (which hold the
        result: a view of them)."""
        lat, s = self.lattice, self.lattice.stencil
        ug = self.grid_displacement(u)
        scratch = self._theta if self.dtype == np.float64 else np.empty(lat.n_grid)
        theta = lattice_lps_dilatation(
            ug, lat.volume, lat.broken, lat.shape, s.offsets, *self._pairs, s.xi, s.length, self._weight64,
            False, self.theta_coef, scratch,
        )  # fmt: skip
        squares = lattice_energy_sum(
            ug, lat.volume, lat.broken, lat.shape, s.offsets, s.xi, s.length, self._weight64 * s.length,
            theta, float(self.dim), np.empty(lat.n_grid),
        )  # fmt: skip
        np.multiply(theta, theta, out=theta)
        theta *= 0.5 * self.bulk
        for start in range(0, lat.n_grid, ENERGY_CHUNK):  # theta += (0.5 alpha) squares
            part = slice(start, start + ENERGY_CHUNK)
            half_alpha = 0.5 * self.alpha[part]
            theta[part] += np.multiply(half_alpha, squares[part], out=half_alpha)
        return np.take(theta, lat.grid_index, out=squares[: lat.n_points])  # the sums' room reused

    def stiffness_bound(self):
        """The block-Gershgorin bound of ``LPSModel.stiffness_bound`` over the lattice's bonds."""
        lat, s = self.lattice, self.lattice.stencil
        w = self._weight64
        spread = self.theta_coef * lat.bond_sum(w * s.length)
        zero = np.zeros(lat.n_grid)
        pairs = lattice_pair_sum(
            lat.volume,
            lat.broken,
            lat.shape,
            s.offsets,
            2.0 * w,
            self.alpha,
            self.alpha,
            np.empty(lat.n_grid),
        )
        dilatation = lattice_pair_sum(
            lat.volume, lat.broken, lat.shape, s.offsets, 2.0 * w * s.length, zero,
            self.bulk * self.theta_coef * spread, np.empty(lat.n_grid),
        )  # fmt: skip
        return self._at_points(pairs + dilatation + 2.0 * self.bulk * spread * spread)


#: Material name -> its lattice class.
LATTICE_MODELS = {"pmb": LatticePMB, "lps": LatticeLPS}


def check_lattice_correction(name: str, surface_correction: str) -> None:
    """Refuse a surface correction of material ``name`` that lattice storage does not compute."""
    if surface_correction not in LATTICE_SURFACE_CORRECTIONS[name]:
        raise InputError(
            f"surface_correction {surface_correction!r} needs bond lists: lattice storage computes "
            f"{list(LATTICE_SURFACE_CORRECTIONS[name])} for {name}; use discretization.storage: bonds"
        )


def lattice_support(name: str, surface_correction: str = "none") -> str | None:
    """Why material ``name`` with ``surface_correction`` cannot run on lattice storage, or None."""
    if name not in LATTICE_MODELS:
        return f"material {name!r} has no lattice form (lattice storage runs {sorted(LATTICE_MODELS)})"
    if surface_correction not in LATTICE_SURFACE_CORRECTIONS[name]:
        return f"surface_correction {surface_correction!r} of {name} needs bond lists"
    return None


def make_lattice_model(
    name: str,
    body: Body,
    lattice: Lattice,
    *,
    E,
    density,
    nu=None,
    surface_correction="none",
    dtype=np.float64,
) -> LatticeModel:
    """Bind material ``name`` ("pmb" or "lps") to a body and its lattice (see ``make_model``)."""
    why = lattice_support(name, surface_correction)
    if why is not None:
        raise InputError(f"lattice storage: {why}; use discretization.storage: bonds")
    cls = LATTICE_MODELS[name]
    return cls(body, lattice, E=E, density=density, nu=nu, surface_correction=surface_correction, dtype=dtype)
