"""A test-only bond-based material with a conical micromodulus, registered as "conical".

It shows that adding a material is adding one file: it touches no module of peridyn, and
``tests/conftest.py`` imports it so that the material invariants (tests/invariants) and the
modal test of tests/unit/test_material_registry.py run on it as on PMB and LPS.

The micromodulus falls linearly to zero at the horizon delta,

    c(xi) = c0 (1 - |xi| / delta) omega(|xi|),

with c0 from the same bulk-energy equivalence as PMB (Silling and Askari 2005: the strain
energy of an isotropic expansion equals the classical one in the bulk), with the moments
M_p = int_0^delta omega(r) r^p dr:

- 3D: c0 = 18 K / (4 pi (M_3 - M_4 / delta))  (constant omega: 90 K / (pi delta^4));
- 2D: c0 = 8 kappa / (t 2 pi (M_2 - M_3 / delta)),

i.e. PMB's c0 times M_d / (M_d - M_(d+1) / delta). The bond stiffness is k = c(xi) beta V_j
and the force and energy are PMB's kernels with it.
"""

from __future__ import annotations

import warnings

import numpy as np

from peridyn.errors import InputError
from peridyn.kernels.pmb import pmb_energy, pmb_force, pmb_force_cf
from peridyn.physics.materials import BondLinearisation, Model, register_material
from peridyn.physics.materials.elastic import check_elastic, radial_moment
from peridyn.physics.materials.pmb import pmb_micromodulus, pmb_poisson_ratio


@register_material("conical")
class ConicalBondModel(Model):
    """Bond-based material with c(xi) = c0 (1 - |xi| / delta) omega(|xi|) (module docstring).

    Parameters as ``PMBModel``: E (Pa), density (kg/m^3), ``nu`` only checked against the
    implied ratio, ``surface_correction`` "none" only, dtype float64 or float32.
    """

    bond_bytes = 16.0  # bond_stiffness and inv_length

    def __init__(self, body, bonds, E, density, nu=None, surface_correction="none", dtype=np.float64):
        implied = self.implied_poisson_ratio(body.dim, body.plane)
        check_elastic(E, implied if nu is None else nu, density)
        if nu is not None and abs(nu - implied) > 1e-3:
            warnings.warn(
                f"the conical bond material has Poisson ratio {implied:.4g}; nu = {nu} is ignored",
                stacklevel=2,
            )
        if surface_correction != "none":
            raise InputError(
                f"the conical bond material has no surface correction, got {surface_correction!r}"
            )
        super().__init__(body, bonds, E=E, density=density, dtype=dtype)
        delta = bonds.horizon
        #: c0, N/m^6 (3D)
        self.c0 = self._c0(E, body.dim, delta, bonds.influence_name, body.plane, body.thickness)
        stiffness = self.c0 * (1.0 - bonds.length / delta) * bonds.influence * self.bond_volume
        self.bond_stiffness = stiffness.astype(self.dtype)
        self.inv_length = (1.0 / bonds.length).astype(self.dtype)

    @classmethod
    def implied_poisson_ratio(cls, dim, plane=None):
        return pmb_poisson_ratio(dim, plane)

    @classmethod
    def _c0(cls, E, dim, delta, influence, plane, thickness) -> float:
        """c0 (module docstring); in 1D, for a bar of unit cross-section, E / int omega (1 - r /
        delta) r dr as PMB's 1D analogue (``PMBModel.plane_wave_coefficients``)."""
        if dim == 1:
            return E / _cone_moment(influence, delta, 1)
        pmb_c0 = pmb_micromodulus(E, dim, delta, influence, plane, thickness)
        return pmb_c0 * radial_moment(influence, delta, dim) / _cone_moment(influence, delta, dim)

    @classmethod
    def plane_wave_coefficients(cls, family, E, nu):
        """Pair c(xi) w / |xi| = c0 (1 - |xi| / delta) w / |xi|, no dilatation: PMB's with the
        cone's profile (``Model.plane_wave_coefficients``)."""
        c0 = cls._c0(E, family.dim, family.horizon, family.influence, family.plane, family.thickness)
        pair = c0 * (1.0 - family.length / family.horizon) * family.weight / family.length
        return pair, np.zeros_like(pair), 0.0

    def _cone_moment(self, power: int) -> float:
        """int_0^delta omega(r) (1 - r / delta) r^power dr of the bonds, m^(power + 1)."""
        return _cone_moment(self.bonds.influence_name, self.bonds.horizon, power)

    def force(self, u, out=None):
        out = np.empty_like(self.x) if out is None else out
        b = self.bonds
        u = self._as_state(u)
        if self.dtype == np.float32:
            return pmb_force_cf(self.x, u, b.offsets, b.neighbours, self.bond_stiffness, b.intact, out)
        return pmb_force(
            self.bond_vectors, u, b.offsets, b.neighbours, self.inv_length, self.bond_stiffness, b.intact, out
        )

    def energy_density(self, u):
        b = self.bonds
        u = np.ascontiguousarray(u, dtype=np.float64)
        k = self.bond_stiffness.astype(np.float64)
        return pmb_energy(
            self.body.points, u, b.offsets, b.neighbours, b.length, k, b.intact, np.empty(self.body.n_points)
        )

    def stiffness_bound(self):
        b = self.bonds
        return 2.0 * b.family_sum(np.where(b.intact, self.bond_stiffness / b.length, 0.0))

    def critical_stretch(self, fracture_energy):
        """As PMB's, with omega (1 - r / delta) for omega: G = (c0 s^2 / 2) pi int c r^4 dr (3D),
        G = t c0 s^2 int c r^3 dr (2D), c the cone's profile."""
        if self.body.dim == 3:
            per_s2 = 0.5 * self.c0 * np.pi * self._cone_moment(4)
        else:
            per_s2 = self.body.thickness * self.c0 * self._cone_moment(3)
        return float(np.sqrt(fracture_energy / per_s2))

    def _linearise(self):
        per_length = self.bond_stiffness.astype(np.float64) / self.bonds.length
        return BondLinearisation(extension=per_length, pair=per_length)


def _cone_moment(influence: str, delta: float, power: int) -> float:
    """int_0^delta omega(r) (1 - r / delta) r^power dr, m^(power + 1)."""
    return radial_moment(influence, delta, power) - radial_moment(influence, delta, power + 1) / delta
