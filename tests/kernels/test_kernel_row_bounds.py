"""The row bounds ``first, stop`` of the force and dilatation kernels (``peridyn.kernels``).

Oracle: the same kernel on all rows. A bounded call must give the rows ``first .. stop - 1``
the same bits as the full call (an MPI rank computes its rows in two such calls and must
match a serial run bit for bit) and leave every other row of its output as it was.
"""

import numpy as np
import pytest
from kernel_inputs import displacement, jittered_families, per_bond

from peridyn.kernels import lps, pmb
from peridyn.kernels.bond_search import initial_bond_vectors

pytestmark = pytest.mark.kernels


def _calls(rng):
    """{name: call(out, *bounds) -> out} for the six bounded kernels, on one set of inputs."""
    fam = jittered_families(rng)
    x, u = fam.x, displacement(rng, fam, 1e-3)
    k, w, dev = (per_bond(rng, fam, s) for s in (1e14, 1.0, 1e14))
    coef = rng.uniform(0.5, 1.5, fam.n)
    p = 1e11 * rng.uniform(-1.0, 1.0, fam.n)
    xi = initial_bond_vectors(x, fam.offsets, fam.nbr, np.empty((fam.n_bonds, 3)))
    csr = (fam.offsets, fam.nbr)
    f32 = {
        name: a.astype(np.float32) for name, a in dict(x=x, u=u, k=k, w=w, dev=dev, coef=coef, p=p).items()
    }
    return fam.n, {
        "pmb_force": (
            3,
            lambda out, *b: pmb.pmb_force(xi, u, *csr, 1.0 / fam.length, k, fam.intact, out, *b),
        ),
        "pmb_force_cf": (
            3,
            lambda out, *b: pmb.pmb_force_cf(f32["x"], f32["u"], *csr, f32["k"], fam.intact, out, *b),
        ),
        "lps_dilatation": (
            1,
            lambda out, *b: lps.lps_dilatation(xi, u, *csr, fam.length, w, fam.intact, coef, out, *b),
        ),
        "lps_dilatation_cf": (
            1,
            lambda out, *b: lps.lps_dilatation_cf(
                f32["x"], f32["u"], *csr, f32["w"], fam.intact, f32["coef"], out, *b
            ),
        ),
        "lps_pair_force": (
            3,
            lambda out, *b: lps.lps_pair_force(xi, u, *csr, fam.length, w, dev, fam.intact, p, out, *b),
        ),
        "lps_pair_force_cf": (
            3,
            lambda out, *b: lps.lps_pair_force_cf(
                f32["x"], f32["u"], *csr, f32["w"], f32["dev"], fam.intact, f32["p"], out, *b
            ),
        ),
    }


@pytest.mark.bitwise
@pytest.mark.parametrize(
    "name",
    [
        "pmb_force",
        "pmb_force_cf",
        "lps_dilatation",
        "lps_dilatation_cf",
        "lps_pair_force",
        "lps_pair_force_cf",
    ],
)
def test_bounded_rows_equal_the_full_call_and_others_stay(rng, name):
    """A row-bounded call (an MPI rank's) computes the rows ``first .. stop - 1`` with the full call's
    bits and leaves the other rows alone; two calls split at one row give the full call. A row's sums
    are the same operations in the same order whichever call computes them, and the kernels are compiled
    without value-changing fast-math flags (``peridyn.kernels.FASTMATH``), so this holds on every
    CPU."""
    n, calls = _calls(rng)
    width, call = calls[name]
    dtype = np.float32 if name.endswith("_cf") else np.float64
    shape = (n, width) if width == 3 else (n,)
    full = call(np.full(shape, np.nan, dtype=dtype)).copy()
    assert not np.isnan(full).any()
    first, stop = n // 3, 2 * n // 3
    got = call(np.full(shape, np.nan, dtype=dtype), first, stop)
    np.testing.assert_array_equal(got[first:stop], full[first:stop])
    assert np.isnan(got[:first]).all() and np.isnan(got[stop:]).all()
    # stop < 0 runs to the last row; two calls split at one row give the full call's bits
    split = call(np.full(shape, np.nan, dtype=dtype), 0, first)
    call(split, first, -1)
    np.testing.assert_array_equal(split, full)
