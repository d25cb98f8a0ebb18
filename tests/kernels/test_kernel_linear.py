"""Linearised force kernels (``peridyn.kernels.linear``) against their NumPy references
(``kernels.reference.linear``), float64 (the stiffness drivers' dtype).

Tolerances: see ``kernel_inputs``. The linearised extension n . (u_j - u_i) has no
cancellation beyond its dot product, so each bond's terms are rounded relative to |u_j - u_i|.
"""

import numpy as np
import pytest
from kernel_inputs import TOL64, assert_close, displacement, family_magnitude, jittered_families, per_bond

from peridyn.kernels import linear
from peridyn.kernels.reference import bond_vectors, owners
from peridyn.kernels.reference import linear as ref

pytestmark = pytest.mark.kernels


def _inputs(rng):
    fam = jittered_families(rng)
    u = displacement(rng, fam, 1e-3)
    _, du, _ = bond_vectors(fam.x, u, fam.offsets, fam.nbr)
    return fam, u, np.linalg.norm(du, axis=1)


def test_bond_extension(rng):
    """e = n . (u_j - u_i) per intact bond, exactly 0 for a broken one."""
    fam, u, moved = _inputs(rng)
    args = (fam.x, u, fam.offsets, fam.nbr, fam.length, fam.intact)
    got = linear.bond_extension(*args, np.full(fam.n_bonds, np.nan))
    assert np.all(got[~fam.intact] == 0.0)
    assert_close(got, ref.bond_extension(*args), TOL64, moved)


def test_scatter_along_bonds(rng):
    """f_i = sum_j t n over every bond (broken ones included: t carries the mask)."""
    fam, _, _ = _inputs(rng)
    t = rng.standard_normal(fam.n_bonds)
    args = (fam.x, fam.offsets, fam.nbr, fam.length, t)
    got = linear.scatter_along_bonds(*args, np.full_like(fam.x, np.nan))
    assert_close(got, ref.scatter_along_bonds(*args), TOL64, family_magnitude(fam.offsets, t))


def test_lps_linear_force(rng):
    """f_i = sum_j [w |xi| (P_i + P_j) + dev e] n: terms of size w |xi| (|P_i| + |P_j|) +
    dev |u_j - u_i|, P bounded by |theta_coef p_coef| sum w |xi| |u_j - u_i|."""
    fam, u, moved = _inputs(rng)
    w = per_bond(rng, fam)
    dev = per_bond(rng, fam, 1e14)
    theta_coef = rng.uniform(0.5, 1.5, fam.n) * 3.0 / (30 * fam.length.mean() ** 2)
    p_coef = rng.uniform(-1.5, 1.5, fam.n) * 3e13  # P = theta p_coef: w |xi| P comparable to dev e
    args = (fam.x, u, fam.offsets, fam.nbr, fam.length, w, dev, fam.intact, theta_coef, p_coef)
    p_bound = np.abs(theta_coef * p_coef) * family_magnitude(fam.offsets, fam.intact * w * fam.length * moved)
    pair = p_bound[owners(fam.offsets)] + p_bound[fam.nbr]
    scale = family_magnitude(fam.offsets, fam.intact * (w * fam.length * pair + dev * moved))
    assert_close(linear.lps_linear_force(*args), ref.lps_linear_force(*args), TOL64, scale)
