"""Stiffness matrices agree with the force kernels (K u = -V f(u)) and are symmetric."""

import numpy as np
import pytest
from conftest import MATERIALS, MODEL_CASES, small_model

from peridyn.linalg.stiffness import assemble_stiffness, linear_force, mass_matrix, stiffness_operator


def _setup(case, rng, amplitude=1e-9):
    name, dim, plane = case
    model = small_model(name, dim, plane, n=6, horizon_factor=2.015)
    u = amplitude * rng.standard_normal(model.x.shape)
    if dim == 2:
        u[:, 2] = 0.0
    return model, u


@pytest.mark.parametrize("case", MODEL_CASES)
def test_stiffness_is_symmetric_and_matches_the_linear_force(case, rng):
    model, u = _setup(case, rng)
    K = assemble_stiffness(model)
    assert abs(K - K.T).max() <= 1e-14 * abs(K).max()
    vol = np.repeat(model.body.volumes, 3)
    np.testing.assert_allclose(
        K @ u.ravel(),
        -vol * linear_force(model, u).ravel(),
        rtol=1e-10,
        atol=1e-12 * np.abs(K @ u.ravel()).max(),
    )


@pytest.mark.parametrize("case", MODEL_CASES)
def test_stiffness_matches_the_nonlinear_force_for_small_u(case, rng):
    """K u = -V f(u) up to the geometric nonlinearity, O(|u| / h) = 1e-6 here."""
    model, u = _setup(case, rng)
    Ku = assemble_stiffness(model) @ u.ravel()
    f = -np.repeat(model.body.volumes, 3) * model.force(u).ravel()
    assert np.linalg.norm(Ku - f) < 1e-5 * np.linalg.norm(f)


@pytest.mark.parametrize("case", MODEL_CASES)
def test_stiffness_matches_a_finite_difference_jacobian(case, rng):
    model, u = _setup(case, rng, amplitude=0.0)
    K = assemble_stiffness(model).toarray()
    vol = np.repeat(model.body.volumes, 3)
    h = 1e-10
    for dof in (0, 4, 3 * model.body.n_points // 2):
        if model.body.dim == 2 and dof % 3 == 2:
            continue
        du = np.zeros(3 * model.body.n_points)
        du[dof] = h
        fp = model.force(du.reshape(-1, 3)).ravel()
        fm = model.force(-du.reshape(-1, 3)).ravel()
        column = -vol * (fp - fm) / (2 * h)
        np.testing.assert_allclose(K[:, dof], column, rtol=1e-4, atol=1e-6 * np.abs(column).max())


@pytest.mark.parametrize("case", MODEL_CASES)
def test_rigid_motions_are_in_the_null_space(case):
    model, _ = _setup(case, np.random.default_rng(0))
    K = assemble_stiffness(model)
    x = model.body.points - model.body.points.mean(axis=0)
    modes = [np.tile(np.eye(3)[a], (len(x), 1)) for a in range(3)]
    modes += [np.cross(np.eye(3)[a], x) for a in range(3)]
    scale = abs(K).max() * np.abs(x).max()
    for mode in modes:
        assert np.abs(K @ mode.ravel()).max() < 1e-10 * scale


@pytest.mark.parametrize("name", MATERIALS)
def test_operator_equals_matrix_and_mass_is_lumped(name, rng):
    model = small_model(name, 3, n=6, horizon_factor=2.015)
    v = rng.standard_normal(3 * model.body.n_points)
    np.testing.assert_allclose(
        stiffness_operator(model) @ v,
        assemble_stiffness(model) @ v,
        rtol=1e-10,
        atol=1e-10 * np.abs(assemble_stiffness(model) @ v).max(),
    )
    M = mass_matrix(model)
    assert M.diagonal().sum() == pytest.approx(3 * 7850.0 * model.body.volumes.sum(), rel=1e-12)


@pytest.mark.parametrize("case", MODEL_CASES)
def test_split_stiffness_and_augmented_solve_equal_the_assembled_matrix(case, rng):
    """K = P + G^T D G exactly, and the augmented factorisation solves (K + s M) x = b
    (block elimination of y = D G x; see solvers.modal) to round-off."""
    from peridyn.linalg.dofs import free_dofs
    from peridyn.linalg.shift_invert import shifted_inverse
    from peridyn.linalg.stiffness import stiffness_parts

    model, _ = _setup(case, rng)
    parts = stiffness_parts(model)
    K = assemble_stiffness(model)
    dofs = free_dofs(model)
    v = rng.standard_normal(len(dofs))
    Kv = K[dofs][:, dofs] @ v
    np.testing.assert_allclose(parts.restricted(dofs) @ v, Kv, rtol=1e-12, atol=1e-12 * np.abs(Kv).max())
    np.testing.assert_allclose(parts.diagonal(), K.diagonal(), rtol=1e-12)
    sm = 1e-3 * np.median(K.diagonal()[dofs]) * np.ones(len(dofs))
    x = shifted_inverse(parts, dofs, sm, model.body.points, model.bonds.horizon) @ v
    np.testing.assert_allclose(K[dofs][:, dofs] @ x + sm * x, v, rtol=0, atol=1e-9 * np.abs(v).max())
