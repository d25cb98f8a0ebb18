"""The fused LPS force (``kernels.lps.lps_force_fused`` with ``discretization.bonds.fused_plan``)
against the two passes it replaces: the same bits, not a tolerance.

``lps_dilatation``, ``theta * p_coef`` and ``lps_pair_force`` on the same inputs give the
reference; the fused kernel must return the same ``theta``, ``p`` and force, for any number
of parts (threads) and block size: one part, more parts than rows, blocks of one row, one
block a part, a ring just large enough (it wraps around many times on these small inputs).
"""

import numpy as np
import pytest
from conftest import small_model
from kernel_inputs import displacement, jittered_families, per_bond

from peridyn.discretization.bonds import fused_plan, fused_ring_columns
from peridyn.kernels import lps
from peridyn.kernels.bond_search import initial_bond_vectors

pytestmark = pytest.mark.kernels

#: (grid shape, horizon in spacings) of the families: a box, and a flat one of larger horizon
#: (the index bandwidth then spans most of the rows).
FAMILIES = [((4, 4, 3), 2.015), ((6, 3, 2), 3.015)]


def _inputs(rng, shape, horizon_factor):
    """Families (10% of the bonds broken), then float64 xi, u, w, dev, theta_coef, p_coef."""
    fam = jittered_families(rng, shape=shape, horizon_factor=horizon_factor)
    xi = initial_bond_vectors(fam.x, fam.offsets, fam.nbr, np.empty((len(fam.nbr), 3)))
    u = displacement(rng, fam, 1e-3)
    theta_coef = rng.uniform(0.5, 1.5, fam.n) / fam.length.mean() ** 2
    p_coef = rng.uniform(-1.0, 1.0, fam.n) * 1e11
    return fam, xi, u, per_bond(rng, fam), per_bond(rng, fam, 1e11), theta_coef, p_coef


def _two_passes(fam, xi, u, w, dev, theta_coef, p_coef):
    """theta, p and the force of ``lps_dilatation`` and ``lps_pair_force``."""
    families = (xi, u, fam.offsets, fam.nbr, fam.length, w)
    theta = lps.lps_dilatation(*families, fam.intact, theta_coef, np.empty(fam.n))
    p = theta * p_coef
    return theta, p, lps.lps_pair_force(*families, dev, fam.intact, p, np.empty((fam.n, 3)))


def _fused(fam, xi, u, w, dev, theta_coef, p_coef, parts, block_rows):
    """theta, p and the force of ``lps_force_fused`` (outputs filled with NaN first)."""
    plan = fused_plan(fam.offsets, fam.nbr, parts, block_rows)
    ring = np.full((parts, 4, fused_ring_columns(fam.offsets, plan)), np.nan)
    theta, p, f = np.full(fam.n, np.nan), np.full(fam.n, np.nan), np.full((fam.n, 3), np.nan)
    args = (xi, u, fam.offsets, fam.nbr, fam.length, w, dev, fam.intact, theta_coef, p_coef)
    lps.lps_force_fused(*args, *plan, ring, theta, p, f)
    return theta, p, f


@pytest.mark.bitwise
@pytest.mark.parametrize("block_rows", [1, 7, 10**9])
@pytest.mark.parametrize("parts", [1, 2, 3, 200])
@pytest.mark.parametrize("shape, horizon_factor", FAMILIES)
def test_fused_force_is_the_two_passes_bit_for_bit(rng, shape, horizon_factor, parts, block_rows):
    """The fused LPS force (dilatation, pressure and pair force in one sweep of the rows, in parts and
    blocks of rows) gives the two passes' theta, p and force bit for bit: each row's sums are the same
    operations in the same order, and the kernels are compiled without value-changing fast-math flags
    (``peridyn.kernels.FASTMATH``), so this holds on every CPU."""
    inputs = _inputs(rng, shape, horizon_factor)
    for got, ref in zip(_fused(*inputs, parts, block_rows), _two_passes(*inputs), strict=True):
        assert np.array_equal(got, ref)


@pytest.mark.parametrize("block_rows", [1, 5, 64])
@pytest.mark.parametrize("parts", [1, 2, 5, 200])
def test_fused_plan_orders_the_rows_it_reads(rng, parts, block_rows):
    """Parts and blocks tile the rows in order; a part's inner rows are read by no row of another
    part; a block's ``need`` is above its rows and every neighbour of them. Row indices: compared
    exactly."""
    fam = jittered_families(rng, shape=(6, 3, 2), horizon_factor=3.015)
    plan = fused_plan(fam.offsets, fam.nbr, parts, block_rows)
    n = fam.n
    assert plan.parts[0, 0] == 0 and plan.parts[-1, 1] == n
    assert np.array_equal(plan.parts[1:, 0], plan.parts[:-1, 1])
    assert plan.blocks[0] == 0 and plan.blocks[-1] == n and np.all(np.diff(plan.blocks) > 0)
    owners = np.repeat(np.arange(n), np.diff(fam.offsets))
    part_of = np.searchsorted(plan.parts[:, 1], np.arange(n), side="right")
    for t, (lo, hi, first, end) in enumerate(plan.parts):
        assert plan.blocks[first] == lo and plan.blocks[end] == hi
        inner_lo, inner_hi = plan.inner[t]
        assert lo <= inner_lo <= inner_hi <= hi
        read = (fam.nbr >= inner_lo) & (fam.nbr < inner_hi)
        assert np.all(part_of[owners[read]] == t)
    for k in range(len(plan.need)):
        rows = (owners >= plan.blocks[k]) & (owners < plan.blocks[k + 1])
        assert plan.need[k] >= plan.blocks[k + 1]
        assert plan.need[k] > fam.nbr[rows].max(initial=-1)


@pytest.mark.bitwise
@pytest.mark.parametrize("dim", [2, 3])
def test_lps_model_force_is_fused_and_the_two_passes(dim, rng):
    """``LPSModel.force`` (float64) takes the fused kernel on a small body, with the same bits as
    the model's own two passes. Same operations in the same order, and the kernels are compiled without
    value-changing fast-math flags (``peridyn.kernels.FASTMATH``), so this holds on every CPU."""
    model = small_model("lps", dim, n=8)
    b = model.bonds
    b.intact[rng.random(b.n_bonds) < 0.05] = False
    u = 1e-5 * rng.standard_normal(model.x.shape)
    assert model._fused(model.body.n_points) is not None
    got = model.force(u)
    fused_theta = model._theta.copy()
    np.multiply(model._dilatation(u), model._p_coef, out=model._p)  # the two passes' theta, p
    ref = model._pair_force(u, np.empty_like(got))
    assert np.array_equal(got, ref)
    assert np.array_equal(fused_theta, model._theta)


@pytest.mark.bitwise
@pytest.mark.parametrize("parts", [1, 2, 3])
def test_fused_force_of_leading_rows_after_the_rest_is_the_two_passes(rng, parts):
    """An MPI rank's overlapped force (``LPSModel.force_overlapped``): the dilatation of the rows
    after ``rows`` first, then the fused force of the first ``rows`` rows on the plan of their
    families alone. Neighbours past ``rows`` order nothing (the plan's ``need`` stays within
    ``rows``), and the leading rows' theta, p and force are the two passes' bits. The kernels are
    compiled without value-changing fast-math flags (``peridyn.kernels.FASTMATH``): on every CPU."""
    fam, xi, u, w, dev, theta_coef, p_coef = _inputs(rng, (6, 3, 2), 3.015)
    rows = fam.n // 2
    offsets = fam.offsets[: rows + 1]
    plan = fused_plan(offsets, fam.nbr[: offsets[-1]], parts, 5)
    assert plan.need.max() <= rows
    theta_ref, p_ref, f_ref = _two_passes(fam, xi, u, w, dev, theta_coef, p_coef)
    theta, p, f = np.full(fam.n, np.nan), np.full(fam.n, np.nan), np.full((fam.n, 3), np.nan)
    theta[rows:], p[rows:] = theta_ref[rows:], p_ref[rows:]
    ring = np.full((parts, 4, fused_ring_columns(offsets, plan)), np.nan)
    args = (xi, u, fam.offsets, fam.nbr, fam.length, w, dev, fam.intact, theta_coef, p_coef)
    lps.lps_force_fused(*args, *plan, ring, theta, p, f)
    assert np.array_equal(theta, theta_ref) and np.array_equal(p, p_ref)
    assert np.array_equal(f[:rows], f_ref[:rows]) and np.isnan(f[rows:]).all()
