"""The material drivers (``PMBModel.force``, ``LPSModel.force``: input normalisation, kernel
choice, the two LPS passes) against the NumPy references of the whole force."""

import numpy as np
import pytest
from conftest import MODEL_CASES, small_model

from peridyn.kernels.reference import lps, pmb, stress
from peridyn.kernels.reference.bond_search import initial_bond_vectors

pytestmark = pytest.mark.kernels


@pytest.mark.parametrize("case", [c for c in MODEL_CASES if c.values[0][0] in ("pmb", "lps")])
def test_kernel_matches_numpy_reference(case, rng):
    """``model.force(u)`` is the reference force of the model's own arrays, float64 (1e-10
    relative: the sums of ~100 bonds round to ~1e-14 of their terms)."""
    name, dim, plane = case
    model = small_model(name, dim, plane, n=8)
    b = model.bonds
    b.intact[rng.random(b.n_bonds) < 0.05] = False  # break some bonds (asymmetrically: fine)
    u = 1e-5 * rng.standard_normal(model.x.shape)
    xi = initial_bond_vectors(model.x, b.offsets, b.neighbours)
    if model.name == "pmb":
        ref = pmb.pmb_force(xi, u, b.offsets, b.neighbours, model.inv_length, model.bond_stiffness, b.intact)
    else:
        ref = lps.lps_force(
            xi,
            u,
            b.offsets,
            b.neighbours,
            model.length,
            model.w,
            model.dev,
            b.intact,
            model.theta_coef,
            model._p_coef,
        )
    got = model.force(u)
    np.testing.assert_allclose(got, ref, rtol=1e-10, atol=1e-12 * np.abs(ref).max())


@pytest.mark.parametrize("surface_correction", ["none", "energy"])
@pytest.mark.parametrize("name", ["pmb", "lps"])
def test_partial_stress_is_the_materials_force_state(name, surface_correction, rng):
    """``model.partial_stress(u)`` (built from the linearisation) is sum_j T_ij (x) xi_ij V_j with
    each material's own force state of its module docstring: PMB T V_j = k e / (2 |xi|) (half the
    pair force), LPS t = w |xi| P_i + alpha_i g_ij w e with P_i = p_coef_i theta_i; 1e-10 of the
    largest entry (sums of ~100 bonds)."""
    model = small_model(name, 3, n=8, surface_correction=surface_correction)
    b = model.bonds
    b.intact[rng.random(b.n_bonds) < 0.05] = False
    u = 1e-5 * rng.standard_normal(model.x.shape)
    n = model.body.n_points
    if name == "pmb":
        axial, owner, p = np.zeros(b.n_bonds), model.bond_stiffness / (2 * b.length), np.zeros(n)
    else:
        w = np.asarray(model.w, dtype=np.float64)
        xi = initial_bond_vectors(model.x, b.offsets, b.neighbours)
        theta = lps.lps_dilatation(xi, u, b.offsets, b.neighbours, b.length, w, b.intact, model.theta_coef)
        axial, owner = w * b.length, model.alpha[b.owners()] * model.dev_factor * w
        p = theta * model._p_coef
    ref = stress.partial_stress(model.x, u, b.offsets, b.neighbours, b.length, axial, owner, b.intact, p)
    got = model.partial_stress(u)
    np.testing.assert_allclose(got, ref, rtol=0, atol=1e-10 * np.abs(ref).max())
