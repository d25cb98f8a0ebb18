"""Quasi-static stretch by adaptive dynamic relaxation, and the lattice facts behind it."""

import numpy as np
import pytest
from conftest import STEEL_K, STEEL_MU

from peridyn.discretization import geometry
from peridyn.discretization.bonds import find_bonds
from peridyn.physics.loads import BoundaryCondition, Loading
from peridyn.physics.materials import make_model
from peridyn.physics.materials.elastic import bulk_modulus, shear_modulus
from peridyn.physics.timefunctions import Constant
from peridyn.solvers import relax

E_AL, RHO_AL = 70e9, 2700.0


def _apparent_modulus(name, surface_correction="none", partial_volumes=False):
    """Pull a 40 x 10 x 10 mm bar by end forces (uniaxial stress 1 MPa); E = sigma / strain at
    its centre, the strain fitted on the centre line over +-5 mm."""
    h = 1e-3
    body = geometry.box((0.040, 0.010, 0.010), h)
    body = body.with_node_set("left", geometry.face(body, "x-"))
    body = body.with_node_set("right", geometry.face(body, "x+"))
    bonds = find_bonds(body, 3.015 * h, partial_volumes=partial_volumes)
    model = make_model(
        name, body, bonds, E=E_AL, nu=0.25, density=RHO_AL, surface_correction=surface_correction
    )
    sigma, area = 1e6, 0.010 * 0.010
    loading = Loading(
        body,
        [
            BoundaryCondition("left", "force", "x", Constant(-sigma * area)),
            BoundaryCondition("right", "force", "x", Constant(sigma * area)),
        ],
    )
    result = relax(model, loading, tolerance=1e-8)
    assert result.converged
    x = body.points
    line = (np.abs(x[:, 1] - 0.005) < 0.6e-3) & (np.abs(x[:, 2] - 0.005) < 0.6e-3)
    line &= np.abs(x[:, 0] - 0.020) < 5.1e-3
    strain = np.polyfit(x[line, 0], result.u[line, 0], 1)[0]
    return sigma / strain


def test_lps_bar_apparent_modulus():
    """VALIDATION.md: a plain LPS bar (40 x 10 x 10 points, 3.015 dx, neighbours by centre
    distance) has an apparent modulus within 0.6% of E at its centre; the issue asks 2%."""
    assert _apparent_modulus("lps") == pytest.approx(E_AL, rel=0.006)


def test_pmb_bar_with_energy_surface_correction():
    """PMB with the energy surface correction (Madenci and Oterkus 2014): E within 2%."""
    assert _apparent_modulus("pmb", "energy") == pytest.approx(E_AL, rel=0.02)


def test_pmb_surface_correction_matters():
    """Without the correction the same PMB bar is more than 5% too soft (surface points
    miss part of their family), which is why the correction exists."""
    assert _apparent_modulus("pmb") < 0.95 * E_AL


# -- long-wave limits of the LPS lattice (VALIDATION.md, discretisation facts) ----------------


@pytest.mark.parametrize(
    "factor, partial, p_err, s_err",
    [
        (1.4143, False, 0.0, 0.0),
        (2.015, False, 0.034, -0.053),
        (3.015, False, -0.038, 0.054),
        (5.015, False, -0.010, 0.015),
        (2.015, True, 0.007, -0.011),
        (3.015, True, 0.002, -0.003),
    ],
)
def test_lattice_long_wave_speeds(factor, partial, p_err, s_err):
    """Long-wave P (along x) and S speeds of an LPS simple cubic lattice (constant influence, m
    from the discrete family), from the energy of homogeneous uniaxial strain and simple shear
    at an interior point, against VALIDATION.md to 0.2 percentage points. Partial volumes make
    the 2-3 dx lattices accurate, which is why they are the default."""
    h = 1e-3
    n = int(2 * np.ceil(factor) + 4) * 2 + 1
    body = geometry.box((n * h,) * 3, h)
    bonds = find_bonds(body, factor * h, partial_volumes=partial)
    E = 9 * STEEL_K * STEEL_MU / (3 * STEEL_K + STEEL_MU)
    nu = (3 * STEEL_K - 2 * STEEL_MU) / (2 * (3 * STEEL_K + STEEL_MU))
    model = make_model("lps", body, bonds, E=E, nu=nu, density=8000.0)
    centre = np.argmin(np.linalg.norm(body.points - n * h / 2, axis=1))
    eps = 1e-7
    u = np.zeros_like(body.points)
    u[:, 0] = eps * body.points[:, 0]
    w_p = model.energy_density(u)[centre]
    u = np.zeros_like(body.points)
    u[:, 0] = eps * body.points[:, 1]
    w_s = model.energy_density(u)[centre]
    K, mu = bulk_modulus(E, nu), shear_modulus(E, nu)
    p_ratio = np.sqrt(w_p / (0.5 * (K + 4 * mu / 3) * eps**2))
    s_ratio = np.sqrt(w_s / (0.5 * mu * eps**2))
    assert p_ratio - 1 == pytest.approx(p_err, abs=0.002)
    assert s_ratio - 1 == pytest.approx(s_err, abs=0.002)
