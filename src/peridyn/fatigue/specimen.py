"""Stress intensity of the modelled specimen from its own compliance (a check of eq. 7.12).

The Paris slope of a fatigue run is only m_II if the dK it is plotted against is the specimen's.
Eqs. 7.12-7.13 (K = sigma sqrt(pi a) F(a/b)) hold for a single-edge-notch strip loaded far from
the crack plane; this module measures K(a) of the discretised specimen under its own loads:
straight cracks of length a are cut, the linear equilibrium at the load is solved, and at fixed
load the energy release rate is G = dU/da / t with U = f . u / 2 (the complementary energy, Irwin
and Kies' compliance method), K = sqrt(E' G) (E' = E in plane stress).
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from peridyn.discretization.bonds import both_copies, crossing_rectangle, crossing_segment
from peridyn.errors import InputError
from peridyn.fatigue.statics import LinearStatics
from peridyn.physics.loads import Loading
from peridyn.physics.materials.base import Model


def compliance_energy(
    model: Model, loading: Loading, crack_lengths, cut: Callable[[float], np.ndarray], time: float = 1.0
) -> np.ndarray:
    """Complementary energy U(a) = f . u / 2 (J) at each crack length (m).

    Parameters
    ----------
    crack_lengths : (n,) crack lengths a, m, increasing
    cut : a -> (n_bonds,) bool, the bonds a straight crack of length a cuts (on top of the bonds
        already broken, which stay broken)
    time : s, the loads are evaluated at this time
    """
    a = np.asarray(crack_lengths, dtype=float)
    if a.size < 3 or np.any(np.diff(a) <= 0):
        raise InputError("compliance K needs at least 3 increasing crack lengths")
    intact = model.bonds.intact
    start = intact.copy()
    reverse = model.bonds.reverse()
    statics = LinearStatics(model, loading, time, "direct")
    energy = np.empty(a.size)
    try:
        for i, length in enumerate(a):
            intact[:] = start & ~both_copies(cut(length), reverse)
            energy[i] = 0.5 * statics.force @ statics.solve().ravel()
    finally:
        intact[:] = start
    return energy


def compliance_stress_intensity(crack_lengths, energy, thickness: float, modulus: float) -> np.ndarray:
    """K_I (Pa m^0.5) at each crack length from U(a): G = dU/da / thickness, K = sqrt(modulus G).

    Parameters
    ----------
    crack_lengths, energy : (n,) m and J, from ``compliance_energy``
    thickness : m, the crack front length
    modulus : Pa, E' (E in plane stress, E / (1 - nu^2) in plane strain)
    """
    a = np.asarray(crack_lengths, dtype=float)
    g = np.gradient(np.asarray(energy, dtype=float), a) / thickness
    if np.any(g < 0):
        raise InputError("compliance K: the energy fell with crack length (loads not fixed?)")
    return np.sqrt(modulus * g)


def straight_crack_cut(
    points: np.ndarray, spacing: float, bonds, precrack, axis: int
) -> Callable[[float], np.ndarray]:
    """The pre-crack ``precrack`` (a case's rectangle or segment) lengthened along ``axis`` (0, 1, 2):
    a -> (n_bonds,) bool, the bonds crossing it when it runs to length a (m) from the body's low
    edge (its outermost points minus half a spacing, as ``crack_tip`` measures).
    """
    owners, neighbours = bonds.owners(), bonds.neighbours
    x_from, x_to = points[owners], points[neighbours]
    low = points[:, axis].min() - 1.0  # 1 m beyond the edge: the crack starts outside the body
    unit = np.eye(3)[axis]
    edge = points[:, axis].min() - 0.5 * spacing
    if precrack.type == "rectangle":
        origin = np.array(precrack.origin, dtype=float)
        origin[axis] = low
        other = np.array(precrack.edge_v, dtype=float)

        def cut(a):
            return crossing_rectangle(x_from, x_to, origin, unit * (edge + a - low), other)
    else:
        start = np.zeros(3)
        start[: len(precrack.start)] = precrack.start
        start[axis] = low

        def cut(a):
            return crossing_segment(x_from, x_to, start, start + unit * (edge + a - low))

    return cut
