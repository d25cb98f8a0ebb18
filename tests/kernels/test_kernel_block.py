"""Block kernels (``peridyn.kernels.block``: k displacement fields at once) against their NumPy
references (``kernels.reference.block``), float64 (the block operator's dtype).

Tolerances: see ``kernel_inputs``; no cancellation beyond the sums themselves, so the scale
is the sum of the magnitudes of the summed terms.
"""

import numpy as np
import pytest
from kernel_inputs import SPACING, TOL64, assert_close, jittered_families, per_bond

from peridyn.kernels import block
from peridyn.kernels.reference import block as ref
from peridyn.kernels.reference import family_sum, owners

pytestmark = pytest.mark.kernels

#: Number of displacement fields of the block.
K = 3


def test_block_extension(rng):
    """e_b = n . (u_j - u_i) per field for intact bonds, exactly 0 for broken ones."""
    fam = jittered_families(rng)
    u = 1e-3 * SPACING * rng.standard_normal((fam.n, 3, K))
    args = (fam.x, u, fam.offsets, fam.nbr, fam.length, fam.intact)
    got = block.block_extension(*args, np.full((fam.n_bonds, K), np.nan))
    assert np.all(got[~fam.intact] == 0.0)
    moved = np.linalg.norm(u[fam.nbr] - u[owners(fam.offsets)], axis=1)  # (n_bonds, K)
    assert_close(got, ref.block_extension(*args), TOL64, moved)


def test_block_family_sum(rng):
    """sum_b weight_b e_b over each family, per field."""
    fam = jittered_families(rng)
    weight = rng.standard_normal(fam.n_bonds)
    e = rng.standard_normal((fam.n_bonds, K))
    got = block.block_family_sum(fam.offsets, weight, e, np.full((fam.n, K), np.nan))
    scale = family_sum(fam.offsets, np.abs(weight[:, None] * e))
    assert_close(got, ref.block_family_sum(fam.offsets, weight, e), TOL64, scale)


@pytest.mark.parametrize("model", ["lps", "pmb"])
def test_block_bond_force(rng, model):
    """f_i = sum_j [axial (P_i + P_j) + extension_coef e] n over intact bonds, per field (PMB:
    axial = 0)."""
    fam = jittered_families(rng)
    e = 1e-6 * rng.standard_normal((fam.n_bonds, K))
    axial = per_bond(rng, fam, fam.length.mean()) if model == "lps" else np.zeros(fam.n_bonds)
    coef = per_bond(rng, fam, 1e14)
    p = 1e8 * rng.standard_normal((fam.n, K))
    args = (fam.x, e, fam.offsets, fam.nbr, fam.length, axial, coef, fam.intact, p)
    got = block.block_bond_force(*args, np.full((fam.n, 3, K), np.nan))
    pair = np.abs(p[owners(fam.offsets)]) + np.abs(p[fam.nbr])
    terms = fam.intact[:, None] * (axial[:, None] * pair + np.abs(coef[:, None] * e))
    scale = family_sum(fam.offsets, terms)[:, None, :]  # (n, 1, K): the same for the 3 components
    assert_close(got, ref.block_bond_force(*args), TOL64, np.broadcast_to(scale, got.shape))
