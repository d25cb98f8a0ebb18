"""Peridigm's order of operations (``solver.arithmetic: peridigm``, docs/peridigm.md, Rounding)
and the bodies Peridigm's decks may hold (points without bonds)."""

import numpy as np
import pytest

from peridyn.discretization import geometry
from peridyn.discretization.bonds import find_bonds
from peridyn.errors import InputError
from peridyn.physics.loads import InitialCondition, Loading
from peridyn.physics.materials import make_model
from peridyn.solvers import ExplicitSolver

H = 1e-3


def _cube(model="lps"):
    """A 4 x 4 x 4 cube of steel-like LPS (or PMB), families of 2.015 h without partial volumes;
    its upper half thrown at 2 m/s along x, its lower half at rest."""
    body = geometry.box((4 * H, 4 * H, 4 * H), H)
    body = body.with_node_set("upper", body.points[:, 2] > 2 * H)
    bonds = find_bonds(body, 2.015 * H, partial_volumes=False)
    nu = {"lps": 0.3, "pmb": None}[model]
    material = make_model(model, body, bonds, E=200e9, nu=nu, density=7800.0)
    return material, Loading(body, initial=[InitialCondition("upper", "velocity", "x", 2.0)])


def test_peridigm_order_moves_as_peridyns():
    """The two orders compute one LPS force, rounded differently: after 50 steps of a shearing
    cube the displacements agree to 1e-11 of the largest (measured 2.3e-13: roundings of 1e-16
    a step, carried by the dynamics; a wrong force would differ at O(1)), the velocities
    likewise."""
    runs = {}
    for arithmetic in ("peridyn", "peridigm"):
        model, loading = _cube()
        solver = ExplicitSolver(model, loading, dt=2e-8, arithmetic=arithmetic)
        runs[arithmetic] = solver.run(solver.initial_state(), 50)
    a, b = runs["peridyn"], runs["peridigm"]
    assert np.max(np.abs(a.u)) > 1e-8  # the cube has moved and sheared
    assert np.max(np.abs(a.u - b.u)) < 1e-11 * np.max(np.abs(a.u))
    assert np.max(np.abs(a.v - b.v)) < 1e-11 * np.max(np.abs(a.v))


def test_peridigm_order_is_lps_only():
    """A material without Peridigm's force order refuses it, naming the option."""
    model, loading = _cube("pmb")
    solver = ExplicitSolver(model, loading, dt=2e-8, arithmetic="peridigm")
    with pytest.raises(InputError, match="solver.arithmetic: peridigm"):
        solver.initial_state()


def test_lps_points_without_bonds():
    """Points with no neighbour at all (a horizon below the spacing, allowed by ``required=[]``)
    have zero LPS coefficients and no force, at any displacement; a point whose bonds are all
    cut is still refused (its weighted volume is zero but it has a family)."""
    body = geometry.box((3 * H, 2 * H, 2 * H), H)
    bonds = find_bonds(body, 0.4 * H, partial_volumes=False, required=np.zeros(0, dtype=np.int64))
    assert bonds.n_bonds == 0
    model = make_model("lps", body, bonds, E=200e9, nu=0.3, density=7800.0)
    assert np.all(model.alpha == 0.0) and np.all(model.theta_coef == 0.0)
    u = np.random.default_rng(1).standard_normal((body.n_points, 3)) * 1e-6
    assert np.all(model.force(u) == 0.0)
    cut = find_bonds(body, 1.015 * H, partial_volumes=False)
    cut.intact[cut.offsets[0] : cut.offsets[1]] = False
    with pytest.raises(InputError, match="point 0 has no intact bond"):
        make_model("lps", body, cut, E=200e9, nu=0.3, density=7800.0)
