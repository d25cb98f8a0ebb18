"""Tangent CSR kernel (``peridyn.kernels.tangent``) against its NumPy reference
(``kernels.reference.tangent``)."""

import numpy as np
import pytest
from kernel_inputs import TOL64, assert_close, displacement, family_magnitude, jittered_families, per_bond

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


def test_deformed_bonds(rng):
    """x_j - x_i + u_j - u_i in the order written: the same bits as NumPy's expression."""
    fam = jittered_families(rng)
    u = displacement(rng, fam, 1e-3)
    nbr = fam.nbr.astype(np.int64)
    got = tangent.deformed_bonds(fam.x, u, fam.offsets, nbr, np.empty((fam.n_bonds, 3)))
    np.testing.assert_array_equal(got, ref.deformed_bonds(fam.x, u, fam.offsets, nbr))


def test_tangent_extension_and_action(rng):
    """The two passes of the matrix-free tangent: e and theta, then the bond sums; each value
    is a sum over a family of terms, so the scale is the family's sum of their magnitudes.
    Broken bonds carry zero coefficients (as ``peridyn.linalg.tangent`` passes them)."""
    fam = jittered_families(rng)
    nbr = fam.nbr.astype(np.int64)
    n_vec = rng.standard_normal((fam.n_bonds, 3))
    n_vec /= np.linalg.norm(n_vec, axis=1)[:, None]
    axial = np.where(fam.intact, per_bond(rng, fam, 1e-12), 0.0)
    along = np.where(fam.intact, per_bond(rng, fam, 1e14), 0.0)
    geometric = np.where(fam.intact, 1e11 * rng.standard_normal(fam.n_bonds), 0.0)
    v = displacement(rng, fam, 1e-3)
    e, theta = np.empty(fam.n_bonds), np.empty(fam.n)
    tangent.tangent_extension(fam.offsets, nbr, n_vec, axial, v, e, theta)
    e_ref, theta_ref = ref.tangent_extension(fam.offsets, nbr, n_vec, axial, v)
    reach = np.abs(v).max() * 2 * np.sqrt(3)  # |n . (v_j - v_i)| bound
    assert_close(e, e_ref, TOL64, np.full(fam.n_bonds, reach))
    assert_close(theta, theta_ref, TOL64, family_magnitude(fam.offsets, axial * reach))
    p = 1e22 * rng.standard_normal(fam.n)
    out = np.empty((fam.n, 3))
    tangent.tangent_action(fam.offsets, nbr, n_vec, axial, along, geometric, p, e_ref, v, out)
    expected = ref.tangent_action(fam.offsets, nbr, n_vec, axial, along, geometric, p, e_ref, v)
    owners = np.repeat(np.arange(fam.n), np.diff(fam.offsets))
    terms = np.abs(axial) * (np.abs(p[owners]) + np.abs(p[nbr])) + np.abs(along * e_ref)
    terms = terms + np.abs(geometric) * reach
    assert_close(out, expected, TOL64, family_magnitude(fam.offsets, terms))
