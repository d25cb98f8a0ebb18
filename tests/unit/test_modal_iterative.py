"""LOBPCG eigensolver (solvers.eigen_iterative) against shift-invert, and the automatic choice.

Reference: the shift-invert Lanczos of solvers.modal, itself checked against the independent
assembly of VALIDATION.md V4; issue 9 asks the iterative solver to give the same frequencies
to 1e-6 relative, with every residual ||K x - lambda M x|| / ||K x|| below 1e-6.
"""

import numpy as np
import pytest

from peridyn.discretization import geometry
from peridyn.discretization.bonds import find_bonds
from peridyn.errors import InputError
from peridyn.linalg.dofs import free_dofs
from peridyn.physics.materials import make_model
from peridyn.solvers.modal import modal_analysis

#: PMMA plate of VALIDATION.md V4 (m, Pa, -, kg/m^3); 4 mm spacing keeps it small (600 points).
SIZE, E, NU, RHO = (0.10, 0.05, 0.008), 5.35e9, 0.33, 1200.0


def _plate(spacing=4e-3, horizon=3.001, model="lps"):
    body = geometry.box(SIZE, spacing)
    bonds = find_bonds(body, horizon * spacing, partial_volumes=False)
    return make_model(model, body, bonds, E=E, nu=NU, density=RHO)


@pytest.fixture(scope="module")
def plate_3h():
    model = _plate()
    return model, modal_analysis(model, 12), modal_analysis(model, 12, method="lobpcg")


def test_lobpcg_matches_shift_invert_on_a_free_lps_plate_at_3h(plate_3h):
    """Same elastic frequencies to 1e-6 relative; residuals below 1e-6 (issue 9)."""
    _, direct, iterative = plate_3h
    assert iterative.n_rigid == 6 and direct.n_rigid == 6
    np.testing.assert_allclose(iterative.frequencies[6:], direct.frequencies[6:], rtol=1e-6)
    assert np.all(iterative.residuals < 1e-6)


def test_lobpcg_rigid_modes_are_exact_and_excluded(plate_3h):
    """The six rigid modes come first with |f| far below the elastic ones (K R = 0 up to
    round-off: a rigid motion stretches no bond), and elastic() drops them."""
    _, _, iterative = plate_3h
    assert np.all(iterative.rigid[:6]) and not np.any(iterative.rigid[6:])
    assert np.all(np.abs(iterative.frequencies[:6]) < 1e-6 * iterative.frequencies[6])
    assert np.all(iterative.residuals[:6] < 1e-10)
    assert len(iterative.elastic().frequencies) == 6


def test_lobpcg_modes_are_mass_orthonormal(plate_3h):
    """x_i^T M x_j = delta_ij (the Ritz vectors are M-orthonormal; rigid ones M-normalised)."""
    model, _, iterative = plate_3h
    masses = np.repeat(model.density * model.body.volumes, 3)
    shapes = iterative.shapes.reshape(12, -1)
    gram = shapes @ (masses[:, None] * shapes.T)
    np.testing.assert_allclose(gram, np.eye(12), atol=1e-8)


def test_lobpcg_on_a_clamped_plate_has_no_rigid_mode():
    """A plate clamped at one end (x- face fixed): no rigid motion is allowed, the lowest
    modes are elastic and equal the shift-invert ones to 1e-6."""
    model = _plate(horizon=2.001)
    fixed = np.zeros((model.body.n_points, 3), dtype=bool)
    fixed[geometry.face(model.body, "x-")] = True
    direct = modal_analysis(model, 6, fixed=fixed)
    iterative = modal_analysis(model, 6, fixed=fixed, method="lobpcg")
    assert iterative.n_rigid == 0 and direct.n_rigid == 0
    np.testing.assert_allclose(iterative.frequencies, direct.frequencies, rtol=1e-6)
    assert np.all(iterative.residuals < 1e-6)


def test_block_operator_equals_the_linearised_force_kernel():
    """K applied to a block (linalg.block_operator) equals, column by column, the one-vector
    operator K u = -V f_lin(u) of peridyn.linalg.stiffness, for LPS (plain and with the energy surface
    correction's per-bond deviatoric stiffness) with cut bonds and for PMB."""
    from peridyn.linalg.block_operator import block_stiffness_operator
    from peridyn.linalg.stiffness import stiffness_operator

    rng = np.random.default_rng(1)
    for name, correction in (("lps", "none"), ("lps", "energy"), ("pmb", "none")):
        body = geometry.box((0.012, 0.008, 0.006), 2e-3)
        bonds = find_bonds(body, 3.001 * 2e-3, partial_volumes=False)
        bonds.intact[rng.random(bonds.n_bonds) < 0.1] = False  # any cut: both sides use bonds.intact
        model = make_model(name, body, bonds, E=E, nu=0.25, density=RHO, surface_correction=correction)
        dofs = free_dofs(model)
        block = block_stiffness_operator(model, dofs)
        single = stiffness_operator(model)
        u = rng.standard_normal((len(dofs), 4))
        expected = np.column_stack([single @ col for col in u.T])
        np.testing.assert_allclose(block @ u, expected, rtol=0, atol=1e-12 * np.abs(expected).max())


def test_rigid_body_modes_follow_the_constraints():
    """Six rigid motions for a free 3D body, three (x, y translations, z rotation) for a free
    2D one, one (the rotation about that line) when the points on a line are fixed, two when
    they may slide along it."""
    from peridyn.linalg.amg import rigid_body_modes

    body = geometry.box((0.01, 0.006, 0.004), 2e-3)
    n = body.n_points
    assert rigid_body_modes(body.points, np.arange(3 * n)).shape[1] == 6
    flat = geometry.rectangle(0.01, 0.006, 2e-3, 1e-3)
    dofs_2d = np.flatnonzero(np.tile([True, True, False], flat.n_points))
    assert rigid_body_modes(flat.points, dofs_2d).shape[1] == 3
    x = body.points
    axis = np.isclose(x[:, 1], x[:, 1].min()) & np.isclose(x[:, 2], x[:, 2].min())
    fixed = np.zeros((n, 3), dtype=bool)
    fixed[axis] = True
    modes = rigid_body_modes(x, np.flatnonzero(~fixed.ravel()))
    assert modes.shape[1] == 1
    field = np.zeros(3 * n)
    field[~fixed.ravel()] = modes[:, 0]
    field = field.reshape(n, 3)
    # a rotation about the x-parallel line: no x component, |u| proportional to the distance
    distance = np.hypot(x[:, 1] - x[axis, 1].min(), x[:, 2] - x[axis, 2].min())
    assert np.abs(field[:, 0]).max() < 1e-12
    np.testing.assert_allclose(
        np.linalg.norm(field, axis=1), distance * np.linalg.norm(field[-1]) / distance[-1], atol=1e-12
    )
    fixed[axis, 0] = False  # sliding along the line (x) allowed too
    assert rigid_body_modes(x, np.flatnonzero(~fixed.ravel())).shape[1] == 2


def test_auto_picks_lobpcg_when_the_factor_would_not_fit(monkeypatch):
    """The rule: shift-invert while the estimated factor is within FACTOR_BUDGET and the
    machine's memory share, LOBPCG beyond; a forced shift-invert that cannot fit is refused."""
    import os

    from peridyn.setup import eigensolver as modal_run

    model = _plate(spacing=2e-3, horizon=1.4143)
    assert modal_run.factor_bytes(model) < modal_run.FACTOR_BUDGET
    assert modal_run.choose_eigensolver(model) == "shift-invert"
    monkeypatch.setattr(modal_run, "FACTOR_BUDGET", modal_run.factor_bytes(model) / 2)
    assert modal_run.choose_eigensolver(model) == "lobpcg"
    monkeypatch.undo()
    pages = {"SC_PAGE_SIZE": 4096, "SC_PHYS_PAGES": 64 * 2**20 // 4096}  # a 64 MiB machine
    monkeypatch.setattr(os, "sysconf", lambda key: pages[key])
    assert modal_run.choose_eigensolver(model, "auto") == "lobpcg"
    assert modal_run.choose_eigensolver(model, "lobpcg") == "lobpcg"
    with pytest.raises(InputError, match="use solver.eigensolver lobpcg"):
        modal_run.choose_eigensolver(model, "shift-invert")


def test_unknown_eigensolver_is_refused():
    model = _plate(spacing=8e-3, horizon=1.4143)
    with pytest.raises(InputError, match=r"eigensolver must be one of .* got 'arpack'"):
        modal_analysis(model, 3, method="arpack")
    from peridyn.setup.eigensolver import choose_eigensolver

    with pytest.raises(InputError, match="got 'arpack'"):
        choose_eigensolver(model, "arpack")


def test_case_key_solver_eigensolver():
    """solver.eigensolver accepts auto, shift-invert and lobpcg (default auto), nothing else."""
    from pydantic import ValidationError

    from peridyn.io.case import Solver

    assert Solver(type="modal").eigensolver == "auto"
    assert Solver(type="modal", eigensolver="lobpcg").eigensolver == "lobpcg"
    with pytest.raises(ValidationError):
        Solver(type="modal", eigensolver="arpack")
