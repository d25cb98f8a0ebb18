"""Tangent CSR kernel (``peridyn.kernels.tangent``) against its NumPy reference
(``kernels.reference.tangent``)."""

import numpy as np
import pytest
from kernel_inputs import TOL64, assert_close, jittered_families

from peridyn.kernels import tangent
from peridyn.kernels.reference import family_sum
from peridyn.kernels.reference import tangent as ref

pytestmark = pytest.mark.kernels


def test_bond_blocks_csr(rng):
    """Structure (indptr, indices: exact, int64) and values: entry (3 i + a, .) sums at
    most the blocks B_b of i's bonds, each of entries below |stretch_b| + |geometric_b|, so
    the scale of row 3 i + a is the family sum of those; broken bonds carry zero
    coefficients (as ``peridyn.linalg.tangent`` passes them)."""
    fam = jittered_families(rng)
    n_vec = rng.standard_normal((fam.n_bonds, 3))
    n_vec /= np.linalg.norm(n_vec, axis=1)[:, None]
    stretch = np.where(fam.intact, rng.uniform(0.5, 1.5, fam.n_bonds) * 1e14, 0.0)
    geometric = np.where(fam.intact, 1e11 * rng.standard_normal(fam.n_bonds), 0.0)
    nbr = fam.nbr.astype(np.int64)
    indptr, indices, data = tangent.bond_blocks_csr(fam.offsets, nbr, n_vec, stretch, geometric)
    expected_indptr, expected_indices, expected_data = ref.bond_blocks_csr(
        fam.offsets, nbr, n_vec, stretch, geometric
    )
    assert indptr.dtype == indices.dtype == np.int64
    np.testing.assert_array_equal(indptr, expected_indptr)
    np.testing.assert_array_equal(indices, expected_indices)
    row_scale = np.repeat(family_sum(fam.offsets, np.abs(stretch) + np.abs(geometric)), 3)
    assert_close(data, expected_data, TOL64, np.repeat(row_scale, np.diff(indptr)))
