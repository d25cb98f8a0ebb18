"""Stress kernels (``peridyn.kernels.stress``) against their NumPy references
(``kernels.reference.stress``).

Tolerance: ``TOL64`` of ``kernel_inputs`` times the per-point sum of the magnitudes of the
terms (both sides sum the same terms in different orders).
"""

import numpy as np
import pytest
from kernel_inputs import TOL64, assert_close, displacement, family_magnitude, jittered_families, per_bond

from peridyn.kernels import stress
from peridyn.kernels.reference import bond_vectors
from peridyn.kernels.reference import stress as ref

pytestmark = pytest.mark.kernels


def _per_point_bound(fam, terms):
    """(n_points, 1, 1): the per-point sum of |terms| (n_bonds,) over the intact bonds."""
    return family_magnitude(fam.offsets, fam.intact * terms)[:, None, None]


@pytest.mark.parametrize("strain", [1e-3, 1e-6])
def test_shape_tensors(rng, strain):
    """K and N of jittered families with broken bonds (w in m^3: neighbour volumes)."""
    fam = jittered_families(rng)
    u = displacement(rng, fam, strain)
    w = per_bond(rng, fam, 1e-9)
    n = fam.n
    K, N = stress.shape_tensors(
        fam.x, u, fam.offsets, fam.nbr, w, fam.intact, np.full((n, 3, 3), np.nan), np.full((n, 3, 3), np.nan)
    )
    K_ref, N_ref = ref.shape_tensors(fam.x, u, fam.offsets, fam.nbr, w, fam.intact)
    xi, _, y = bond_vectors(fam.x, u, fam.offsets, fam.nbr)
    scale = _per_point_bound(fam, w * np.linalg.norm(xi, axis=1) * np.linalg.norm(y, axis=1))
    assert_close(K, K_ref, TOL64, scale[:, 0, 0])
    assert_close(N, N_ref, TOL64, scale[:, 0, 0])


@pytest.mark.parametrize("strain", [1e-3, 1e-6])
def test_partial_stress(rng, strain):
    """Partial stress with both parts of the force state (axial p and owner extension)."""
    fam = jittered_families(rng)
    u = displacement(rng, fam, strain)
    axial = per_bond(rng, fam, 1e-12)  # w |xi|, m^4
    owner = per_bond(rng, fam, 1e17)  # N/m^5
    p = 1e18 * strain * rng.standard_normal(fam.n)  # Pa/m^5
    got = stress.partial_stress(
        fam.x,
        u,
        fam.offsets,
        fam.nbr,
        fam.length,
        axial,
        owner,
        fam.intact,
        p,
        np.full((fam.n, 3, 3), np.nan),
    )
    expected = ref.partial_stress(fam.x, u, fam.offsets, fam.nbr, fam.length, axial, owner, fam.intact, p)
    _, _, y = bond_vectors(fam.x, u, fam.offsets, fam.nbr)
    r = np.linalg.norm(y, axis=1)
    # each term: (|axial p| + owner |xi| (1 + r / |xi|)) |xi|, the extension rounded relative to r
    owners = np.repeat(np.arange(fam.n), np.diff(fam.offsets))
    terms = (np.abs(axial * p[owners]) + owner * (r + fam.length)) * fam.length
    assert_close(got, expected, TOL64, _per_point_bound(fam, terms)[:, 0, 0])
