"""Remaining-life fatigue model of Silling and Askari (Freimanis 2019, eqs. 7.1-7.6, 7.15).

Each bond carries a remaining life lambda, 1 at N = 0 (eq. 7.3). Per load cycle

- phase I (nucleation): d lambda / dN = -A_I (eps - eps_inf)^m_I for eps > eps_inf, 0 otherwise
  (eq. 7.4);
- phase II (growth): d lambda / dN = -A_II eps^m_II (eq. 7.5), for the bonds of a point once a
  point of its family (itself included) has damage phi >= phi_c (eq. 7.6); at the switch the
  point's bonds restart with lambda = 1.

eps is the cyclic bond strain |s+ - s-| between the two load extremes (eq. 7.1); for proportional
loading with load ratio R = load- / load+ it is (1 - R) |s+|. A bond breaks, for good, when its
lambda reaches zero (eq. 7.2); both directed halves of a bond break together.
A_II depends on the horizon: A_II(delta) = A_II_hat delta^((m_II - 2) / 2) (eq. 7.15).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from peridyn.errors import InputError
from peridyn.parallel.domain import Domain
from peridyn.physics.materials.base import Model


@dataclass(frozen=True)
class FatigueParameters:
    """Remaining-life parameters (dimensionless; A_I, A_II per cycle).

    Attributes
    ----------
    A_I, m_I, eps_inf : phase I (eq. 7.4); eps_inf is the bond-strain fatigue limit.
    A_II, m_II : phase II (eq. 7.5), A_II at the horizon the model runs with.
    phi_c : damage that switches a family to phase II (eq. 7.6).
    """

    A_I: float
    m_I: float
    eps_inf: float
    A_II: float
    m_II: float
    phi_c: float = 0.385

    def __post_init__(self):
        for name in ("A_I", "m_I", "A_II", "m_II"):
            value = getattr(self, name)
            if not (np.isfinite(value) and value > 0):
                raise InputError(f"fatigue parameter {name} must be positive, got {value!r}")
        if not (np.isfinite(self.eps_inf) and self.eps_inf >= 0):
            raise InputError(f"fatigue parameter eps_inf must be >= 0, got {self.eps_inf!r}")
        if not 0 < self.phi_c <= 1:
            raise InputError(f"fatigue parameter phi_c must be in (0, 1], got {self.phi_c!r}")

    def phase_one_life(self, eps: float) -> float:
        """Cycles to break a bond held at cyclic strain ``eps`` in phase I: 1 / (A_I (eps - eps_inf)^m_I)."""
        if eps <= self.eps_inf:
            return np.inf
        return 1.0 / (self.A_I * (eps - self.eps_inf) ** self.m_I)


def scale_A_II(A_II: float, horizon_from: float, horizon_to: float, m_II: float) -> float:
    """A_II calibrated at ``horizon_from`` (m) moved to ``horizon_to`` (m) by eq. 7.15."""
    if not (horizon_from > 0 and horizon_to > 0):
        raise InputError("A_II horizon scaling needs positive horizons")
    return A_II * (horizon_to / horizon_from) ** ((m_II - 2.0) / 2.0)


def bond_strain(model: Model, u: np.ndarray) -> np.ndarray:
    """Linearised bond strain n . (u_j - u_i) / |xi| (n_bonds,), for displacement u (n_points, 3), m."""
    b = model.bonds
    x = model.body.points
    owners = b.owners()
    xi = x[b.neighbours] - x[owners]
    eta = u[b.neighbours] - u[owners]
    return np.einsum("ij,ij->i", xi, eta) / b.length**2


def cyclic_bond_strain(model: Model, u_max: np.ndarray, load_ratio: float) -> np.ndarray:
    """Cyclic bond strain (n_bonds,) |s+ - s-| = (1 - R) |s+| for proportional loading (eq. 7.1)."""
    return (1.0 - load_ratio) * np.abs(bond_strain(model, u_max))


class RemainingLife:
    """Per-bond remaining life of one model, updated in place; breaks ``model.bonds.intact``.

    Parameters
    ----------
    model : Model
    params : FatigueParameters
    breakable : (n_bonds,) bool or None
        Bonds allowed to break (False for bonds touching no-damage node sets).
    domain : Domain or None
        Under MPI, the rank's place in the body (``model`` is its part: owned points, then
        ghosts): the ghosts' phase comes from their owners (``update_phase``). None: one process.

    Every bond on a rank is a copy of a bond of an owned family of some rank (its owner's), and
    its life is computed from the same values there and here (the strain from the exchanged
    displacement, the phase of its owner), so the copies stay equal and a bond and its reverse,
    owned by two ranks, break at the same step on both, as in serial.
    """

    def __init__(
        self,
        model: Model,
        params: FatigueParameters,
        breakable: np.ndarray | None = None,
        domain: Domain | None = None,
    ):
        b = model.bonds
        self.model = model
        self.domain = domain
        self.params = params
        self.life = np.ones(b.n_bonds)
        self.phase_two = np.zeros(model.body.n_points, dtype=bool)
        self.breakable = np.ones(b.n_bonds, dtype=bool) if breakable is None else breakable
        self._owners = b.owners()
        self._reverse = b.reverse()

    def rate(self, eps: np.ndarray) -> np.ndarray:
        """Loss of life per cycle (n_bonds,) >= 0 at cyclic strains ``eps`` (eqs. 7.4, 7.5)."""
        p = self.params
        one = p.A_I * np.maximum(eps - p.eps_inf, 0.0) ** p.m_I
        two = p.A_II * eps**p.m_II
        rate = np.where(self.phase_two[self._owners], two, one)
        return np.where(self.model.bonds.intact & self.breakable, rate, 0.0)

    def cycles_to_next_break(self, eps: np.ndarray) -> float:
        """Cycles until the first intact breakable bond reaches zero life at ``eps`` (inf if none)."""
        rate = self.rate(eps)
        active = rate > 0
        if not active.any():
            return np.inf
        return float(np.min(self.life[active] / rate[active]))

    def advance(self, eps: np.ndarray, cycles: float) -> int:
        """Spend ``cycles`` cycles at ``eps``; break the bonds whose life ran out (both directions
        of a bond together). Returns the directed bonds broken (twice the bonds)."""
        intact = self.model.bonds.intact
        self.life -= self.rate(eps) * cycles
        dead = intact & (self.life <= 0.0)
        dead |= dead[self._reverse]
        intact &= ~dead
        return int(dead.sum())

    def update_phase(self, phi: np.ndarray) -> int:
        """Switch points with a family member at phi >= phi_c to phase II (eq. 7.6); returns how many
        (of the owned points, under MPI; the ghosts take their owners' switch).

        Phase and restart are per directed bond half, by its owner: the halves owned by a
        switched point restart at life 1 with the phase-II rate, the reverse halves keep
        their owner's phase; a bond breaks when either half's life runs out (``advance``).
        """
        b = self.model.bonds
        hit = (phi[b.neighbours] >= self.params.phi_c).astype(np.float64)
        near = np.bincount(self._owners, weights=hit, minlength=len(phi)) > 0
        new = (near | (phi >= self.params.phi_c)) & ~self.phase_two
        if self.domain is not None and self.domain.size > 1:  # the ghosts' switch is their owners'
            switched = new.astype(np.float64)
            self.domain.exchange(switched)
            new = switched > 0.0
        self.phase_two |= new
        self.life[new[self._owners]] = 1.0
        n_owned = len(phi) if self.domain is None else self.domain.n_owned
        return int(new[:n_owned].sum())
