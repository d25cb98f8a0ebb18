"""What every material model bound to a discretisation provides."""

from __future__ import annotations

import numpy as np

from peridyn.discretization.body import Body
from peridyn.discretization.bonds import Bonds


class Model:
    """A material law over the bonds of one body (abstract).

    Subclasses set the per-bond and per-point coefficient arrays in their
    constructor and implement :meth:`force`, :meth:`energy_density`,
    :meth:`stiffness_bound` and :meth:`critical_stretch`.

    Attributes
    ----------
    body : Body
    bonds : Bonds
        ``bonds.intact`` is shared and updated in place when bonds break.
    dtype : numpy dtype
        Floating type of the kernels (float64 or float32).
    x : (n_points, 3) dtype, m
        Reference positions in the kernel dtype.
    density : (n_points,) float64, kg/m^3
    """

    name = "model"

    def __init__(self, body: Body, bonds: Bonds, density: float, dtype=np.float64):
        self.body = body
        self.bonds = bonds
        self.dtype = np.dtype(dtype)
        self.x = np.ascontiguousarray(body.points, dtype=self.dtype)
        self.density = np.full(body.n_points, float(density))
        self.neighbours = bonds.neighbours
        self.offsets = bonds.offsets
        # neighbour volume times its volume factor, (n_bonds,) m^3
        self.bond_volume = body.volumes[bonds.neighbours] * bonds.volume_factor

    def __repr__(self) -> str:
        return f"{type(self).__name__}(n_points={self.body.n_points}, dtype={self.dtype.name})"

    def _as_state(self, u: np.ndarray) -> np.ndarray:
        return np.ascontiguousarray(u, dtype=self.dtype)

    def force(self, u: np.ndarray, out: np.ndarray | None = None) -> np.ndarray:
        """Internal force density (n_points, 3), N/m^3, at displacement ``u`` (n_points, 3), m."""
        raise NotImplementedError

    def energy_density(self, u: np.ndarray) -> np.ndarray:
        """Strain energy density (n_points,), J/m^3."""
        raise NotImplementedError

    def strain_energy(self, u: np.ndarray) -> float:
        """Total strain energy, J."""
        return float(np.dot(self.energy_density(u), self.body.volumes))

    def stiffness_bound(self) -> np.ndarray:
        """(n_points,) N/m^4: an upper bound of each point's block row sum of the stiffness per volume.

        By the block Gershgorin theorem the largest eigenvalue of M^-1 K is at
        most ``max(stiffness_bound / density)``; for PMB this is the bound of
        Silling and Askari (2005).
        """
        raise NotImplementedError

    def critical_stretch(self, fracture_energy: float) -> float:
        """Critical bond stretch for a fracture energy ``fracture_energy`` (J/m^2)."""
        raise NotImplementedError

    def critical_time_step(
        self, extra_bound: np.ndarray | None = None, points: np.ndarray | None = None
    ) -> float:
        """Largest stable velocity-Verlet step, s: 2 / sqrt(max stiffness_bound / density).

        ``extra_bound`` ((n_points,) N/m^4): stiffness added to the material's (e.g. contact);
        ``points``: take the maximum over these point indices only (e.g. a periodic cell).
        """
        bound = self.stiffness_bound() / self.density
        if extra_bound is not None:
            bound = bound + extra_bound / self.density
        if points is not None:
            bound = bound[points]
        return float(2.0 / np.sqrt(np.max(bound)))
