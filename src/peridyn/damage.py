"""Bond breaking by critical stretch, and the damage index.

The critical stretch is given directly or derived from the fracture energy
G_c with the model's formula (``Model.critical_stretch``). Bonds with an end
point in a ``no_damage`` node set never break. Breaking is irreversible.
"""

from __future__ import annotations

import numpy as np

from peridyn.errors import InputError
from peridyn.kernels.damage import break_stretched_bonds, damage_index
from peridyn.materials.base import Model


class BondDamage:
    """Critical-stretch bond failure for one model.

    Parameters
    ----------
    model : Model
    critical_stretch : float or None
        Dimensionless; give this or ``fracture_energy``.
    fracture_energy : float or None, J/m^2
    no_damage_sets : sequence of str
        Node sets whose bonds never break.
    """

    def __init__(self, model: Model, critical_stretch: float | None = None,
                 fracture_energy: float | None = None, no_damage_sets=()):
        if (critical_stretch is None) == (fracture_energy is None):
            raise InputError("damage needs exactly one of critical_stretch or fracture_energy")
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
