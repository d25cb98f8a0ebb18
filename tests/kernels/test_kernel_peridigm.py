"""Peridigm's LPS force order (``peridyn.kernels.peridigm``) against its NumPy reference
(``kernels.reference.peridigm``), and on Peridigm's two-point compression deck, whose forces
Peridigm's gold file gives to the last bit."""

import numpy as np
import pytest
from kernel_inputs import TOL64, assert_close, displacement, family_magnitude, jittered_families, per_bond

from peridyn.kernels.peridigm import peridigm_lps_force
from peridyn.kernels.reference import peridigm as ref

pytestmark = pytest.mark.kernels


@pytest.mark.parametrize("strain", [1e-3, 1e-6])
def test_peridigm_lps_force_matches_reference(rng, strain):
    """theta and f within TOL64 of the per-point sums of the terms' magnitudes (kernel_inputs:
    the two sum in different orders)."""
    fam = jittered_families(rng, partial_volumes=False)
    y = fam.x + displacement(rng, fam, strain)
    influence = per_bond(rng, fam)
    m = rng.uniform(0.5, 1.5, fam.n) * 30 * fam.length.mean() ** 2 * fam.volumes.mean()
    alpha = 15.0 * 78e9 / m
    p_coef = 3.0 * 130e9 / m - alpha / 3.0
    args = (fam.x, y, fam.offsets, fam.nbr, fam.volumes, influence, fam.intact, m, alpha, p_coef)
    theta, f = peridigm_lps_force(*args, np.full(fam.n, np.nan), np.full((fam.n, 3), np.nan))
    want_theta, want_f = ref.peridigm_lps_force(*args)
    zeta = fam.length
    i = np.repeat(np.arange(fam.n), np.diff(fam.offsets))
    bound = fam.intact * 3.0 * influence * zeta * zeta * fam.volumes[fam.nbr] / m[i]
    assert_close(theta, want_theta, TOL64, family_magnitude(fam.offsets, bound))
    t = fam.intact * influence * (np.abs(want_theta[i] * p_coef[i]) * zeta + alpha[i] * zeta)
    scale = family_magnitude(fam.offsets, t * fam.volumes.max())
    assert_close(f, want_f, TOL64, scale + np.bincount(fam.nbr, t * fam.volumes.max(), minlength=fam.n))


def test_two_points_give_peridigm_bits():
    """Two points 2 m apart (Peridigm's Compression_2x1x1 deck: volumes 2 m^3, K = 130 GPa,
    mu = 78 GPa, m = 8 m^5) at the deformed positions of its second step, as Peridigm's
    explicit loop forms them ((x + u) + dt v(n + 1/2), dt = 1e-5 s; u, v and a of the first
    step from the gold file): the force density of its gold file, bit for bit
    (-23224499.999920934 N/m^3), and the dilatation (-5.9549999999797265e-05)."""
    x = np.array([[-1.0, 0.0, 0.0], [1.0, 0.0, 0.0]])
    u, v, a = 1.0000000000000001e-05, 0.9925000000000341, -1499.9999999931733
    half = v + 0.5e-5 * a
    y = np.array([[(-1.0 + u) + 1e-5 * half, 0.0, 0.0], [(1.0 - u) - 1e-5 * half, 0.0, 0.0]])
    m = np.full(2, 8.0)
    alpha = 15.0 * 78e9 / m
    args = (np.array([0, 1, 2]), np.array([1, 0], dtype=np.int32), np.full(2, 2.0), np.ones(2))
    theta, f = peridigm_lps_force(
        x, y, *args, np.ones(2, bool), m, alpha, 3.0 * 130e9 / m - alpha / 3.0, np.empty(2), np.empty((2, 3))
    )
    assert f[0, 0] == -23224499.999920934 and f[1, 0] == -f[0, 0]
    assert theta[0] == theta[1] == -5.9549999999797265e-05
