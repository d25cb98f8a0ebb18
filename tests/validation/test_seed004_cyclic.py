"""Seed 004 cyclic loading (VALIDATION.md V6; seed Fig. 2b: "skew paths for fatigue observed
at 7 us"), at the seed's spacing and at half of it: the crack leaves the vertical line of the
central crack along skew branches."""

from pathlib import Path

import numpy as np
import pytest

from peridyn.analysis.crack import crack_paths
from peridyn.io.case import load_case
from peridyn.physics.damage import damage_field
from peridyn.setup.build import build
from peridyn.solvers import ExplicitSolver

CASE = Path(__file__).parents[2] / "cases" / "plate2d_cyclic.yaml"


@pytest.mark.parametrize("spacing", [0.125e-3, 0.0625e-3])
def test_cyclic_case_gives_skew_branches(spacing):
    """Skew: paths at least 1 mm long whose start-end line is 45-80 degrees from the load
    axis x (not the straight vertical crack of the stretching case, 90 degrees); branching:
    more than one such path."""
    grip = 4 * spacing  # the five loaded columns at either resolution
    case = load_case(
        CASE,
        [
            f"discretization.spacing={spacing}",
            f"node_sets.left.depth={grip}",
            f"node_sets.right.depth={grip}",
        ],
    )
    setup = build(case)
    solver = ExplicitSolver(
        setup.model, setup.loading, safety=case.solver.safety, damage=setup.damage, contact=setup.contact
    )
    state = solver.initial_state()
    solver.run(state, int(np.ceil(case.solver.time / solver.dt)))
    paths = crack_paths(setup.body.points, damage_field(setup.model), spacing)
    skew = [p for p in paths if p.length_m >= 1e-3 and 45.0 <= abs(p.angle_deg) <= 80.0]
    report = [(round(p.length_m * 1e3, 2), round(p.angle_deg, 1)) for p in paths]
    print(f"spacing {spacing * 1e3} mm: paths (mm, deg) {report}")
    assert len(skew) >= 2, report
