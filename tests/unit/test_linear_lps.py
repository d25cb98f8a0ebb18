"""Linear LPS (``linear_lps``, Peridigm's "Linear LPS"): LPS linearised about the reference
configuration (peridyn.physics.materials.linear_lps). Exactly linear, LPS to O(u^2), energy
and stiffness consistent with its force, and bonds break under it as under any material."""

from pathlib import Path

import numpy as np
import pytest
from conftest import small_model

from peridyn.io.case import validate_case
from peridyn.io.exodus import read_exodus
from peridyn.io.peridigm_case import deck_case
from peridyn.io.peridigm_deck import read_deck
from peridyn.jobs.run import run_case
from peridyn.linalg.stiffness import assemble_stiffness

DATA = Path(__file__).parents[1] / "data" / "peridigm"


def _pair():
    """The same 6 x 6 x 6 LPS body (horizon 3.015 spacings, nu = 0.3) as linear_lps and lps,
    and a random displacement pattern of unit size (n_points, 3)."""
    linear, lps = (small_model(n, 3, n=6, nu=0.3) for n in ("linear_lps", "lps"))
    u = np.random.default_rng(7).normal(size=linear.body.points.shape)
    return linear, lps, u


def test_linear_lps_is_exactly_linear():
    """f(2 u) = 2 f(u) and f(u + v) = f(u) + f(v) to round-off (1e-14 of the largest force),
    theta likewise; W(2 u) = 4 W(u)."""
    linear, _, u = _pair()
    v = np.roll(u, 5)
    scale = 1e-3 * linear.body.spacing
    f = linear.force(scale * u)
    top = np.abs(f).max()
    np.testing.assert_allclose(linear.force(2 * scale * u), 2 * f, rtol=0, atol=1e-14 * top)
    np.testing.assert_allclose(
        linear.force(scale * (u + v)), f + linear.force(scale * v), rtol=0, atol=1e-14 * top
    )
    theta = linear.dilatation(scale * u)
    np.testing.assert_allclose(
        linear.dilatation(2 * scale * u), 2 * theta, rtol=0, atol=1e-14 * np.abs(theta).max()
    )
    w = linear.energy_density(scale * u)
    np.testing.assert_allclose(linear.energy_density(2 * scale * u), 4 * w, rtol=1e-14, atol=0)


def test_linear_lps_is_lps_to_second_order():
    """The difference from LPS (exact extension |y| - |xi|) is O(u^2): ten times smaller a
    displacement makes it 100 times smaller (within 2%: the O(u^3) rest; measured 100.0),
    and at strains about 1e-5 it is below 1e-4 of the force (measured 1e-5)."""
    linear, lps, u = _pair()
    errors = []
    for scale in (1e-5, 1e-6):
        s = scale * linear.body.spacing
        errors.append(np.abs(linear.force(s * u) - lps.force(s * u)).max())
    assert errors[0] / errors[1] == pytest.approx(100.0, rel=0.02)
    s = 1e-5 * linear.body.spacing
    assert errors[0] < 1e-4 * np.abs(lps.force(s * u)).max()


def test_linear_lps_energy_and_stiffness_are_its_force():
    """A quadratic energy with f = -grad(E) / V: sum V W(u) = -u . (V f(u)) / 2 (to 1e-12); its
    stiffness matrix is LPS's (the linearisation at the reference, entry for entry) and
    K u = -V f(u) (1e-10 of the largest force, the round-off of the assembly)."""
    linear, lps, u = _pair()
    u = 1e-3 * linear.body.spacing * u
    volume = linear.body.volumes
    f = linear.force(u)
    assert linear.strain_energy(u) == pytest.approx(-0.5 * np.sum(volume[:, None] * f * u), rel=1e-12)
    k_linear, k_lps = assemble_stiffness(linear), assemble_stiffness(lps)
    assert (k_linear != k_lps).nnz == 0
    np.testing.assert_allclose(
        k_linear @ u.ravel(),
        -(volume[:, None] * f).ravel(),
        rtol=0,
        atol=1e-10 * np.abs(volume[:, None] * f).max(),
    )


def test_linear_lps_deck_breaks_bonds(tmp_path):
    """Compression_3x1x1 as a "Linear LPS" deck pulled apart (the end points' initial velocities
    outward) with a Critical Stretch of 1e-7: both bonds break (the deformed length's stretch,
    Peridigm's critical-stretch rule, for any material), after which no force acts: the last
    two recorded velocities are equal and every point's damage is 1. The velocities are compared
    exactly: with every bond broken the force is exactly zero, and a step adds exactly zero to them."""
    deck = read_deck(DATA / "Compression_3x1x1.yaml")
    deck["Materials"]["My Elastic Material"]["Material Model"] = "Linear LPS"
    deck["Blocks"]["My Group of Blocks"]["Damage Model"] = "Stretch"
    deck["Damage Models"] = {"Stretch": {"Damage Model": "Critical Stretch", "Critical Stretch": 1e-7}}
    for name, sign in (("Min X Face", -1.0), ("Max X Face", 1.0)):
        deck["Boundary Conditions"][f"Initial Velocity {name}"]["Value"] = str(sign)
    deck["Output"]["Output Variables"] = {"Velocity": True, "Damage": True}
    case = validate_case(deck_case(deck, "linear", "deck.yaml", DATA))
    assert case.material.model == "linear_lps"
    summary = run_case(case, tmp_path)
    assert summary["broken_bonds"] == summary["bonds"] > 0
    (written,) = tmp_path.glob("*.e")
    result = read_exodus(written)
    assert np.array_equal(result.nodal_variables["VelocityX"][-1], result.nodal_variables["VelocityX"][-2])
    assert np.all(result.element_variables["Damage"][-1] == 1.0)
