"""Critical bond stress criterion (peridyn.physics.damage): sigma_b = E s, so s_c = sigma_u / E."""

import numpy as np
import pytest

from peridyn.discretization import geometry
from peridyn.discretization.bonds import find_bonds
from peridyn.errors import CaseFileError, InputError
from peridyn.io.case import validate_case
from peridyn.physics.damage import BondDamage, stretch_from_bond_stress
from peridyn.physics.materials.pmb import PMBModel


def small_model():
    body = geometry.rectangle(0.004, 0.002, spacing=0.5e-3, thickness=1e-3, plane="stress")
    bonds = find_bonds(body, 3.015 * body.spacing)
    return PMBModel(body, bonds, E=70e9, density=2100)


def test_seed004_stress_is_critical_stretch_over_E():
    """Seed 004: 40 MPa with E = 70 GPa -> s_c = 40e6 / 70e9 = 5.714e-4 (closed form)."""
    damage = BondDamage(small_model(), critical_bond_stress=40e6)
    assert damage.value == pytest.approx(40e6 / 70e9, rel=1e-12)


def test_bonds_break_exactly_when_uniaxial_stress_passes_the_ultimate():
    """A uniaxial strain eps along x stretches the x-bonds by eps: E eps is their bond stress.
    Just below 40 MPa no bond breaks, just above the bonds along x do (and only bonds whose
    stretch E s exceeds 40 MPa). Booleans, compared exactly: the bonds along x are 1% above the
    threshold and every other bond well below it, far beyond rounding."""
    model = small_model()
    x = model.body.points
    for factor, expect_broken in ((0.99, False), (1.01, True)):
        model.bonds.intact[:] = True
        damage = BondDamage(model, critical_bond_stress=40e6)
        u = np.zeros_like(x)
        u[:, 0] = factor * 40e6 / 70e9 * x[:, 0]
        broken = damage.update(u)
        assert (broken > 0) is expect_broken
        if expect_broken:
            b = model.bonds
            xi = x[b.neighbours] - x[b.owners()]
            stretch = (np.linalg.norm(xi + u[b.neighbours] - u[b.owners()], axis=1) - b.length) / b.length
            np.testing.assert_array_equal(~b.intact, 70e9 * stretch > 40e6)


@pytest.mark.parametrize(
    "kwargs",
    [
        {},
        {"critical_stretch": 1e-3, "critical_bond_stress": 40e6},
        {"fracture_energy": 1e3, "critical_bond_stress": 40e6},
    ],
)
def test_exactly_one_criterion(kwargs):
    with pytest.raises(
        InputError, match="exactly one of critical_stretch, fracture_energy or critical_bond_stress"
    ):
        BondDamage(small_model(), **kwargs)


def test_non_positive_stress_refused():
    with pytest.raises(InputError, match="critical_bond_stress must be positive, got -1"):
        stretch_from_bond_stress(-1.0, 70e9)


def _raw(damage):
    return {
        "name": "d",
        "geometry": {"type": "rectangle", "size": [0.004, 0.002], "thickness": 1e-3},
        "discretization": {"spacing": 0.5e-3, "horizon": 3.015},
        "material": {"model": "pmb", "E": 70e9, "density": 2100, "damage": damage},
        "solver": {"type": "explicit", "steps": 1},
    }


def test_case_key_and_errors():
    case = validate_case(_raw({"critical_bond_stress": 40e6}))
    assert case.material.damage.critical_bond_stress == 40e6
    with pytest.raises(CaseFileError, match="give exactly one of critical_stretch, fracture_energy"):
        validate_case(_raw({"critical_bond_stress": 40e6, "critical_stretch": 1e-3}))
    with pytest.raises(CaseFileError, match="critical_bond_stress"):
        validate_case(_raw({"critical_bond_stress": -5.0}))


def test_breaking_kernel_breaks_exactly_the_bonds_a_direct_stretch_count_breaks():
    """Definition of critical-stretch breaking: bond i->j breaks iff |xi + u_j - u_i| / |xi| - 1
    exceeds s_c, both directed copies together, protected bonds never. Compared with numpy on
    random displacements (bonds within 1e-9 of the threshold left out of the comparison). Booleans,
    compared exactly: the bonds compared are 1e-9 or more from the threshold, far beyond rounding."""
    model = small_model()
    b = model.bonds
    rng = np.random.default_rng(7)
    u = rng.normal(scale=2e-7, size=(model.body.n_points, 3))
    u[:, 2] = 0.0
    damage = BondDamage(model, critical_stretch=2e-4)
    owners = b.owners()
    protected = np.zeros(model.body.n_points, dtype=bool)
    protected[::7] = True  # as a no-damage node set: both copies of a bond protected
    damage.breakable &= ~(protected[owners] | protected[b.neighbours])
    y = model.body.points[b.neighbours] + u[b.neighbours] - model.body.points[owners] - u[owners]
    stretch = np.linalg.norm(y, axis=1) / b.length - 1.0
    expected = ~((stretch > 2e-4) & damage.breakable)
    broken = damage.update(u)
    clear = np.abs(stretch - 2e-4) > 1e-9
    assert broken == int((~b.intact).sum())
    np.testing.assert_array_equal(b.intact[clear], expected[clear])
    assert 0 < broken < b.n_bonds
    np.testing.assert_array_equal(b.intact, b.intact[b.reverse()])
