"""LPS kernels (``peridyn.kernels.lps``) against their NumPy references (``kernels.reference.lps``).

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

from peridyn.kernels import lps
from peridyn.kernels.reference import bond_vectors, owners
from peridyn.kernels.reference import lps as ref
from peridyn.kernels.reference.bond_search import initial_bond_vectors

pytestmark = pytest.mark.kernels

DTYPES = [np.float64, np.float32]
#: Typical bond strains of the random displacements (see ``test_kernel_pmb``).
STRAINS = [1e-3, 1e-6]


def _inputs(rng, dtype, strain):
    """Families, then x, u, w, dev, theta_coef and P in ``dtype``: positive weights w and
    deviatoric stiffnesses dev per bond, theta_coef of the size of d / m (m = sum w |xi|^2
    over ~30 bonds), and P of either sign of the size that makes w |xi| P and dev e alike."""
    fam = jittered_families(rng)
    u = displacement(rng, fam, strain)
    w = per_bond(rng, fam, 1.0)
    dev = per_bond(rng, fam, 1e14)
    theta_coef = rng.uniform(0.5, 1.5, fam.n) * 3.0 / (30 * fam.length.mean() ** 2)
    p = strain * 1e14 * rng.uniform(-1.0, 1.0, fam.n)
    return fam, *(a.astype(dtype) for a in (fam.x, u, w, dev, theta_coef, p))


def _lengths(x, u, fam):
    """(|xi|, |u_j - u_i|, |Y|) per bond, float64."""
    xi, du, y = bond_vectors(x, u, fam.offsets, fam.nbr)
    return (np.linalg.norm(a, axis=1) for a in (xi, du, y))


@pytest.mark.parametrize("strain", STRAINS)
@pytest.mark.parametrize("dtype", DTYPES)
def test_lps_dilatation_length_form(rng, dtype, strain):
    """theta_coef sum w |xi| (|Y| - |xi|): the extension cancels terms of size |xi|."""
    fam, x, u, w, _, theta_coef, _ = _inputs(rng, dtype, strain)
    length = fam.length.astype(dtype)
    xi = initial_bond_vectors(x, fam.offsets, fam.nbr).astype(dtype)
    args = (xi, u, fam.offsets, fam.nbr, length, w, fam.intact, theta_coef)
    got = lps.lps_dilatation(*args, np.full(fam.n, np.nan, dtype))
    scale = theta_coef * family_magnitude(fam.offsets, fam.intact * w * length * length)
    assert got.dtype == dtype
    assert_close(got, ref.lps_dilatation(*args), TOL[dtype], scale)


@pytest.mark.parametrize("strain", STRAINS)
@pytest.mark.parametrize("dtype", DTYPES)
def test_lps_dilatation_cancellation_free_form(rng, dtype, strain):
    """Cancellation-free: the extension keeps its precision relative to |u_j - u_i|."""
    fam, x, u, w, _, theta_coef, _ = _inputs(rng, dtype, strain)
    args = (x, u, fam.offsets, fam.nbr, w, fam.intact, theta_coef)
    got = lps.lps_dilatation_cf(*args, np.full(fam.n, np.nan, dtype))
    length, moved, _ = _lengths(x, u, fam)
    scale = theta_coef * family_magnitude(fam.offsets, fam.intact * w * length * moved)
    assert got.dtype == dtype
    assert_close(got, ref.lps_dilatation_cf(*args), TOL[dtype], scale)


@pytest.mark.parametrize("strain", STRAINS)
@pytest.mark.parametrize("dtype", DTYPES)
def test_lps_pair_force_length_form(rng, dtype, strain):
    """[w |xi| (P_i + P_j) + dev (|Y| - |xi|)] Y / |Y|: the extension cancels dev |xi|."""
    fam, x, u, w, dev, _, p = _inputs(rng, dtype, strain)
    length = fam.length.astype(dtype)
    xi = initial_bond_vectors(x, fam.offsets, fam.nbr).astype(dtype)
    args = (xi, u, fam.offsets, fam.nbr, length, w, dev, fam.intact, p)
    got = lps.lps_pair_force(*args, np.full_like(x, np.nan))
    pair = np.abs(p[owners(fam.offsets)]) + np.abs(p[fam.nbr])
    scale = family_magnitude(fam.offsets, fam.intact * (w * length * pair + dev * length))
    assert got.dtype == dtype
    assert_close(got, ref.lps_pair_force(*args), TOL[dtype], scale)


@pytest.mark.parametrize("strain", STRAINS)
@pytest.mark.parametrize("dtype", DTYPES)
def test_lps_pair_force_cancellation_free_form(rng, dtype, strain):
    """Cancellation-free: the deviatoric term keeps its precision relative to dev |u_j - u_i|."""
    fam, x, u, w, dev, _, p = _inputs(rng, dtype, strain)
    args = (x, u, fam.offsets, fam.nbr, w, dev, fam.intact, p)
    got = lps.lps_pair_force_cf(*args, np.full_like(x, np.nan))
    length, moved, _ = _lengths(x, u, fam)
    pair = np.abs(p[owners(fam.offsets)]) + np.abs(p[fam.nbr])
    scale = family_magnitude(fam.offsets, fam.intact * (w * length * pair + dev * moved))
    assert got.dtype == dtype
    assert_close(got, ref.lps_pair_force_cf(*args), TOL[dtype], scale)


@pytest.mark.parametrize("dim", [2, 3])
def test_lps_deviatoric_energy(rng, dim):
    """sum_j w (e - theta |xi| / d)^2 (float64, the only dtype it is called with): the
    deviatoric extension is rounded to ~1e-16 |xi|, its square to ~1e-16 of |e_d| |xi|."""
    fam, x, u, w, _, theta_coef, _ = _inputs(rng, np.float64, 1e-3)
    xi = initial_bond_vectors(x, fam.offsets, fam.nbr)
    theta = ref.lps_dilatation(xi, u, fam.offsets, fam.nbr, fam.length, w, fam.intact, theta_coef)
    args = (x, u, fam.offsets, fam.nbr, fam.length, w, fam.intact, theta, dim)
    got = lps.lps_deviatoric_energy(*args, np.full(fam.n, np.nan))
    _, _, r = _lengths(x, u, fam)
    deviatoric = r - fam.length - theta[owners(fam.offsets)] * fam.length / dim
    scale = family_magnitude(fam.offsets, fam.intact * w * deviatoric * fam.length)
    assert_close(got, ref.lps_deviatoric_energy(*args), TOL64, scale)


@pytest.mark.bitwise
@pytest.mark.parametrize("dev_dtype", [np.float64, np.float32])
def test_lps_stiffness_bound_is_the_numpy_form_to_the_bit(rng, dev_dtype):
    """The stiffness bound that sets the stable time step, with broken bonds and a float32
    deviatoric coefficient (a float32 model's): bit for bit the NumPy form, so that a run's
    time step, and every bit after it, is the same as before the kernel. The kernel sums each family in
    bond order as the reference's ``np.add.at`` does, with the same products, and the kernels are
    compiled without value-changing fast-math flags (``peridyn.kernels.FASTMATH``), so this holds on
    every CPU."""
    fam, *_ = _inputs(rng, np.float64, 1e-3)
    intact = fam.intact.copy()
    intact[rng.random(len(intact)) < 0.1] = False
    w = per_bond(rng, fam, 1e-9)
    dev = per_bond(rng, fam, 1e14).astype(dev_dtype)
    bulk = rng.uniform(5e10, 8e10, fam.n)
    theta_coef = rng.uniform(0.5, 1.5, fam.n) * 3.0 / (30 * fam.length.mean() ** 2)
    args = (fam.offsets, fam.nbr, intact, w, fam.length, dev, bulk, theta_coef)
    got = lps.lps_stiffness_bound(*args, np.full(fam.n, np.nan), np.full(fam.n, np.nan))
    np.testing.assert_array_equal(got, ref.lps_stiffness_bound(*args))
