"""Bond-based prototype microelastic brittle (PMB) material.

The micromodulus c(xi) = c0 omega(|xi|) is chosen so that the peridynamic
strain energy of an isotropic expansion equals the classical one in the
bulk (Silling and Askari 2005):

- 3D: c0 = 18 K / I,  I = int_0^delta omega(r) 4 pi r^3 dr  (constant omega: 18 K / (pi delta^4));
- 2D: c0 = 8 kappa / (t J),  J = int_0^delta omega(r) 2 pi r^2 dr  (constant omega,
  plane stress: 9 E / (pi t delta^3)).

A bond-based model has a fixed Poisson ratio: 1/4 in 3D and plane strain,
1/3 in plane stress. K (kappa) is taken from E with that ratio, so that the
Young's modulus is right; a different ``nu`` given by the user is refused (InputError).

Surface correction ``"energy"`` (Madenci and Oterkus 2014, sec. 4.2): for each
axis a, a uniform uniaxial strain along a gives each point a strain energy
density W_i; its factor g_a,i = W_bulk / W_i (W_bulk the continuum value).
A bond's stiffness is scaled by the ellipsoidal mean
G = (sum_a (n_a / g_a)^2)^(-1/2) of the two end points' averaged factors.
"""

from __future__ import annotations

import numba
import numpy as np

from peridyn.discretization.body import Body
from peridyn.discretization.bonds import Bonds
from peridyn.discretization.pairs import block_split, half_list, index_bandwidth, row_blocks
from peridyn.kernels.pmb import pmb_energy, pmb_force, pmb_force_cf, pmb_pair_force
from peridyn.physics.materials.base import Model
from peridyn.physics.materials.elastic import (
    bulk_modulus,
    mean_fourth_power,
    plane_bulk_modulus,
    radial_moment,
    radial_moments,
)
from peridyn.physics.materials.linearisation import BondLinearisation
from peridyn.physics.materials.registry import register_material

SURFACE_CORRECTIONS = ("none", "energy")


def pmb_poisson_ratio(dim: int, plane: str | None) -> float:
    """The Poisson ratio a bond-based model implies: 1/3 in plane stress, else 1/4."""
    return 1.0 / 3.0 if (dim == 2 and plane == "stress") else 0.25


def pmb_micromodulus(
    E: float,
    dim: int,
    horizon: float,
    influence: str,
    plane: str | None = None,
    thickness: float | None = None,
) -> float:
    """c0 of c(xi) = c0 omega(|xi|), N/m^6 (3D) — see the module docstring. E (Pa) and the
    horizon (m) may be (n_points,) arrays (a body of several blocks), giving c0 per point."""
    nu = pmb_poisson_ratio(dim, plane)
    if dim == 3:
        return 18.0 * bulk_modulus(E, nu) / (4.0 * np.pi * radial_moments(influence, horizon, 3))
    kappa = plane_bulk_modulus(E, nu, plane)
    return 8.0 * kappa / (thickness * 2.0 * np.pi * radial_moments(influence, horizon, 2))


def bond_micromodulus(c0, bonds: Bonds):
    """c0 of each bond, N/m^6 (3D): ``c0`` itself if one number, else the mean of its two end
    points' c0 (``c0`` (n_points,), a body of several blocks), an (n_bonds,) array.

    The mean is the bond-based rule of docs/blocks.md: each end point's energy holds its half
    of the bond energy with its own micromodulus, c0_i s^2 |xi| / 4 (per unit volume squared),
    so the bond's force, the derivative of the sum, carries (c0_i + c0_j) / 2; it is what
    Peridigm gives when each block's material applies half of the bond force to both ends.
    A bond within one block keeps that block's c0 exactly ((c + c) / 2 = c in floating point).
    """
    if np.ndim(c0) == 0:
        return c0
    return 0.5 * (c0[bonds.owners()] + c0[bonds.neighbours])


@register_material("pmb")
class PMBModel(Model):
    """PMB material bound to a body and its bonds.

    Parameters
    ----------
    body, bonds : Body, Bonds
    E : float or (n_points,), Pa
    density : float or (n_points,), kg/m^3
    nu : float, (n_points,) or None
        Only checked against the model's implied Poisson ratio.

    Per-point E and density describe a body of several blocks: each bond's micromodulus is
    then the mean of its ends' (``bond_micromodulus``, docs/blocks.md).
    surface_correction : {"none", "energy"}
    dtype : float64 or float32
    """

    def __init__(
        self,
        body: Body,
        bonds: Bonds,
        E: float,
        density: float,
        nu: float | None = None,
        surface_correction: str = "none",
        dtype=np.float64,
    ):
        self.check_parameters(E=E, density=density, nu=nu, surface_correction=surface_correction)
        self.check_nu(nu, body.dim, body.plane)
        super().__init__(body, bonds, E=E, density=density, dtype=dtype)
        self.c0 = pmb_micromodulus(
            E, body.dim, bonds.horizons(), bonds.influence_name, body.plane, body.thickness
        )
        self.bond_c0 = bond_micromodulus(self.c0, bonds)
        self.inv_length = (1.0 / bonds.length).astype(self.dtype)
        base = self.bond_c0 * bonds.influence * self.bond_volume
        self.bond_stiffness = base.astype(self.dtype)
        self.surface_factor = np.ones(bonds.n_bonds)
        if surface_correction == "energy":
            self.surface_factor = self._energy_surface_factor()
            self.bond_stiffness = (base * self.surface_factor).astype(self.dtype)
        self._blocks: np.ndarray | None = None  # row blocks and splits of the float64 sums
        self._split: np.ndarray | None = None
        self._pairs = None  # the half list, once made (None if the families do not allow it)
        self._pairs_h: np.ndarray | None = None
        self._pairs_tried = False

    surface_corrections = SURFACE_CORRECTIONS

    @classmethod
    def implied_poisson_ratio(cls, dim, plane=None):
        """1/3 in plane stress, else 1/4 (``pmb_poisson_ratio``)."""
        return pmb_poisson_ratio(dim, plane)

    @classmethod
    def plane_wave_coefficients(cls, family, E, nu):
        """Pair ``c0 w / |xi|``, no dilatation (``Model.plane_wave_coefficients``): c0 of
        ``pmb_micromodulus`` in 3D and 2D; in 1D, for a bar of unit cross-section,
        c0 = E / int_0^delta omega r dr (2 E / delta^2 for a constant omega, Silling 2000)."""
        w, dim = family.weight, family.dim
        if dim == 1:
            c0 = E / radial_moment(family.influence, family.horizon, 1)
        else:
            c0 = pmb_micromodulus(E, dim, family.horizon, family.influence, family.plane, family.thickness)
        return c0 * w / family.length, np.zeros_like(w), 0.0

    def force(self, u, out=None):
        """Internal force density (see ``Model.force``).

        float64 uses the stored ``inv_length``; float32 the cancellation-free kernel,
        which recomputes |xi| from ``x`` (see ``peridyn.kernels``). Both read
        ``bonds.intact`` on every call, so broken bonds need no notification (a bond breaks in
        both directions together: the float64 half list reads one of them).

        float64 sums each family in the row-block order of ``discretization.pairs``; the half
        list (each pair once, ``kernels.pmb.pmb_pair_force``) is used where each of its two phases
        has a block for every thread, else the full list: the same bits.
        """
        out = np.empty_like(self.x) if out is None else out
        return self._kernel_force(self._as_state(u), out)

    def force_overlapped(self, u, out, clear_rows, n_owned, finish):
        """See ``Model.force_overlapped``: a bond-based force needs no ghost value on the first
        ``clear_rows[0]`` rows."""
        clear = clear_rows[0]
        state = self._as_state(u)
        self._kernel_force(state, out, 0, clear)
        finish()
        state = self._refresh_ghosts(state, u, n_owned)
        self._kernel_force(state, out, clear, n_owned)
        out[n_owned:] = 0.0
        return out

    def _kernel_force(self, state, out, first: int = 0, stop: int = -1):
        """The force kernel of the dtype on ``state`` (``_as_state``) into the rows
        ``first .. stop - 1`` of ``out`` (``stop`` < 0: to the last row)."""
        b = self.bonds
        if self.dtype == np.float32:
            args = (self.x, state, b.offsets, b.neighbours, self.bond_stiffness, b.intact, out)
            return pmb_force_cf(*args, first, stop)
        if first == 0 and stop < 0 and self.runs_half_list():
            pairs = self._pairs
            args = (pairs.xi, state, pairs.offsets, pairs.neighbours, pairs.inv_len, pairs.k, pairs.k_rev)
            for phase in (0, 1):
                pmb_pair_force(*args, b.intact, pairs.intact_at, pairs.blocks, phase, out, self._pairs_h)
            return out
        self._plan_sums()
        per_bond = (self.inv_length, self.bond_stiffness, b.intact)
        return pmb_force(
            self.bond_vectors, state, b.offsets, b.neighbours, *per_bond, out, first, stop, self._split
        )

    def runs_half_list(self) -> bool:
        """Whether :meth:`force` runs the half list now: float64, a whole body whose families
        allow it, and at least one row block per numba thread in each of its two phases. The
        half list is made the first time this holds."""
        if self.dtype != np.float64:
            return False
        self._plan_sums()
        b = self.bonds
        if (
            self._split is None
            or b.global_rows is not None
            or len(self._blocks) <= 2 * numba.get_num_threads()
        ):
            return False
        if not self._pairs_tried:
            self._pairs = half_list(b, self.x, self.inv_length, self.bond_stiffness, self._blocks)
            self._pairs_h = None if self._pairs is None else np.empty_like(self.x)
            self._pairs_tried = True
        return self._pairs is not None

    def _plan_sums(self):
        """Once (float64): the row blocks of the sums and each family's ``h`` / ``g`` split
        (``discretization.pairs``; a rank's part takes the whole body's from its bonds)."""
        if self._blocks is not None:
            return
        b = self.bonds
        blocks = b.row_blocks
        if blocks is None:
            blocks = row_blocks(len(b.offsets) - 1, index_bandwidth(b.offsets, b.neighbours))
        self._split = block_split(b.offsets, b.neighbours, blocks, b.global_rows)
        self._blocks = blocks

    def energy_density(self, u):
        b = self.bonds
        w = np.empty(self.body.n_points)
        return pmb_energy(
            self.body.points,
            np.ascontiguousarray(u, dtype=np.float64),
            b.offsets,
            b.neighbours,
            b.length,
            self.bond_stiffness.astype(np.float64),
            b.intact,
            w,
        )

    def stiffness_bound(self):
        b = self.bonds
        per_bond = np.where(b.intact, self.bond_stiffness / b.length, 0.0)
        return 2.0 * b.family_sum(per_bond)

    def _linearise(self):
        """Bond-based: t = (k / |xi|) e, and point i's energy holds k e^2 / (4 |xi|) per bond."""
        per_length = self.bond_stiffness.astype(np.float64) / self.bonds.length
        return BondLinearisation(extension=per_length, pair=per_length)

    def critical_stretch(self, fracture_energy):
        """s_c from G_c by integrating the bond energies across a crack plane.

        3D: G = (c0 s^2 / 2) pi int omega r^4 dr (constant omega: s_c = sqrt(5 G / (9 K delta)),
        Silling and Askari 2005); 2D: G = t c0 s^2 int omega r^3 dr (constant omega, plane
        stress: s_c = sqrt(4 pi G / (9 E delta)), Ha and Bobaru 2010). Per point, (n_points,),
        from each point's own c0 in a body of several blocks.
        """
        delta, name = self.bonds.horizons(), self.bonds.influence_name
        if self.body.dim == 3:
            per_s2 = 0.5 * self.c0 * np.pi * radial_moments(name, delta, 4)
        else:
            per_s2 = self.body.thickness * self.c0 * radial_moments(name, delta, 3)
        s_c = np.sqrt(fracture_energy / per_s2)
        return float(s_c) if np.ndim(s_c) == 0 else s_c

    def _energy_surface_factor(self) -> np.ndarray:
        body, b = self.body, self.bonds
        dim = body.dim
        strain = 1e-3
        # continuum energy density of a uniaxial strain: (c0/4) eps^2 int omega r^d dr * <n^4>
        moment = radial_moments(b.influence_name, b.horizons(), dim)
        thickness = body.thickness if dim == 2 else 1.0
        w_bulk = 0.25 * self.c0 * strain**2 * moment * mean_fourth_power(dim) * thickness
        owners = b.owners()
        xi = body.points[b.neighbours] - body.points[owners]
        n = xi / b.length[:, None]
        base = self.bond_c0 * b.influence * self.bond_volume
        inv_g2 = np.zeros(b.n_bonds)
        for axis in range(dim):
            u = np.zeros_like(body.points)
            u[:, axis] = strain * body.points[:, axis]
            w = pmb_energy(
                body.points, u, b.offsets, b.neighbours, b.length, base, b.intact, np.empty(body.n_points)
            )
            g = w_bulk / np.maximum(w, 1e-300)
            g_bond = 0.5 * (g[owners] + g[b.neighbours])
            inv_g2 += (n[:, axis] / g_bond) ** 2
        return 1.0 / np.sqrt(inv_g2)
