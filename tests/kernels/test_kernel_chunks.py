"""The chunked two-loop force kernels sum each family in its written order (``peridyn.kernels``).

Oracle: the float64 kernels as they were before the chunks (``single_loop_kernels``, one
loop per family, same ``FASTMATH``, gathering the neighbours' positions). Same operations in
the same order give the same bits, whatever the chunk boundaries (the families here have 41
to 99 bonds, ``CHUNK`` 32: up to four chunks, the last one partial), and whether
``xi = x_j - x_i`` is computed in the loop or read from the stored bond vectors
(``initial_bond_vectors``, the same subtraction).
"""

import numpy as np
import pytest
import single_loop_kernels as single
from kernel_inputs import displacement, jittered_families, per_bond

from peridyn.kernels import CHUNK, lps, pmb
from peridyn.kernels.bond_search import initial_bond_vectors

pytestmark = pytest.mark.kernels


@pytest.mark.bitwise
def test_chunks_sum_in_written_order(rng):
    """Each chunked kernel gives the single-loop kernel's bits (module docstring): the same operations
    in the same order, and the kernels are compiled without value-changing fast-math flags
    (``peridyn.kernels.FASTMATH``), so this holds on every CPU."""
    fam = jittered_families(rng, shape=(5, 5, 4), horizon_factor=3.015)
    sizes = np.diff(fam.offsets)
    assert sizes.max() > 2 * CHUNK and np.any(sizes % CHUNK)  # several chunks, partial ones
    x, u = fam.x, displacement(rng, fam, 1e-3)
    k, w, dev = (per_bond(rng, fam, s) for s in (1e14, 1.0, 1e14))
    theta_coef = rng.uniform(0.5, 1.5, fam.n)
    p = 1e11 * rng.uniform(-1.0, 1.0, fam.n)
    args = (x, u, fam.offsets, fam.nbr)
    xi = initial_bond_vectors(x, fam.offsets, fam.nbr, np.empty((len(fam.nbr), 3)))
    inv_len = 1.0 / fam.length
    for kernel, oracle, extra, out in (
        (pmb.pmb_force, single.pmb_force, (inv_len, k, fam.intact), (fam.n, 3)),
        (lps.lps_dilatation, single.lps_dilatation, (fam.length, w, fam.intact, theta_coef), (fam.n,)),
        (lps.lps_pair_force, single.lps_pair_force, (fam.length, w, dev, fam.intact, p), (fam.n, 3)),
    ):
        got = kernel(xi, *args[1:], *extra, np.full(out, np.nan))
        np.testing.assert_array_equal(got, oracle(*args, *extra, np.full(out, np.nan)))
