"""Bond breaking by critical stretch on lattice storage (``peridyn.discretization.lattice``).

The criterion of ``peridyn.physics.damage``: a bond breaks when its deformed length passes
``|xi| (1 + s_c)``, never where an end point lies in a ``no_damage`` set; breaking is
irreversible. Each :meth:`LatticeDamage.update` tests every bond (one pass over the stencil,
about the cost of a force); the broken bits live in the lattice.
"""

from __future__ import annotations

import numpy as np

from peridyn.errors import InputError
from peridyn.kernels.lattice import lattice_scatter, lattice_stretch_test
from peridyn.physics.damage import protected_points, stretch_from_bond_stress


class LatticeDamage:
    """Critical-stretch bond failure of a lattice model (``materials.lattice``).

    Parameters as ``physics.damage.BondDamage`` (one material: the critical stretch is a number).
    """

    def __init__(
        self,
        model,
        critical_stretch: float | None = None,
        fracture_energy: float | None = None,
        no_damage_sets=(),
        critical_bond_stress: float | None = None,
    ):
        given = [v is not None for v in (critical_stretch, fracture_energy, critical_bond_stress)]
        if sum(given) != 1:
            raise InputError(
                "damage needs exactly one of critical_stretch, fracture_energy or "
                f"critical_bond_stress (got {sum(given)})"
            )
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
        lattice = model.lattice
        #: (n_off,) m: the critical length of each offset's bonds
        self.limit = lattice.stencil.length * (1.0 + self.value)
        #: (n_grid,) bool: grid points whose bonds may break
        self.breakable = np.ones(lattice.n_grid, dtype=bool)
        self.breakable[lattice.grid_index[protected_points(model.body, no_damage_sets)]] = False
        self._ug = np.zeros((3, lattice.n_grid))
        self._count = np.zeros(int(lattice.shape[1] * lattice.shape[2]), dtype=np.int64)

    def __repr__(self) -> str:
        return f"LatticeDamage(critical_stretch={self.value:.4g})"

    def update(self, u: np.ndarray) -> int:
        """Break every over-stretched breakable bond at displacement ``u`` (n_points, 3), m;
        returns the number of directed bonds broken."""
        lat = self.model.lattice
        ug = lattice_scatter(np.ascontiguousarray(u, dtype=np.float64), lat.grid_index, self._ug)
        s = lat.stencil
        args = (lat.volume, lat.broken, lat.shape, s.offsets, s.xi, self.limit, self.breakable, self._count)
        return int(lattice_stretch_test(ug, *args))

    def reset(self) -> None:
        """Nothing to forget: every update tests every bond."""

    def checkpoint_state(self) -> dict:
        """Nothing beyond the broken bits (saved with the state)."""
        return {}

    def restore_state(self, saved: dict) -> None:
        """Nothing beyond the broken bits (restored with the state)."""
