"""The half-list PMB force (``kernels.pmb.pmb_pair_force``, each pair once) gives the bits of
the full-list ``pmb_force`` summing in the same row-block order (``discretization.pairs``).

Oracle: ``pmb_force`` with ``split = block_split(...)``, itself checked against the NumPy
reference here (to ``TOL64``, see ``kernel_inputs``). Bit-for-bit equality is the design claim
of ``pmb_pair_force``: each reverse term is the negation of the same rounded product
(``Y_ji = -Y_ij`` exactly), and every row's two chains receive their terms in the full list's
order. The stiffness differs per direction (``k_rev`` != ``k``, as with the neighbour volume in
``k_ij``), and bonds are broken in both directions (as every breaking rule of the package does).
"""

import numpy as np
import pytest
from kernel_inputs import TOL64, assert_close, displacement, family_magnitude, jittered_families, per_bond

from peridyn.discretization.bonds import Bonds
from peridyn.discretization.pairs import block_split, half_list, index_bandwidth, row_blocks
from peridyn.kernels import pmb
from peridyn.kernels.reference import bond_vectors
from peridyn.kernels.reference import pmb as ref
from peridyn.kernels.reference.bond_search import initial_bond_vectors

pytestmark = pytest.mark.kernels


def _bonds(fam, intact) -> Bonds:
    one = np.ones(fam.n_bonds)
    return Bonds(fam.offsets, fam.nbr, fam.length, one, one, intact, 2e-3, "constant")


def _inputs(rng):
    """Families of up to 109 bonds (four chunks) on rows long enough for five blocks."""
    fam = jittered_families(rng, shape=(18, 4, 4), horizon_factor=3.015)
    bonds = _bonds(fam, fam.intact)
    broken = ~fam.intact
    intact = ~(broken | broken[bonds.reverse()])  # a bond breaks in both directions
    u = displacement(rng, fam, 1e-3)
    k = per_bond(rng, fam, 1e14)  # k_ij != k_ji
    xi = initial_bond_vectors(fam.x, fam.offsets, fam.nbr)
    return fam, _bonds(fam, intact), u, k, xi, 1.0 / fam.length


def _pair_force(pairs, u, intact):
    f, h = np.full_like(u, np.nan), np.full_like(u, np.nan)
    args = (pairs.xi, u, pairs.offsets, pairs.neighbours, pairs.inv_len, pairs.k, pairs.k_rev, intact)
    for phase in (0, 1):
        pmb.pmb_pair_force(*args, pairs.intact_at, pairs.blocks, phase, f, h)
    return f


@pytest.mark.bitwise
@pytest.mark.parametrize("n_blocks", [1, 2, 3, 5])
def test_half_list_gives_the_block_order_bits(rng, n_blocks):
    """The half-list PMB force (each bond pair computed once and added to both ends, row block by row
    block) is the full-list kernel's force on the same row blocks, zero signs included, and its stored
    bond vectors are the full list's (the same subtraction). Bit for bit: every point's sum adds the
    same terms in the same order (``peridyn.discretization.pairs``), and the kernels are compiled
    without value-changing fast-math flags (``peridyn.kernels.FASTMATH``), so this holds on every
    CPU."""
    fam, bonds, u, k, xi, inv_len = _inputs(rng)
    bandwidth = index_bandwidth(fam.offsets, fam.nbr)
    assert fam.n >= 5 * bandwidth  # five blocks of at least the bandwidth fit
    blocks = row_blocks(n_blocks * bandwidth + bandwidth // 2, bandwidth)
    blocks[-1] = fam.n  # the last block takes the rest of the rows
    assert len(blocks) == n_blocks + 1
    split = block_split(fam.offsets, fam.nbr, blocks)
    full = pmb.pmb_force(
        xi, u, fam.offsets, fam.nbr, inv_len, k, bonds.intact, np.full_like(u, np.nan), 0, -1, split
    )
    pairs = half_list(bonds, fam.x, inv_len, k, blocks)
    upper = fam.nbr > bonds.owners()
    np.testing.assert_array_equal(pairs.xi, xi[upper])  # the stored vectors' subtraction
    half = _pair_force(pairs, u, bonds.intact)
    np.testing.assert_array_equal(half.view(np.int64), full.view(np.int64))  # zero signs too


def test_block_order_matches_the_reference(rng):
    fam, bonds, u, k, xi, inv_len = _inputs(rng)
    blocks = row_blocks(fam.n, index_bandwidth(fam.offsets, fam.nbr))
    split = block_split(fam.offsets, fam.nbr, blocks)
    assert np.any(split > fam.offsets[:-1])  # some rows have two chains
    got = pmb.pmb_force(
        xi, u, fam.offsets, fam.nbr, inv_len, k, bonds.intact, np.full_like(u, np.nan), 0, -1, split
    )
    expected = ref.pmb_force(xi, u, fam.offsets, fam.nbr, inv_len, k, bonds.intact)
    _, _, y = bond_vectors(fam.x, u, fam.offsets, fam.nbr)
    scale = family_magnitude(fam.offsets, bonds.intact * k * inv_len * np.linalg.norm(y, axis=1))
    assert_close(got, expected, TOL64, scale)


@pytest.mark.bitwise
def test_row_bounds_keep_the_block_order(rng):
    """An MPI rank's two row-bounded calls give the rows of one whole call. A row's sum is the same
    operations in the same order whichever call computes it, and the kernels are compiled without
    value-changing fast-math flags (``peridyn.kernels.FASTMATH``), so this holds on every CPU."""
    fam, bonds, u, k, xi, inv_len = _inputs(rng)
    split = block_split(fam.offsets, fam.nbr, row_blocks(fam.n, index_bandwidth(fam.offsets, fam.nbr)))
    args = (xi, u, fam.offsets, fam.nbr, inv_len, k, bonds.intact)
    whole = pmb.pmb_force(*args, np.full_like(u, np.nan), 0, -1, split)
    parts = np.full_like(u, np.nan)
    pmb.pmb_force(*args, parts, 0, fam.n // 3, split)
    pmb.pmb_force(*args, parts, fam.n // 3, fam.n, split)
    np.testing.assert_array_equal(parts, whole)
