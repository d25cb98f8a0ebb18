"""The family of one point of a regular lattice, as a material sees it before any body exists.

What a material class answers from it (``Model.plane_wave_coefficients``,
``Model.family_stiffness_bound``): the plane-wave dispersion of an infinite medium
(``peridyn.analysis.dispersion``) and the continuum stable step that ``peridyn validate``
estimates from a case alone (``peridyn.setup.stable_step``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class PointFamily:
    """The bonds of one point: their lengths and weights, with the lattice's description.

    Attributes
    ----------
    length : (n,) float64, m
        ``|xi|`` of each bond.
    weight : (n,) float64, m^3 (3D; a 2D family's volumes include its thickness; m^2 in 1D)
        ``omega(|xi|) V``: the influence function times the neighbour's volume (times its
        partial-volume factor, or the quadrature weight of a continuous family).
    dim : {1, 2, 3}
    horizon : float, m
    influence : str
        Name of the influence function (``discretization.bonds.influence_function``).
    plane : {"stress", "strain"} or None
        2D only.
    thickness : float or None, m
        Out-of-plane thickness of a 2D family.
    """

    length: np.ndarray
    weight: np.ndarray
    dim: int
    horizon: float
    influence: str
    plane: str | None = None
    thickness: float | None = None
