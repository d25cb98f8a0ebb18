"""Crack-tip damage threshold against the horizon (``fatigue/tip.py``, cases/dogbone_fatigue.yaml).

Thesis seed 002, section 7.2: the tip is where every point through the depth has phi >= 0.385.
Closed form on a cubic grid: a point beside a plane that separates the body fully loses the bonds
that cross the plane, 47 of its 122 at a horizon of 3.001 spacings (0.385, the thesis's horizon
and threshold) but 5 of its 18 at 1.5001 spacings (0.278). So the dog-bone case, at 1.5001
spacings, uses 0.277: the same criterion (a clean crack face) at its horizon.
"""

from pathlib import Path

import numpy as np
import pytest

from peridyn.discretization import geometry
from peridyn.discretization.bonds import find_bonds
from peridyn.fatigue.tip import TIP_DAMAGE, crack_tip
from peridyn.io.case import load_case
from peridyn.physics.damage import damage_field
from peridyn.physics.materials import make_model

CASE = Path(__file__).resolve().parents[2] / "cases" / "dogbone_fatigue.yaml"
SPACING = 1e-3


def _cut_block(horizon: float):
    """12 x 12 x 8 points, LPS, every bond crossing the plane x = 6 mm broken (a clean crack through
    the whole y-z section): (points, damage)."""
    body = geometry.box((0.012, 0.012, 0.008), SPACING)
    bonds = find_bonds(body, horizon * SPACING, partial_volumes=False)  # as the case
    model = make_model("lps", body, bonds, E=189.9e9, nu=0.3, density=7850.0)
    x = body.points
    xi, xj = x[bonds.owners(), 0], x[bonds.neighbours, 0]
    bonds.intact[(np.minimum(xi, xj) < 0.006) & (np.maximum(xi, xj) > 0.006)] = False
    return x, damage_field(model)


@pytest.mark.parametrize("horizon, crossing", [(3.001, 47 / 122), (1.5001, 5 / 18)])
def test_damage_beside_a_clean_cut_is_the_share_of_bonds_crossing_it(horizon, crossing):
    """Interior points next to the cut plane (not near the outer faces) have phi = crossing share."""
    x, phi = _cut_block(horizon)
    inner = np.all((x[:, 1:] > 3.4 * SPACING) & (x[:, 1:] < np.array([0.012, 0.008]) - 3.4 * SPACING), axis=1)
    beside = inner & (np.abs(x[:, 0] - 0.006) < 0.6 * SPACING)
    assert beside.sum() > 0
    np.testing.assert_allclose(phi[beside], crossing, rtol=1e-9)


def test_dogbone_tip_threshold_sees_a_clean_crack_at_its_horizon():
    """With the case's horizon (1.5001 spacings) a through crack is invisible to the thesis's 0.385
    (length 0) and found by the case's tip.damage (the cut columns are cracked through the depth;
    the cut runs along y here, so along x the tip is the cut plane, 6 mm from the low edge)."""
    case = load_case(CASE)
    assert case.discretization.horizon == pytest.approx(1.5001)
    threshold = case.fatigue.tip.damage
    assert threshold < 5 / 18 < TIP_DAMAGE
    x, phi = _cut_block(case.discretization.horizon)
    assert crack_tip(x, phi, SPACING, "x", "z", TIP_DAMAGE) == 0.0
    assert crack_tip(x, phi, SPACING, "x", "z", threshold) == pytest.approx(0.0065, abs=1e-9)
