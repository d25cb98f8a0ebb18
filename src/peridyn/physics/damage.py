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
s_c = sigma_u / E (Martowicz: sigma_u = 40 MPa, E = 70 GPa -> s_c = 5.71e-4), the same
for PMB and LPS, 2D and 3D. See docs/theory.md, "Critical bond stress".

The stretch-test skin. A bond (i, j) breaks when its deformed length ``|Y|`` passes its
critical length ``L_c = |xi| (1 + s_c)``. Between two displacements ``|Y|`` changes by at most
``|du_i| + |du_j|`` (triangle inequality), so a bond with margin ``L_c - |Y|`` cannot break before
its end points have moved that much. ``BondDamage.update`` therefore tests every bond only
now and then (a "full test" at a reference displacement u_ref), keeping per point the
smallest margin m_i of its intact breakable bonds. At the next calls, with
``d_k = |u_k - u_ref_k|``, a bond can only break if m < d_i + d_j <= 2 max(d_i, d_j): only the
points with m_i <= 2 d_i have their families tested, and a bond broken there is broken in
both copies (the other end may not be tested). Their margins are refreshed, taken back to
u_ref (minus d_j per bond and d_i). When ``FULL_TEST_SHARE`` of the points or more would
be tested, a full test is done and u_ref reset. The bonds broken are exactly those that
testing every bond at every call breaks (same test, same roundings; the margins carry a
1e-9 relative slack for roundings).
"""

from __future__ import annotations

import numpy as np

from peridyn.errors import InputError
from peridyn.kernels.damage import MAX_QUANTA, flag_moved_points, stretch_test_families
from peridyn.physics.materials.base import Model


def stretch_from_bond_stress(critical_bond_stress: float, E):
    """Critical stretch s_c = sigma_u / E of the bond stress sigma_b = E s (module docstring).

    Parameters
    ----------
    critical_bond_stress : float, Pa
    E : float or (n_points,), Pa (Young's modulus; per point in a body of several blocks, which
        gives s_c per point)
    """
    if not critical_bond_stress > 0:
        raise InputError(f"critical_bond_stress must be positive, got {critical_bond_stress!r}")
    if np.ndim(E) == 0:
        return float(critical_bond_stress) / float(E)
    return float(critical_bond_stress) / np.asarray(E, dtype=float)


def protected_points(body, names, empty: bool = False) -> np.ndarray:
    """(n_points,) bool: the points of the node sets ``names`` (whose bonds never break);
    ``empty``: a set may hold none of them (``body`` a rank's part)."""
    protected = np.zeros(body.n_points, dtype=bool)
    for name in names:
        protected[body.node_set(name, empty)] = True
    return protected


def resolve_critical_stretch(model, critical_stretch=None, fracture_energy=None, critical_bond_stress=None):
    """The critical stretch from exactly one of the three criteria: itself (a number or
    (n_points,) values), a fracture energy (J/m^2, through ``model.critical_stretch``) or a
    critical bond stress (Pa, ``stretch_from_bond_stress``).

    Raises
    ------
    InputError
        Not exactly one criterion given, or a value that is not positive.
    """
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
    if not np.all(np.asarray(critical_stretch) > 0):
        raise InputError(f"critical_stretch must be positive, got {critical_stretch!r}")
    return critical_stretch


class BondDamage:
    """Critical-stretch bond failure for one model.

    Parameters
    ----------
    model : Model
    critical_stretch : float, (n_points,) or None
        Dimensionless; give exactly one of this, ``fracture_energy`` or ``critical_bond_stress``.
        Per point (a body of several blocks, docs/blocks.md; also what ``fracture_energy`` and
        ``critical_bond_stress`` give on such a body): a bond breaks at the smaller of its two
        ends' values, and never where both are inf.
    fracture_energy : float or None, J/m^2
    no_damage_sets : sequence of str
        Node sets whose bonds never break.
    critical_bond_stress : float or None, Pa
        Bonds break when E s exceeds it (module docstring); needs ``model.E``.
    protected : (n_points,) bool or None
        More points whose bonds never break (a rank's part of the ``no_damage_sets`` of the
        whole body, where its own part of a set may be empty).
    schedule : TimeFunction or None
        A critical stretch that changes in time (Peridigm's "Time Dependent Critical
        Stretch"): s_c(t), given instead of ``critical_stretch``; ``update`` at time t takes it.

    ``critical_stretch`` (n_bonds,) and ``breakable`` (n_bonds,) bool may be edited until
    the first ``update``, which reads them into the critical lengths and makes them
    read-only. Code that changes them later, or that mends bonds (sets ``intact`` back to
    True), must call ``reset`` first. Breaking bonds elsewhere needs nothing.
    """

    #: Share of the points from which on ``update`` tests every bond rather than the flagged
    #: families (and resets the skin's reference displacement).
    FULL_TEST_SHARE = 0.25

    def __init__(
        self,
        model: Model,
        critical_stretch: float | None = None,
        fracture_energy: float | None = None,
        no_damage_sets=(),
        critical_bond_stress: float | None = None,
        protected: np.ndarray | None = None,
        schedule=None,
    ):
        self.schedule = schedule
        if schedule is not None:
            critical_stretch = float(schedule(0.0))
        criteria = (critical_stretch, fracture_energy, critical_bond_stress)
        critical_stretch = resolve_critical_stretch(model, *criteria)
        self.model = model
        bonds = model.bonds
        protected = protected_points(model.body, no_damage_sets) | (False if protected is None else protected)
        self.breakable = ~(protected[bonds.owners()] | protected[bonds.neighbours])
        if np.ndim(critical_stretch) == 0:
            self.value = float(critical_stretch)
            self.critical_stretch = np.full(bonds.n_bonds, self.value)
        else:
            per_point = np.asarray(critical_stretch, dtype=float)
            self.critical_stretch = np.minimum(per_point[bonds.owners()], per_point[bonds.neighbours])
            self.breakable &= np.isfinite(self.critical_stretch)
            self.value = float(np.min(per_point))
        n = model.body.n_points
        self.full_tests = 0  # calls of ``update`` that tested every bond
        self.partial_tests = 0  # calls that tested only the flagged families
        self._limit = None  # (n_bonds,) critical length L_c, m (inf: may not break)
        self._u_ref = None  # (n, 3) displacement of the last full test, m
        self._margin = np.empty(n)  # (n,) room left per point, taken at u_ref, m
        self._fresh = np.empty(n)  # (n,) margins measured by the last test, m
        self._moved = np.empty(n)  # (n,) |u - u_ref|, m
        self._tested = np.empty(n, dtype=bool)  # (n,) families the last partial test covered
        self._quantum = bonds.horizon / MAX_QUANTA  # margins are whole multiples of it, m
        self._everyone = np.arange(n)
        self._all_tested = np.ones(n, dtype=bool)
        self._none_moved = np.zeros(n)

    def __repr__(self) -> str:
        return f"BondDamage(critical_stretch={self.value:.4g})"

    def update(self, u: np.ndarray, t: float | None = None) -> int:
        """Break every over-stretched breakable bond at displacement ``u`` (n_points, 3), m, at
        time ``t`` (s: a ``schedule`` gives the critical stretch then).

        Returns the number of directed bonds broken.
        """
        if self.schedule is not None and t is not None:
            value = float(self.schedule(t))
            if value != self.value:
                self.reset()
                self.value = value
                self.critical_stretch[:] = value
        m = self.model
        b = m.bonds
        u = np.ascontiguousarray(u, dtype=np.float64)
        if self._u_ref is None:
            return self._full_test(u)
        n_tested = flag_moved_points(u, self._u_ref, self._margin, self._moved, self._tested)
        if n_tested < 0 or n_tested >= self.FULL_TEST_SHARE * self._margin.size:
            return self._full_test(u)
        self.partial_tests += 1
        if n_tested == 0:
            return 0
        flagged = np.flatnonzero(self._tested)
        broken = stretch_test_families(
            m.body.points,
            u,
            b.offsets,
            b.neighbours,
            self._limit,
            b.intact,
            flagged,
            self._tested,
            self._moved,
            self._quantum,
            self._fresh,
        )
        self._margin[flagged] = np.maximum(self._margin[flagged], self._fresh[flagged])
        return int(broken)

    def reset(self) -> None:
        """Forget the skin and the critical lengths (after mending bonds, or to edit
        ``critical_stretch`` or ``breakable``): the next ``update`` tests every bond."""
        self._limit = self._u_ref = None
        self.critical_stretch.flags.writeable = True
        self.breakable.flags.writeable = True

    def checkpoint_state(self) -> dict:
        """The stretch-test skin, for a checkpoint: u_ref (n, 3) m, margins (n,) m and the test
        counters (empty before the first ``update``)."""
        if self._u_ref is None:
            return {}
        return {
            "u_ref": self._u_ref,
            "margin": self._margin,
            "full_tests": self.full_tests,
            "partial_tests": self.partial_tests,
        }

    def restore_state(self, saved: dict) -> None:
        """Take back the skin of ``checkpoint_state`` (the intact mask is restored apart)."""
        self.reset()
        if not saved:
            return
        self._freeze_limit()
        self._u_ref = np.array(saved["u_ref"], dtype=np.float64)
        self._margin[:] = saved["margin"]
        self.full_tests = int(saved["full_tests"])
        self.partial_tests = int(saved["partial_tests"])

    def critical_lengths(self) -> np.ndarray:
        """(n_bonds,) m: the deformed length past which each bond breaks, ``|xi| (1 + s_c)`` (inf
        where it may not break); from the first call on, ``critical_stretch`` and ``breakable``
        are read-only (see the class)."""
        if self._limit is None:
            self._freeze_limit()
        return self._limit

    def _freeze_limit(self) -> None:
        """Compute the critical lengths and make their inputs read-only."""
        self._limit = np.where(
            self.breakable, self.model.bonds.length * (1.0 + self.critical_stretch), np.inf
        )
        self.critical_stretch.flags.writeable = False
        self.breakable.flags.writeable = False

    def _full_test(self, u: np.ndarray) -> int:
        """Test every bond at ``u``; margins and u_ref taken there."""
        m = self.model
        b = m.bonds
        if self._limit is None:
            self._freeze_limit()
        broken = stretch_test_families(
            m.body.points,
            u,
            b.offsets,
            b.neighbours,
            self._limit,
            b.intact,
            self._everyone,
            self._all_tested,
            self._none_moved,
            self._quantum,
            self._margin,
        )
        self._u_ref = u.copy()
        self.full_tests += 1
        return int(broken)


def damage_field(model: Model) -> np.ndarray:
    """Damage index phi (n_points,): the broken share of each family's bond volume
    (``Model.damage_index``)."""
    return model.damage_index()
