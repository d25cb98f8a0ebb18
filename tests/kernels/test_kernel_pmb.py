"""PMB kernels (``peridyn.kernels.pmb``) against their NumPy references (``kernels.reference.pmb``).

Tolerances: see ``kernel_inputs``; the scale of each comparison is the per-point sum of the
magnitudes the kernel's form rounds (stated per test).
"""

import numpy as np
import pytest
from kernel_inputs import (
    TOL,
    TOL64,
    assert_close,
    displacement,
    family_magnitude,
    jittered_families,
    per_bond,
)

from peridyn.kernels import pmb
from peridyn.kernels.reference import bond_vectors
from peridyn.kernels.reference import pmb as ref
from peridyn.kernels.reference.bond_search import initial_bond_vectors

pytestmark = pytest.mark.kernels

DTYPES = [np.float64, np.float32]
#: Typical bond strains of the random displacements: large, and the strain-1e-6 waves that
#: the float32 cancellation-free form exists for.
STRAINS = [1e-3, 1e-6]


def _inputs(rng, dtype, strain):
    fam = jittered_families(rng)
    u = displacement(rng, fam, strain)
    k = per_bond(rng, fam, 1e14)  # bond stiffness, N/m^4 (c V_j of steel-like constants)
    return fam, fam.x.astype(dtype), u.astype(dtype), k.astype(dtype)


@pytest.mark.parametrize("strain", STRAINS)
@pytest.mark.parametrize("dtype", DTYPES)
def test_pmb_force_length_form(rng, dtype, strain):
    """k (1/|xi| - 1/|Y|) Y cancels two terms of size k |Y| / |xi| down to the stretch: the
    rounding is relative to those (whatever the strain)."""
    fam, x, u, k = _inputs(rng, dtype, strain)
    inv_len = (1.0 / fam.length).astype(dtype)
    xi = initial_bond_vectors(x, fam.offsets, fam.nbr).astype(dtype)
    got = pmb.pmb_force(xi, u, fam.offsets, fam.nbr, inv_len, k, fam.intact, np.full_like(x, np.nan))
    expected = ref.pmb_force(xi, u, fam.offsets, fam.nbr, inv_len, k, fam.intact)
    _, _, y = bond_vectors(x, u, fam.offsets, fam.nbr)
    scale = family_magnitude(fam.offsets, fam.intact * k * inv_len * np.linalg.norm(y, axis=1))
    assert got.dtype == dtype
    assert_close(got, expected, TOL[dtype], scale)


@pytest.mark.parametrize("strain", STRAINS)
@pytest.mark.parametrize("dtype", DTYPES)
def test_pmb_force_cancellation_free_form(rng, dtype, strain):
    """The cancellation-free form has no cancellation: each bond's term, of size
    k |u_j - u_i| / |xi|, keeps its relative precision however small the strain."""
    fam, x, u, k = _inputs(rng, dtype, strain)
    got = pmb.pmb_force_cf(x, u, fam.offsets, fam.nbr, k, fam.intact, np.full_like(x, np.nan))
    expected = ref.pmb_force_cf(x, u, fam.offsets, fam.nbr, k, fam.intact)
    xi, du, _ = bond_vectors(x, u, fam.offsets, fam.nbr)
    scale = family_magnitude(
        fam.offsets, fam.intact * k * np.linalg.norm(du, axis=1) / np.linalg.norm(xi, axis=1)
    )
    assert got.dtype == dtype
    assert_close(got, expected, TOL[dtype], scale)


@pytest.mark.parametrize("dtype", DTYPES)
def test_pmb_force_baseline(rng, dtype):
    """c (|Y| - |xi|) / |xi| Y / |Y|: |Y| - |xi| cancels terms of size c |Y| / |xi|."""
    fam, x, u, c = _inputs(rng, dtype, 1e-3)
    length = fam.length.astype(dtype)
    got = pmb.pmb_force_baseline(x, u, fam.offsets, fam.nbr, length, c, fam.intact, np.full_like(x, np.nan))
    expected = ref.pmb_force_baseline(x, u, fam.offsets, fam.nbr, length, c, fam.intact)
    _, _, y = bond_vectors(x, u, fam.offsets, fam.nbr)
    scale = family_magnitude(fam.offsets, fam.intact * c * np.linalg.norm(y, axis=1) / length)
    assert_close(got, expected, TOL[dtype], scale)


def test_pmb_energy(rng):
    """W_i = sum_j k s^2 |xi| / 4 (float64, the only dtype it is called with): s = |Y|/|xi| - 1
    is rounded to ~1e-16 absolute, so k s^2 |xi| to ~1e-16 of k |s| |xi|."""
    fam, x, u, k = _inputs(rng, np.float64, 1e-3)
    got = pmb.pmb_energy(x, u, fam.offsets, fam.nbr, fam.length, k, fam.intact, np.full(fam.n, np.nan))
    expected = ref.pmb_energy(x, u, fam.offsets, fam.nbr, fam.length, k, fam.intact)
    _, _, y = bond_vectors(x, u, fam.offsets, fam.nbr)
    stretch = np.linalg.norm(y, axis=1) / fam.length - 1.0
    scale = 0.25 * family_magnitude(fam.offsets, fam.intact * k * stretch * fam.length)
    assert_close(got, expected, TOL64, scale)
