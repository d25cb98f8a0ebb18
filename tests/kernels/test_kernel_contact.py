"""Contact kernels (``peridyn.kernels.contact``) against their NumPy references
(``kernels.reference.contact``)."""

import numpy as np
import pytest
from kernel_inputs import SPACING, TOL, assert_close, displacement, jittered_families
from scipy.spatial import cKDTree

from peridyn.kernels import contact
from peridyn.kernels.reference import contact as ref

pytestmark = pytest.mark.kernels


def _pairs(rng):
    """Face-neighbour families (horizon 1.1 spacing, 30 % of bonds broken) and the candidate
    pairs i < j within 1.5 spacings of the deformed positions y = x + u: bonded intact,
    bonded broken and unbonded (diagonal) pairs, some beyond the contact radius."""
    fam = jittered_families(rng, horizon_factor=1.1, broken=0.3, partial_volumes=False)
    y = fam.x + displacement(rng, fam, 0.05)
    pairs = cKDTree(y).query_pairs(1.5 * SPACING, output_type="ndarray")
    pairs = pairs[np.lexsort((pairs[:, 1], pairs[:, 0]))].astype(np.int64)
    return fam, y, pairs[:, 0].copy(), pairs[:, 1].copy()


def test_pair_bond_index(rng):
    """The bond index of each pair, or -1: exact (bonded and unbonded pairs both occur)."""
    fam, _, first, second = _pairs(rng)
    got = contact.pair_bond_index(fam.offsets, fam.nbr, first, second)
    expected = ref.pair_bond_index(fam.offsets, fam.nbr, first, second)
    assert got.dtype == np.int64
    np.testing.assert_array_equal(got, expected)
    assert 0 < np.sum(expected < 0) < len(expected)


@pytest.mark.parametrize("dtype", [np.float64, np.float32])
def test_add_contact_force(rng, dtype):
    """Forces added to a random ``f``, and the number of touching pairs (exact). Each pair
    adds at most c d_c V_max to a point, so a point's sum has the scale |f| + (its pairs)
    c d_c V_max; ``f`` of either dtype (the kernel computes in float64 and rounds each update
    to ``f``'s dtype)."""
    fam, y, first, second = _pairs(rng)
    y[second[0]] = y[first[0]]  # one pair at zero distance: skipped
    bond = ref.pair_bond_index(fam.offsets, fam.nbr, first, second)
    stiffness, radius = 1e20, 1.3 * SPACING
    f0 = (1e20 * SPACING * fam.volumes.max() * rng.standard_normal((fam.n, 3))).astype(dtype)
    f = f0.copy()
    args = (y, first, second, bond, fam.intact, fam.volumes, stiffness, radius)
    touching = contact.add_contact_force(*args, f)
    expected, expected_touching = ref.add_contact_force(*args, f0)
    assert touching == expected_touching > 0
    assert f.dtype == dtype
    pairs_per_point = np.bincount(np.concatenate([first, second]), minlength=fam.n)
    scale = np.abs(f0).max(axis=1) + pairs_per_point * stiffness * radius * fam.volumes.max()
    assert_close(f, expected, TOL[dtype], scale)


def test_largest_squared_move(rng):
    """max_k |u_k - u_ref_k|^2: the same three squares summed (the order may differ by an ulp)."""
    fam = jittered_families(rng)
    u, u_ref = displacement(rng, fam, 1e-3), displacement(rng, fam, 1e-3)
    expected = ref.largest_squared_move(u, u_ref)
    assert contact.largest_squared_move(u, u_ref) == pytest.approx(expected, rel=1e-15)
