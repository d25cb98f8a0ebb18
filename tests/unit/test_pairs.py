"""Row blocks, family splits and the half list (``discretization.pairs``), and the PMB model's
float64 force through them: the half list where it applies, the same bits as the full list.

Sources: the definitions in ``discretization.pairs`` (a block is at least the index bandwidth
long, so a row's neighbours are in its own block or the ones beside it; a family's ``h`` chain
is the neighbours in earlier blocks) and ``kernels.pmb.pmb_pair_force``'s claim that it gives
``pmb_force``'s bits in that order.
"""

from dataclasses import replace

import numba
import numpy as np
import pytest

from peridyn.discretization import geometry
from peridyn.discretization.bonds import find_bonds, reorder_bonds
from peridyn.discretization.pairs import block_split, half_list, index_bandwidth, row_blocks
from peridyn.physics.materials import make_model

SPACING = 1e-3


def _plate(shape=(24, 8, 3), horizon_factor=3.015):
    body = geometry.box(tuple(k * SPACING for k in shape), SPACING)
    return body, find_bonds(body, horizon_factor * SPACING)


@pytest.mark.parametrize("n_points, bandwidth", [(100, 7), (100, 50), (100, 51), (10, 30), (64, 0)])
def test_row_blocks_are_at_least_the_bandwidth_and_cover_the_rows(n_points, bandwidth):
    blocks = row_blocks(n_points, bandwidth)
    assert blocks[0] == 0 and blocks[-1] == n_points
    sizes = np.diff(blocks)
    assert len(sizes) == max(1, n_points // max(bandwidth, 1))
    assert np.all(sizes >= min(bandwidth, n_points)) and sizes.max() - sizes.min() <= 1


def test_split_ends_each_family_where_its_neighbours_leave_earlier_blocks():
    body, bonds = _plate()
    blocks = row_blocks(body.n_points, index_bandwidth(bonds.offsets, bonds.neighbours))
    assert len(blocks) > 3
    split = block_split(bonds.offsets, bonds.neighbours, blocks)
    start = blocks[np.searchsorted(blocks, np.arange(body.n_points), side="right") - 1]
    for i in range(body.n_points):
        fam = bonds.neighbours[bonds.offsets[i] : bonds.offsets[i + 1]]
        cut = split[i] - bonds.offsets[i]
        assert np.all(fam[:cut] < start[i]) and np.all(fam[cut:] >= start[i])


def test_a_rank_part_gets_the_whole_bodys_split_from_its_global_rows():
    """Rows in another order (a rank's part): the split from the global row numbers is the
    whole body's, row by row, and so is the bandwidth. Indices: compared exactly."""
    body, bonds = _plate()
    blocks = row_blocks(body.n_points, index_bandwidth(bonds.offsets, bonds.neighbours))
    order = np.random.default_rng(0).permutation(body.n_points)
    part = reorder_bonds(bonds, order, body.n_points)
    assert index_bandwidth(part.offsets, part.neighbours, order) == index_bandwidth(
        bonds.offsets, bonds.neighbours
    )
    whole = block_split(bonds.offsets, bonds.neighbours, blocks)
    got = block_split(part.offsets, part.neighbours, blocks, order)
    np.testing.assert_array_equal(got - part.offsets[:-1], (whole - bonds.offsets[:-1])[order])


def test_families_out_of_order_get_one_chain_and_no_half_list():
    body, bonds = _plate()
    n = body.n_points
    blocks = row_blocks(n, index_bandwidth(bonds.offsets, bonds.neighbours))
    perm = np.arange(bonds.n_bonds)
    for i in range(n):  # reverse each family
        perm[bonds.offsets[i] : bonds.offsets[i + 1]] = perm[bonds.offsets[i] : bonds.offsets[i + 1]][::-1]
    backwards = replace(bonds, neighbours=bonds.neighbours[perm], length=bonds.length[perm])
    assert block_split(backwards.offsets, backwards.neighbours, blocks) is None
    k = np.ones(bonds.n_bonds)
    assert half_list(backwards, body.points, 1.0 / backwards.length, k, blocks) is None
    assert half_list(bonds, body.points, 1.0 / bonds.length, k, blocks) is not None


@pytest.mark.bitwise
def test_pmb_force_uses_the_half_list_and_gives_the_full_lists_bits():
    """``PMBModel.force`` of a whole body takes the half list and gives the full-list kernel's force bit
    for bit, on one thread and on any number: every point's sum adds the same terms in the same order,
    and the kernels are compiled without value-changing fast-math flags (``peridyn.kernels.FASTMATH``),
    so this holds on every CPU."""
    body, bonds = _plate((30, 6, 3))
    rng = np.random.default_rng(1)
    cut = rng.random(bonds.n_bonds) < 0.05
    bonds.intact[cut | cut[bonds.reverse()]] = False
    model = make_model("pmb", body, bonds, E=70e9, density=2700.0, surface_correction="energy")
    u = 1e-3 * SPACING * rng.standard_normal(body.points.shape)
    threads = numba.get_num_threads()
    try:
        numba.set_num_threads(1)
        half = model.force(u)
        assert model._pairs is not None  # the half list ran
        rows = np.full_like(half, np.nan)
        model._kernel_force(u, rows, 0, body.n_points)  # row-bounded: the full list
        np.testing.assert_array_equal(half, rows)
        numba.set_num_threads(threads)
        np.testing.assert_array_equal(model.force(u), half)  # any number of threads
    finally:
        numba.set_num_threads(threads)
