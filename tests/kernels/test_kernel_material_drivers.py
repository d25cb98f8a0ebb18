"""The material drivers (``PMBModel.force``, ``LPSModel.force``: input normalisation, kernel
choice, the two LPS passes) against the NumPy references of the whole force."""

import numpy as np
import pytest
from conftest import MODEL_CASES, small_model

from peridyn.kernels.reference import lps, pmb

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
    if model.name == "pmb":
        ref = pmb.pmb_force(
            model.x, u, b.offsets, b.neighbours, model.inv_length, model.bond_stiffness, b.intact
        )
    else:
        ref = lps.lps_force(
            model.x,
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
