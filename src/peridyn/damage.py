"""Bond breaking by critical stretch, and the damage index.

The critical stretch is given directly, derived from the fracture energy
G_c with the model's formula (``Model.critical_stretch``), or derived from a
critical bond stress (``critical_bond_stress``). Bonds with an end point in a
``no_damage`` node set never break. Breaking is irreversible.

Bond stress. A bond's force density c s (N/m^6) has no stress of its own; we
define the bond stress as the axial stress of the bond seen as a bar of the
material,

    sigma_b = E s,

which is the classical stress when the body is in uniaxial stress along the
bond (then every bond along the load carries stretch s = eps and sigma = E eps).
The criterion sigma_b > sigma_u is therefore the critical stretch
s_c = sigma_u / E (seed 004: sigma_u = 40 MPa, E = 70 GPa -> s_c = 5.71e-4), the same
for PMB and LPS, 2D and 3D. See docs/theory.md, "Critical bond stress".
"""

from __future__ import annotations

import numpy as np

from peridyn.errors import InputError
from peridyn.kernels.damage import break_stretched_bonds, damage_index
from peridyn.materials.base import Model


def stretch_from_bond_stress(critical_bond_stress: float, E: float) -> float:
    """Critical stretch s_c = sigma_u / E of the bond stress sigma_b = E s (module docstring).

    Parameters
    ----------
    critical_bond_stress : float, Pa
    E : float, Pa (Young's modulus)
    """
    if not critical_bond_stress > 0:
        raise InputError(f"critical_bond_stress must be positive, got {critical_bond_stress!r}")
    return float(critical_bond_stress) / float(E)


class BondDamage:
    """Critical-stretch bond failure for one model.

    Parameters
    ----------
    model : Model
    critical_stretch : float or None
        Dimensionless; give exactly one of this, ``fracture_energy`` or ``critical_bond_stress``.
    fracture_energy : float or None, J/m^2
    no_damage_sets : sequence of str
        Node sets whose bonds never break.
    critical_bond_stress : float or None, Pa
        Bonds break when E s exceeds it (module docstring); needs ``model.E``.
    """

    def __init__(self, model: Model, critical_stretch: float | None = None,
                 fracture_energy: float | None = None, no_damage_sets=(),
                 critical_bond_stress: float | None = None):
        given = [v is not None for v in (critical_stretch, fracture_energy, critical_bond_stress)]
        if sum(given) != 1:
            raise InputError("damage needs exactly one of critical_stretch, fracture_energy or "
                             f"critical_bond_stress (got {sum(given)})")
        if critical_bond_stress is not None:
            critical_stretch = stretch_from_bond_stress(critical_bond_stress, model.E)
        if fracture_energy is not None:
            if not fracture_energy > 0:
                raise InputError(f"fracture_energy must be positive, got {fracture_energy!r}")
            critical_stretch = model.critical_stretch(fracture_energy)
        if not critical_stretch > 0:
            raise InputError(f"critical_stretch must be positive, got {critical_stretch!r}")
        self.model = model
        self.value = float(critical_stretch)
        bonds = model.bonds
        self.critical_stretch = np.full(bonds.n_bonds, self.value)
        protected = np.zeros(model.body.n_points, dtype=bool)
        for name in no_damage_sets:
            protected[model.body.node_set(name)] = True
        self.breakable = ~(protected[bonds.owners()] | protected[bonds.neighbours])

    def __repr__(self) -> str:
        return f"BondDamage(critical_stretch={self.value:.4g})"

    def update(self, u: np.ndarray) -> int:
        """Break every over-stretched breakable bond at displacement ``u``; returns the count."""
        m = self.model
        b = m.bonds
        return int(break_stretched_bonds(m.body.points, np.ascontiguousarray(u, dtype=np.float64),
                                         b.offsets, b.neighbours, b.length, self.critical_stretch,
                                         self.breakable, b.intact))


def damage_field(model: Model) -> np.ndarray:
    """Damage index phi (n_points,): the broken share of each family's bond volume."""
    b = model.bonds
    return damage_index(b.offsets, model.bond_volume, b.intact, np.empty(model.body.n_points))
