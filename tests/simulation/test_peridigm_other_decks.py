"""Other decks of Peridigm's test suite (tests/data/peridigm_other, sources in its README):
those peridyn runs, each checked against an independent fact of the physics it was built to
verify; the others refused with a CaseFileError naming the deck parameter that peridyn cannot
run, before any mesh is looked for (docs/peridigm.md lists them)."""

import math
from pathlib import Path

import numpy as np
import pytest
from test_peridigm_decks import run_deck

from peridyn.errors import CaseFileError
from peridyn.io.exodus import read_exodus
from peridyn.io.peridigm_case import convert_deck
from peridyn.io.peridigm_deck import read_deck

OTHER = Path(__file__).parents[1] / "data" / "peridigm_other"


def pair_frequency(bulk: float, density: float, length: float) -> float:
    """Angular frequency (rad/s) of the stretch e of two LPS points joined by one bond of
    ``length`` L (m) and nothing else: each has m = L^2 V and dilatation theta = 3 e / L, so
    the deviatoric extension is 0 and the bond's force density on each is 2 (3 K theta L / m) V
    = 18 K e / L^2 (Peridigm's ``computeInternalForceLinearElastic``, omega = 1); the points
    move apart with e'' = -36 K e / (rho L^2)."""
    return math.sqrt(36.0 * bulk / (density * length**2))


def test_bond_breaking_initial_velocity(tmp_path):
    """Peridigm's BondBreakingInitialVelocity (older deck form): two vertical pairs of points,
    L = 1 m apart along y (the box families of horizon 0.51 m reach one cell along y and none
    along x, spacing 1.05 m), pulled apart at +-v. A pair's stretch is e/L = (2 v / omega L)
    sin(omega t): the critical stretch s_c = 0.02 is reached for v > v_c = omega L s_c / 2 =
    244.949 m/s, which the deck brackets with 244.939 m/s (the pair at x = 0.525 m holds) and
    244.959 m/s (the pair at x = 1.575 m breaks at t_b = asin(v_c / v) / omega = 63.8 us, and
    flies apart at sqrt(v^2 - v_c^2), energy conservation).

    Tolerances: Verlet at omega dt = 2.4e-4 has amplitude and phase errors of (omega dt)^2
    ~ 6e-8 relative over the run (rtol 1e-6); the break is found within one step of the
    crossing, in which the speed changes by at most the acceleration at the critical stretch,
    omega^2 L s_c / 2, times dt."""
    deck = read_deck(OTHER / "BondBreakingInitialVelocity.xml")
    material = deck["Materials"]["My Linear Elastic Material"]
    bulk, density = material["Bulk Modulus"], material["Density"]
    stretch = deck["Damage Models"]["My Critical Stretch Damage Model"]["Critical Stretch"]
    dt = deck["Solver"]["Verlet"]["Fixed dt"]
    length = 1.0
    omega = pair_frequency(bulk, density, length)
    v_c = omega * length * stretch / 2
    speeds = {0.525: 244.939, 1.575: 244.959}  # the deck's Initial Velocity values by column x
    assert speeds[0.525] < v_c < speeds[1.575]

    out = read_exodus(run_deck(OTHER / "BondBreakingInitialVelocity.xml", tmp_path))
    t = out.times
    uy, vy = out.nodal_variables["DisplacementY"], out.nodal_variables["VelocityY"]
    damage, theta = out.element_variables["Damage"], out.element_variables["Dilatation"]
    np.testing.assert_allclose(out.element_variables["Weighted_Volume"], length**2 * 1.05, rtol=1e-14)
    x, y = out.coordinates[:, 0], out.coordinates[:, 1]
    for column, v in speeds.items():
        points = np.flatnonzero(np.isclose(x, column))
        sign = np.where(y[points] > 1.0, 1.0, -1.0)  # the upper point moves up
        assert len(points) == 2
        intact = np.ones(len(t), bool) if v < v_c else t < math.asin(v_c / v) / omega
        expected = np.outer((v / omega) * np.sin(omega * t[intact]), np.ones(2))
        np.testing.assert_allclose(uy[intact][:, points] * sign, expected, rtol=1e-6, atol=0)
        np.testing.assert_allclose(theta[intact][:, points], 3 * 2 * expected / length, rtol=1e-6)
        assert np.all(damage[intact][:, points] == 0)
        if v < v_c:
            continue
        assert not intact[-1] and np.all(damage[~intact][:, points] == 1)
        v_free = math.sqrt(v**2 - v_c**2)
        np.testing.assert_allclose(vy[~intact][:, points] * sign, v_free, rtol=0, atol=omega * v_c * dt)


@pytest.mark.parametrize(
    "deck, key, value",
    [
        (
            "LinearLPSBar.yaml",
            "Materials.Linearized LPS Material.Material Model",
            "Linear LPS Partial Volume",
        ),
        ("ElasticBondBased2DPlaneStress.yaml", "Materials.My Elastic Bond Based Material.Plane Stress", None),
    ],
)
def test_other_peridigm_decks_are_refused_by_parameter(deck, key, value):
    with pytest.raises(CaseFileError) as err:
        convert_deck(OTHER / deck)
    assert (err.value.key, err.value.value) == (key, value)
