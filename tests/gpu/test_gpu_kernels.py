"""GPU kernels (``peridyn.kernels.gpu``, Warp) against the numba kernels and the NumPy references.

The inputs, tolerances and scales are those of ``tests/kernels`` (``kernel_inputs``): a GPU
kernel sums each family in the CSR order of the numba kernels but rounds its own way (no
chunks, the device's or Warp's CPU compiler's fused multiply-adds), so it agrees with both to
a few unit roundoffs of the magnitudes summed: ``TOL64 = 1e-12`` of that scale in float64.
"""

import numpy as np
import pytest
import warp_device  # noqa: F401 - skips without Warp, picks the device (before peridyn)
from kernel_inputs import (
    TOL,
    TOL64,
    assert_close,
    displacement,
    family_magnitude,
    jittered_families,
    per_bond,
)

from peridyn.kernels import damage, lps, pmb, verlet
from peridyn.kernels import gpu as kgpu
from peridyn.kernels.gpu import forces, update
from peridyn.kernels.gpu.ell import EllSlots
from peridyn.kernels.reference import bond_vectors
from peridyn.kernels.reference import lps as lps_ref
from peridyn.kernels.reference import pmb as pmb_ref
from peridyn.kernels.reference import verlet as verlet_ref
from peridyn.kernels.reference.bond_search import initial_bond_vectors

pytestmark = pytest.mark.gpu

STRAINS = [1e-3, 1e-6]


class Ell:
    """The families of ``fam`` on the Warp device, ELL layout."""

    def __init__(self, fam, dtype):
        self.wp = kgpu.warp()
        self.device = kgpu.device()
        self.scalar = self.wp.float64 if dtype == np.float64 else self.wp.float32
        self.dtype = dtype
        self.slots = EllSlots.of(fam.offsets)
        self.count = self.put(self.slots.count, self.wp.int32)
        self.nbr = self.put(self.slots.to_ell(fam.nbr, np.int32), self.wp.int32)
        self.intact = self.put(self.slots.to_ell(fam.intact, np.uint8), self.wp.uint8)
        xi = initial_bond_vectors(fam.x, fam.offsets, fam.nbr)
        self.xi = [self.bond(xi[:, a]) for a in range(3)]

    def put(self, array, dtype):
        return self.wp.array(np.ascontiguousarray(array), dtype=dtype, device=self.device)

    def bond(self, values, fill=0.0):
        return self.put(self.slots.to_ell(values, self.dtype, fill), self.scalar)

    def point(self, values):
        return self.put(np.asarray(values, dtype=self.dtype), self.scalar)

    def out(self, shape, dtype=None):
        return self.wp.zeros(shape, dtype=dtype or self.scalar, device=self.device)

    def launch(self, kernel, n, inputs):
        self.wp.launch(kernel, dim=n, inputs=inputs, device=self.device)


@pytest.mark.parametrize("strain", STRAINS)
def test_pmb_force_float64(rng, strain):
    """Length form: k (1/|xi| - 1/|Y|) Y cancels two terms of size k |Y| / |xi| (the scale of
    ``test_kernel_pmb``): against the reference and the numba kernel, TOL64 of it."""
    fam = jittered_families(rng)
    u = displacement(rng, fam, strain)
    k = per_bond(rng, fam, 1e14)
    inv_len = 1.0 / fam.length
    e = Ell(fam, np.float64)
    f = e.out((fam.n, 3))
    e.launch(
        forces.pmb_force_kernel(e.scalar),
        fam.n,
        [*e.xi, e.point(u), e.count, e.nbr, e.bond(inv_len), e.bond(k), e.intact, f],
    )
    xi = initial_bond_vectors(fam.x, fam.offsets, fam.nbr)
    expected = pmb_ref.pmb_force(xi, u, fam.offsets, fam.nbr, inv_len, k, fam.intact)
    numba = pmb.pmb_force(xi, u, fam.offsets, fam.nbr, inv_len, k, fam.intact, np.empty_like(u))
    _, _, y = bond_vectors(fam.x, u, fam.offsets, fam.nbr)
    scale = family_magnitude(fam.offsets, fam.intact * k * inv_len * np.linalg.norm(y, axis=1))
    assert_close(f.numpy(), expected, TOL64, scale)
    assert_close(f.numpy(), numba, TOL64, scale)


@pytest.mark.parametrize("strain", STRAINS)
def test_pmb_force_float32(rng, strain):
    """Cancellation-free form in float32: TOL32 of k |du| / |xi| summed (``test_kernel_pmb``)."""
    fam = jittered_families(rng)
    x, u = fam.x.astype(np.float32), displacement(rng, fam, strain).astype(np.float32)
    k = per_bond(rng, fam, 1e14).astype(np.float32)
    e = Ell(fam, np.float32)
    f = e.out((fam.n, 3))
    e.launch(
        forces.pmb_force_cf_kernel(e.scalar),
        fam.n,
        [e.point(x), e.point(u), e.count, e.nbr, e.bond(k), e.intact, f],
    )
    expected = pmb_ref.pmb_force_cf(x, u, fam.offsets, fam.nbr, k, fam.intact)
    xi, du, _ = bond_vectors(x, u, fam.offsets, fam.nbr)
    scale = family_magnitude(
        fam.offsets, fam.intact * k * np.linalg.norm(du, axis=1) / np.linalg.norm(xi, axis=1)
    )
    assert f.numpy().dtype == np.float32
    assert_close(f.numpy(), expected, TOL[np.float32], scale)


def _lps_inputs(rng, fam, dtype):
    w = per_bond(rng, fam, 1e-9).astype(dtype)  # influence x bond volume, m^3
    dev = per_bond(rng, fam, 1e14).astype(dtype)  # deviatoric bond stiffness, N/m^4
    theta_coef = rng.uniform(0.5, 1.5, fam.n) * 3.0 / 1e-15  # d / m_i, 1/m^5
    p_coef = rng.uniform(0.5, 1.5, fam.n) * 1e-5  # Pa/m^5
    return w, dev, theta_coef.astype(dtype), p_coef.astype(dtype)


@pytest.mark.parametrize("strain", STRAINS)
@pytest.mark.parametrize("dtype", [np.float64, np.float32])
def test_lps_force(rng, dtype, strain):
    """Two passes, dilatation then pair force: theta to TOL of theta_coef sum w |xi|^2 (length
    form's cancellation) and the force to TOL of the per-point sum of the bond terms' sizes, as
    ``test_kernel_lps``; float64 against the numba kernels too."""
    fam = jittered_families(rng)
    u = displacement(rng, fam, strain)
    w, dev, theta_coef, p_coef = _lps_inputs(rng, fam, dtype)
    e = Ell(fam, dtype)
    theta, p, f = e.out(fam.n), e.out(fam.n), e.out((fam.n, 3))
    length = fam.length.astype(dtype)
    coefs = [e.point(theta_coef), e.point(p_coef), theta, p]
    if dtype == np.float64:
        xi = initial_bond_vectors(fam.x, fam.offsets, fam.nbr)
        common = [*e.xi, e.point(u), e.count, e.nbr, e.bond(length), e.bond(w)]
        e.launch(forces.lps_dilatation_kernel(e.scalar), fam.n, [*common, e.intact, *coefs])
        e.launch(forces.lps_pair_force_kernel(e.scalar), fam.n, [*common, e.bond(dev), e.intact, p, f])
        args = (xi, u, fam.offsets, fam.nbr, length, w)
        th_ref = lps_ref.lps_dilatation(*args, fam.intact, theta_coef)
        th_numba = lps.lps_dilatation(*args, fam.intact, theta_coef, np.empty(fam.n))
        f_ref = lps_ref.lps_pair_force(*args, dev, fam.intact, th_ref * p_coef)
        f_numba = lps.lps_pair_force(*args, dev, fam.intact, th_numba * p_coef, np.empty_like(u))
        compared = [(th_ref, f_ref), (th_numba, f_numba)]
    else:
        x, u = fam.x.astype(dtype), u.astype(dtype)
        common = [e.point(x), e.point(u), e.count, e.nbr, e.bond(w)]
        e.launch(forces.lps_dilatation_cf_kernel(e.scalar), fam.n, [*common, e.intact, *coefs])
        e.launch(forces.lps_pair_force_cf_kernel(e.scalar), fam.n, [*common, e.bond(dev), e.intact, p, f])
        args = (x, u, fam.offsets, fam.nbr, w)
        th_ref = lps_ref.lps_dilatation_cf(*args, fam.intact, theta_coef)
        f_ref = lps_ref.lps_pair_force_cf(*args, dev, fam.intact, th_ref * p_coef)
        compared = [(th_ref, f_ref)]
    _, du, y = bond_vectors(fam.x, u, fam.offsets, fam.nbr)
    r = np.linalg.norm(y, axis=1)
    ok = fam.intact
    th_scale = theta_coef * family_magnitude(fam.offsets, ok * w * fam.length * fam.length)
    pj = np.abs(p_coef * th_ref)[fam.nbr]
    pi = np.repeat(np.abs(p_coef * th_ref), np.diff(fam.offsets))
    f_scale = family_magnitude(fam.offsets, ok * (w * fam.length * (pi + pj) + dev * r))
    for th_expected, f_expected in compared:
        assert_close(theta.numpy(), th_expected, TOL[dtype], th_scale)
        assert_close(f.numpy(), f_expected, TOL[dtype], f_scale)


def test_stretch_break_same_bonds_as_numba(rng):
    """The same directed bonds break as under the numba stretch test of every family, with limits
    set so that about a third of the bonds fail; the count is that of the bonds broken."""
    fam = jittered_families(rng, broken=0.0)
    u = displacement(rng, fam, 1e-2)
    _, _, y = bond_vectors(fam.x, u, fam.offsets, fam.nbr)
    r = np.linalg.norm(y, axis=1)
    owners = np.repeat(np.arange(fam.n), np.diff(fam.offsets))
    pair = np.minimum(owners, fam.nbr) * fam.n + np.maximum(owners, fam.nbr)
    limit = fam.length * (1.0 + rng.uniform(0.0, 2e-2, fam.n * fam.n)[pair])  # one limit per bond pair
    limit[rng.random(len(limit)) < 0.05] = np.inf
    limit[pair == pair[np.argmin(np.abs(r / limit - 1.0))]] = r[np.argmin(np.abs(r / limit - 1.0))]
    e = Ell(fam, np.float64)
    broken = e.out(1, e.wp.int32)
    e.launch(
        update.stretch_break_kernel(),
        fam.n,
        [*e.xi, e.point(u), e.count, e.nbr, e.bond(limit, np.inf), e.intact, broken],
    )
    intact = np.ones(len(fam.nbr), dtype=bool)
    everyone = np.arange(fam.n)
    count = damage.stretch_test_families(
        fam.x,
        u,
        fam.offsets,
        fam.nbr,
        limit,
        intact,
        everyone,
        np.ones(fam.n, bool),
        np.zeros(fam.n),
        1e-12,
        np.empty(fam.n),
    )
    got = e.slots.from_ell(e.intact.numpy()).astype(bool)
    assert 0.05 < (~intact).mean() < 0.95
    np.testing.assert_array_equal(got, intact)
    assert int(broken.numpy()[0]) == count


@pytest.mark.parametrize("damping", [np.zeros(0), np.array([3.0e3]), None])
@pytest.mark.parametrize("dtype", [np.float64, np.float32])
def test_verlet_updates(rng, dtype, damping):
    """Kick-drift and the acceleration with the closing kick, against the NumPy expressions of
    ``kernels.reference.verlet`` and the numba kernels: the same operations in the same order,
    to 1 unit roundoff each (a compiler may fuse a multiply-add)."""
    n = 50
    u, v, a = (rng.standard_normal((n, 3)) for _ in range(3))
    f = (1e9 * rng.standard_normal((n, 3))).astype(dtype)
    b = 1e8 * rng.standard_normal((n, 3))
    inv_rho = 1.0 / rng.uniform(1e3, 1e4, n)
    damping = rng.uniform(0, 1e4, n) if damping is None else damping
    constrained = rng.random((n, 3)) < 0.2
    dt = 1e-7
    e = Ell(jittered_families(rng, shape=(2, 2, 2)), np.float64)
    U, V, A = e.point(u), e.point(v), e.point(a)
    e.launch(update.kick_drift_kernel(), (n, 3), [U, V, A, 0.5 * dt, dt])
    u_ref, v_ref = verlet_ref.kick_drift(u, v, a, 0.5 * dt, dt)
    np.testing.assert_allclose(U.numpy(), u_ref, rtol=2.3e-16, atol=0)
    np.testing.assert_allclose(V.numpy(), v_ref, rtol=2.3e-16, atol=0)
    scalar = e.wp.float64 if dtype == np.float64 else e.wp.float32
    F = e.wp.array(f, dtype=scalar, device=e.device)
    con = e.put(constrained.astype(np.uint8), e.wp.uint8)
    A2 = e.out((n, 3))
    e.launch(
        update.acceleration_kernel(scalar),
        (n, 3),
        [F, e.point(b), e.point(inv_rho), e.point(damping), V, con, A2, 1, 0.5 * dt, 0, e.out((1, 3))],
    )
    a_ref, v2_ref = verlet_ref.acceleration(f, b, inv_rho, damping, v_ref, constrained, True, 0.5 * dt)
    a_numba, v_numba = np.empty((n, 3)), v_ref.copy()
    verlet.acceleration(f, b, inv_rho, damping, v_numba, constrained, a_numba, True, 0.5 * dt)
    for expected_a, expected_v in ((a_ref, v2_ref), (a_numba, v_numba)):
        np.testing.assert_allclose(A2.numpy(), expected_a, rtol=4.5e-16, atol=0)
        np.testing.assert_allclose(V.numpy(), expected_v, rtol=4.5e-16, atol=1e-300)
