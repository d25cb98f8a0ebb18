"""The consistent tangent K(u) = -d(V f)/du against finite differences of the force kernels."""

import numpy as np
import pytest
from conftest import MODEL_CASES, small_model

from peridyn.linalg.stiffness import assemble_stiffness
from peridyn.linalg.tangent import tangent_operator, tangent_stiffness


def _deformed(model, rng):
    """A rotation of 0.3 rad about z, stretches of +1% / -0.5% (/ +0.3% in 3D), plus 1 um noise."""
    x = model.body.points
    c, s = np.cos(0.3), np.sin(0.3)
    rotation = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
    stretch = np.diag([1.01, 0.995, 1.003 if model.body.dim == 3 else 1.0])
    u = x @ (rotation @ stretch).T - x + 1e-6 * rng.standard_normal(x.shape)
    if model.body.dim == 2:
        u[:, 2] = 0.0
    return u


@pytest.mark.parametrize("case", MODEL_CASES)
def test_tangent_matches_finite_differences(case, rng):
    """Central differences of -V f(u) (step 1 nm, truncation error ~(1e-9/1e-3)^2) reproduce
    the assembled tangent in a rotated and stretched state to 1e-6 of its largest entry
    (measured: about 1.4e-10): the stretch and geometric terms of the PMB bond block and the
    LPS dilatation term are the exact derivative of the force kernels."""
    name, dim, plane = case
    model = small_model(name, dim, plane, n=5 if dim == 3 else 7)
    u = _deformed(model, rng)
    k = tangent_stiffness(model, u).toarray()
    vol = np.repeat(model.body.volumes, 3)
    eps = 1e-9
    k_fd = np.empty_like(k)
    for col in range(k.shape[1]):
        up, um = u.copy().ravel(), u.copy().ravel()
        up[col] += eps
        um[col] -= eps
        df = model.force(up.reshape(-1, 3)) - model.force(um.reshape(-1, 3))
        k_fd[:, col] = -vol * df.ravel() / (2 * eps)
    assert np.abs(k - k_fd).max() < 1e-6 * np.abs(k).max()


@pytest.mark.parametrize("case", MODEL_CASES)
def test_tangent_at_rest_is_the_linear_stiffness(case):
    """At u = 0 the geometric term vanishes and the tangent equals the linearised stiffness of
    ``assemble_stiffness`` (an independent assembly) to round-off."""
    name, dim, plane = case
    model = small_model(name, dim, plane, n=5 if dim == 3 else 7)
    cut = np.arange(0, model.bonds.n_bonds, 7)
    model.bonds.intact[cut] = False  # broken bonds (both directions) drop out of both
    model.bonds.intact[model.bonds.reverse()[cut]] = False
    k = tangent_stiffness(model, np.zeros_like(model.body.points)).toarray()
    k_lin = assemble_stiffness(model).toarray()
    assert np.abs(k - k_lin).max() < 1e-12 * np.abs(k_lin).max()


@pytest.mark.parametrize("case", MODEL_CASES)
def test_matrix_free_tangent_is_the_assembled_one(case, rng):
    """``tangent_operator`` (two passes over the bonds, nothing assembled) applies the assembled
    tangent restricted to a subset of the dofs, in a rotated and stretched state with broken
    bonds, to round-off (1e-12 of the product's largest entry): the same derivative, summed
    in another order."""
    name, dim, plane = case
    model = small_model(name, dim, plane, n=5 if dim == 3 else 7)
    cut = np.arange(0, model.bonds.n_bonds, 7)
    model.bonds.intact[cut] = False
    model.bonds.intact[model.bonds.reverse()[cut]] = False
    u = _deformed(model, rng)
    dofs = np.flatnonzero(rng.random(3 * model.body.n_points) < 0.8)
    v = rng.standard_normal(len(dofs))
    expected = tangent_stiffness(model, u)[dofs][:, dofs] @ v
    got = tangent_operator(model, u, dofs) @ v
    assert np.abs(got - expected).max() < 1e-12 * np.abs(expected).max()
