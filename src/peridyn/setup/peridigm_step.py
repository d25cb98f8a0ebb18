"""Peridigm's stable time step of an explicit run (``solver.step_rule: peridigm``).

Peridigm (``PeridigmNS::ComputeCriticalTimeStep``) bounds the Verlet step of every material,
bond-based or not, with the bond-based estimate of Silling and Askari (2005): for each point i
of a block of bulk modulus K (Pa), density rho (kg/m^3) and horizon delta (m),

    dt_i = sqrt(2 rho / sum_j V_j c / |xi_ij|),   c = 18 K / (pi delta^4)

over the points j of its family (V_j their cell volumes, m^3, without partial volumes); a point
without neighbours does not bound the step. Peridigm's source writes pi as 3.14159265, but the
binary that wrote its gold files used pi itself: the output times of its Contact_Cubes test
(the corpus deck on this step, tests/data/peridigm_corpus) are those of pi to 5e-16 s, and
5.5e-10 s off with 3.14159265.
The run's step is the smallest dt_i over the body times ``solver.safety`` (Peridigm's
``Safety Factor``).
"""

from __future__ import annotations

import numpy as np

from peridyn.errors import InputError
from peridyn.io.case import Case
from peridyn.physics.materials.elastic import bulk_modulus
from peridyn.physics.materials.registry import model_class
from peridyn.setup.build import Setup, block_index


def peridigm_stable_step(case: Case, setup: Setup) -> float:
    """The smallest dt_i (s) of the module docstring over the body (under MPI, over every
    rank's owned points). 3D bodies only (Peridigm's estimate is the 3D one)."""
    body, bonds, domain = setup.body, setup.model.bonds, setup.domain
    if body.dim != 3:
        raise InputError("solver.step_rule: peridigm takes Peridigm's 3D stable step; the body is 2D")
    if case.blocks:
        materials = [case.materials[b.material] for b in case.blocks.values()]
        of_point = block_index(case, setup.whole_body)[domain.global_ids]
    else:
        materials, of_point = [case.material], np.zeros(body.n_points, dtype=np.int64)
    nus = [model_class(m.model).implied_poisson_ratio(3) or m.nu for m in materials]  # PMB: 1/4
    bulk = np.array([bulk_modulus(m.E, nu) for m, nu in zip(materials, nus, strict=True)])[of_point]
    density = np.array([m.density for m in materials])[of_point]
    horizon = bonds.horizon if bonds.point_horizon is None else bonds.point_horizon
    spring = 18.0 * bulk / (np.pi * horizon * horizon * horizon * horizon)
    row = np.repeat(np.arange(body.n_points), np.diff(bonds.offsets))
    denominator = np.bincount(
        row, body.volumes[bonds.neighbours] * spring[row] / bonds.length, minlength=body.n_points
    )
    owned = slice(0, domain.n_owned)
    with np.errstate(divide="ignore"):
        step = np.sqrt(2.0 * density[owned] / denominator[owned])
    return float(domain.min(np.min(step, initial=np.inf)))
