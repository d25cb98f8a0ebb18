"""Bond breaking by critical stretch on lattice storage (``peridyn.discretization.lattice``).

The criterion of ``peridyn.physics.damage``: a bond breaks when its deformed length passes
``|xi| (1 + s_c)``, never where an end point lies in a ``no_damage`` set; breaking is
irreversible. The broken bits live in the lattice.

A test of every bond costs about a force. As ``BondDamage`` does with its skin (there per
point), :meth:`LatticeDamage.update` keeps the smallest room ``L_c - |Y|`` left to any
breakable intact bond at the displacement of its last test, and skips the test while no
point has moved half of it since (|Y| changes by at most |du_i| + |du_j|): the bonds broken
are those a test at every call breaks.
"""

from __future__ import annotations

import numpy as np

from peridyn.kernels.lattice import largest_move_squared, lattice_stretch_test
from peridyn.physics.damage import protected_points, resolve_critical_stretch

#: Relative slack on the room (of the largest critical length) for the roundings of |Y|.
ROUNDING_SLACK = 1e-9


class LatticeDamage:
    """Critical-stretch bond failure of a lattice model (``materials.lattice``).

    Parameters as ``physics.damage.BondDamage`` (one material: the critical stretch is a number;
    ``protected``: (n_points,) bool, more points whose bonds never break, as a rank's part gives
    the whole body's no-damage sets).
    """

    def __init__(
        self,
        model,
        critical_stretch: float | None = None,
        fracture_energy: float | None = None,
        no_damage_sets=(),
        critical_bond_stress: float | None = None,
        protected: np.ndarray | None = None,
    ):
        criteria = (critical_stretch, fracture_energy, critical_bond_stress)
        critical_stretch = resolve_critical_stretch(model, *criteria)
        self.model = model
        self.value = float(critical_stretch)
        lattice = model.lattice
        #: (n_off,) m: the critical length of each offset's bonds
        self.limit = lattice.stencil.length * (1.0 + self.value)
        #: (n_grid,) bool: grid points whose bonds may break
        self.breakable = np.ones(lattice.n_grid, dtype=bool)
        protected = protected_points(model.body, no_damage_sets) | (False if protected is None else protected)
        self.breakable[lattice.grid_index[protected]] = False
        rows = int(lattice.shape[1] * lattice.shape[2])
        self._count = np.zeros(rows, dtype=np.int64)
        self._room = np.zeros(rows)
        self._u_ref: np.ndarray | None = None  # (n_points, 3) m, the displacement of the last test
        self._least = 0.0  # m, the smallest room at u_ref
        self._slack = ROUNDING_SLACK * float(self.limit.max())  # m, the roundings of |Y|
        self.full_tests = 0  # calls of ``update`` that tested every bond

    def __repr__(self) -> str:
        return f"LatticeDamage(critical_stretch={self.value:.4g})"

    def update(self, u: np.ndarray, t: float | None = None) -> int:
        """Break every over-stretched breakable bond at displacement ``u`` (n_points, 3), m;
        returns the number of directed bonds broken. ``t`` (s) is that of ``BondDamage.update``:
        the lattice's critical stretch does not change in time (``setup.storage`` refuses one
        that does)."""
        u = np.ascontiguousarray(u, dtype=np.float64)
        if self._u_ref is not None:
            if 2.0 * np.sqrt(largest_move_squared(u, self._u_ref)) < self._least - self._slack:
                return 0
        lat = self.model.lattice
        ug = self.model.grid_displacement(u)
        s = lat.stencil
        args = (lat.volume, lat.broken, lat.shape, s.offsets, s.xi, self.limit, self.breakable)
        broken = int(lattice_stretch_test(ug, *args, self._count, self._room))
        if self._u_ref is None:
            self._u_ref = u.copy()
        else:
            self._u_ref[...] = u
        self._least = float(self._room.min(initial=np.inf))
        self.full_tests += 1
        return broken

    def reset(self) -> None:
        """Forget the room (after editing ``limit`` or ``breakable``, or mending bonds): the next
        ``update`` tests every bond."""
        self._u_ref = None

    def checkpoint_state(self) -> dict:
        """Nothing beyond the broken bits (saved with the state): a restart tests every bond."""
        return {}

    def restore_state(self, saved: dict) -> None:
        """Start again with a test of every bond (the broken bits are restored with the state)."""
        self.reset()
