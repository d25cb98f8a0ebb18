"""Kalthoff-Winkler impact (VALIDATION.md V7): the cracks leave the notch tips at 70 +/- 5
degrees to the notch direction (experiments, Kalthoff and Winkler 1987: about 70 degrees;
peridynamic models 65-70 degrees, Silling 2003). The 2D plane-strain case meets it at 0.5 mm;
the 3D case at the 1.25 mm it can afford here leaves at 62 degrees (docs/fracture.md), so its
test asserts what holds at that resolution."""

from pathlib import Path

import numpy as np
import pytest

from peridyn.analysis.crack import crack_paths, departure_angle, path_from
from peridyn.io.case import load_case
from peridyn.physics.damage import damage_field
from peridyn.setup.build import build
from peridyn.solvers import ExplicitSolver

CASE = Path(__file__).parents[2] / "cases" / "kalthoff_winkler.yaml"
CASE_3D = Path(__file__).parents[2] / "cases" / "kalthoff_winkler_3d.yaml"
# notch tips (m); the notches run along +x from the struck edge x = 0
TIPS = {"upper": np.array([0.050, 0.125]), "lower": np.array([0.050, 0.075])}
INITIAL_RUN = 0.030  # m: the crack's direction is fitted over its first 30 mm


def run_case_file(case_file, overrides=()):
    """Body and final damage index of a Kalthoff-Winkler case run to its end time."""
    case = load_case(case_file, overrides)
    setup = build(case)
    solver = ExplicitSolver(setup.model, setup.loading, safety=case.solver.safety, damage=setup.damage)
    state = solver.initial_state()
    solver.run(state, int(np.ceil(case.solver.time / solver.dt)))
    return setup.body, damage_field(setup.model)


def departure_angles(points, phi, spacing) -> dict:
    """Angle (deg) at which the longest crack ending within 3 spacings of each notch tip leaves
    it, fitted over its first INITIAL_RUN; None where no crack of that length leaves a tip."""
    paths = crack_paths(points, phi, spacing)
    angles = {}
    for name, tip in TIPS.items():
        crack = path_from(paths, tip, 3 * spacing)
        long_enough = crack is not None and crack.length_m > INITIAL_RUN
        angles[name] = departure_angle(crack, tip, INITIAL_RUN) if long_enough else None
    return angles


@pytest.mark.slow
def test_cracks_leave_notch_tips_at_seventy_degrees():
    body, phi = run_case_file(CASE)
    angles = departure_angles(body.points, phi, body.spacing)
    assert angles["upper"] == pytest.approx(70.0, abs=5.0)
    assert angles["lower"] == pytest.approx(-70.0, abs=5.0)


@pytest.mark.slow
def test_3d_cracks_leave_both_notch_tips_alike_through_the_thickness():
    """3D plate (9 mm, 7 layers, 1.25 mm; about 5 min and 1.6 GB). Physical facts of the run:
    the loading is symmetric about the centre line, so the two cracks leave their tips at
    mirror angles (measured 62.2 and -61.5 deg on the mid layer: within 2 deg); the angle is
    that of a shear-driven (mode II loaded) notch, between 55 and 80 deg (Kalthoff and
    Winkler 1987 report 70 deg; the 3D run at 1.25 mm gives 62, the 2D one at 1.25 mm 63);
    and the crack runs straight through the thickness, every layer within 2 deg of the mid
    layer (measured spread 0.6 deg). The 70 +/- 5 deg of V7 is met by the 2D case only."""
    body, phi = run_case_file(CASE_3D)
    layers = int(body.layer_index.max()) + 1
    per_layer = []
    for k in range(layers):
        on_layer = body.layer_index == k
        per_layer.append(departure_angles(body.points[on_layer], phi[on_layer], body.spacing))
    mid = per_layer[layers // 2]
    assert 55.0 <= mid["upper"] <= 80.0
    assert -80.0 <= mid["lower"] <= -55.0
    assert mid["upper"] + mid["lower"] == pytest.approx(0.0, abs=2.0)
    for angles in per_layer:
        assert angles["upper"] == pytest.approx(mid["upper"], abs=2.0)
        assert angles["lower"] == pytest.approx(mid["lower"], abs=2.0)
