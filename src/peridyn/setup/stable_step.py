"""The explicit stable step of a case estimated without its bonds, for ``peridyn validate``.

The models' bound (``Model.critical_time_step``) is dt = 2 / sqrt(max_i B_i / rho), with B_i
the block-Gershgorin bound of point i's row of the stiffness. For a point of a regular grid
whose whole family is on the grid, B_i depends only on E, nu, the cell, the horizon and the
influence function, so it is summed over the lattice offsets of the family
(``estimate.neighbour_offsets``) by the material class itself
(``Model.family_stiffness_bound``: PMB ``B = 2 sum_j c0 omega_j V_j / |xi_j|``, LPS its
dilatation terms as well).

A body of several blocks (docs/blocks.md) is bounded with the constants of all its materials
(the material takes the largest: E for PMB, mu and K for LPS) and divided by the smallest
density: a point at an interface has bonds of both blocks' constants, and these bound them
all; with blocks of different horizons, the
largest bound over the horizons is taken (an interface between horizons is not estimated:
``validate --build`` computes it).

Plates are summed for every layer (the family cut by the faces) and the largest B taken.
What the lattice cannot see makes the real step shorter: surface corrections (stiffer
bonds near faces), removals and pre-cracks (cut families, larger alpha), text meshes,
contact. On the 20 shipped cases the estimate is the model's step exactly for PMB without
surface correction and 0.93 to 1.115 times it otherwise (LPS with the shear factor on the
three-layer Lamb plates is the low end, PMB with the energy correction the high end), hence
``STEP_MARGIN`` (tests/unit/test_no_silent_acceptance.py checks it on small bodies).
``validate`` refuses a dt above the estimate; ``validate --build`` computes the real bound.
"""

from __future__ import annotations

import itertools

import numpy as np

from peridyn.discretization.bonds import influence_function
from peridyn.io.case import Case
from peridyn.physics.materials.family import PointFamily
from peridyn.setup.estimate import grid_shape, neighbour_offsets

#: The estimate is at most this much longer than ``critical_time_step`` on the shipped cases.
STEP_MARGIN = 0.15


def estimated_stable_step(case: Case, base_dir=".") -> float:
    """Estimated largest stable explicit step of ``case``, s (undamped, without contact)."""
    counts, cell, dim = grid_shape(case, base_dir)
    d, g = case.discretization, case.geometry
    spacing = float(cell[0]) if g.type == "plate" else float(np.max(cell[:dim]))
    default = d.horizon_metres(spacing)
    volume = float(np.prod(cell)) if not g.is_mesh else spacing**3
    bound = 0.0
    for horizon in _horizons(case, default, spacing):
        offsets, factor = neighbour_offsets(counts, cell, horizon, d.partial_volumes, dim)
        for low in itertools.product(*(_positions(offsets[:, a], int(counts[a])) for a in range(3))):
            lo, hi = np.array([p[0] for p in low]), np.array([p[1] for p in low])
            keep = np.all((offsets >= lo) & (offsets <= hi), axis=1)
            bound = max(bound, _row_bound(case, offsets[keep] * cell, factor[keep], horizon, volume, dim))
    density = min(m.density for m in case.block_materials().values())
    return float(2.0 / np.sqrt(bound / density))


def _horizons(case: Case, default: float, spacing: float) -> list[float]:
    """The distinct horizons (m) of the case: ``default``, or those of its blocks."""
    found = {b.horizon_metres(spacing, default) for b in case.blocks.values()}
    return sorted(found) or [default]


def _positions(offsets: np.ndarray, count: int) -> list[tuple[int, int]]:
    """(lowest, highest) offset along one axis that a grid point's family may reach, for
    every distinct position of the point relative to the faces (interior included)."""
    reach = int(np.max(np.abs(offsets))) if len(offsets) else 0
    cuts = range(min(reach, count - 1) + 1)
    limits = {(-min(p, reach), min(count - 1 - p, reach)) for p in cuts}
    limits |= {(-min(count - 1 - p, reach), min(p, reach)) for p in cuts}
    return sorted(limits)


def _row_bound(case: Case, xi_vec: np.ndarray, factor: np.ndarray, horizon, volume, dim) -> float:
    """Block-Gershgorin bound B (N/m^5) of a point whose family has bond vectors ``xi_vec``
    (k, 3) m and volume factors (k,), asked of the case's material class with the constants
    of all its materials (``Model.family_stiffness_bound``)."""
    d, g = case.discretization, case.geometry
    mats = list(case.block_materials().values())
    xi = np.linalg.norm(xi_vec, axis=1)
    w = influence_function(d.influence)(xi, horizon) * volume * factor
    family = PointFamily(
        xi, w, dim, horizon, d.influence, g.plane if dim == 2 else None, g.thickness if dim == 2 else None
    )
    return case.material_class().family_stiffness_bound(family, [m.E for m in mats], [m.nu for m in mats])
