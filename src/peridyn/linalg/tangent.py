"""Consistent tangent stiffness of a material at a deformed state.

``K(u) = -d(V f(u)) / du`` (3 n, 3 n), N/m, the exact Jacobian of the force kernels
(``peridyn.kernels.pmb``, ``peridyn.kernels.lps``), so that Newton's method on
``V f(u) + V b = 0`` converges quadratically. At ``u = 0`` it equals the linear
stiffness of ``peridyn.linalg.stiffness.assemble_stiffness``.

The material is asked only for its ``Model.linearisation()``
(``peridyn.physics.materials.linearisation``). The force on point i is a sum over its intact
bonds i->j of a scalar T_ij along the deformed bond direction n = Y / r, Y = xi + u_j - u_i,
r = |Y|:

    f_i = sum_j T_ij n_ij,   T_ij = axial_ij (P_i + P_j) + extension_ij e_ij,   e = r - L,

with L = |xi|, axial = weight L, P_k = p_coef_k theta_k and theta_k = theta_coef_k
sum_m axial_km e_km (no P for a material without dilatation, e.g. PMB: T = (k / L) e).
Differentiating with dY = du_j - du_i, dn = (I - n n^T) dY / r:

    d f_i = sum_j [ (dT/dr) n n^T + (T / r) (I - n n^T) ] dY  +  (terms of T through other dofs).

The first bracket is the bond block B: a stretch term along n, dT/dr = extension, and a
geometric (rotation) term across it, T / r, which vanishes in the reference state.
With a dilatation (LPS), P_k also varies with u: dP_k = p_coef_k theta_coef_k sum_m axial_km
n_km . dY_km, which adds d f_i = sum_j axial_ij n_ij (dP_i + dP_j), a product H G of two
sparse matrices (H: (3 n, n) bond directions weighted by axial; G: (n, 3 n) the gradient of
P). This term reaches two horizons.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from peridyn.kernels.tangent import bond_blocks_csr
from peridyn.physics.materials.base import Model
from peridyn.physics.materials.linearisation import BondLinearisation


def tangent_stiffness(model: Model, u: np.ndarray) -> sp.csr_matrix:
    """Consistent tangent K(u) = -d(V f)/du (3 n, 3 n), N/m, at displacement ``u`` (n, 3), m;
    of a material linear in u (``Model.is_linear``) its one tangent, the one at rest."""
    if model.is_linear:
        u = np.zeros_like(u, dtype=np.float64)
    b = model.bonds
    owners = b.owners()
    nbr = b.neighbours.astype(np.int64)
    x = model.body.points
    u = np.asarray(u, dtype=np.float64)
    y = x[nbr] - x[owners] + u[nbr] - u[owners]
    r = np.linalg.norm(y, axis=1)
    n_vec = y / r[:, None]
    length = b.length
    lin = model.linearisation()
    e = r - length
    k = np.where(b.intact, lin.extension, 0.0)
    force = k * e
    if lin.has_dilatation:
        w = np.where(b.intact, lin.weight, 0.0)
        theta = lin.theta_coef * np.bincount(owners, weights=w * length * e, minlength=len(x))
        p = theta * lin.p_coef
        force = w * length * (p[owners] + p[nbr]) + force
    jacobian = _bond_blocks(b.offsets, nbr, n_vec, k, force / r)
    if lin.has_dilatation:
        jacobian = jacobian + _dilatation_jacobian(lin, length, owners, nbr, n_vec, w)
    vol = sp.diags(np.repeat(model.body.volumes, 3))
    return (-(vol @ jacobian)).tocsr()


def _bond_blocks(offsets, nbr, n_vec, stretch, geometric) -> sp.csr_matrix:
    """df/du of f_i = sum_j T n: block B = stretch n n^T + geometric (I - n n^T) per bond,
    +B on (i, j) and -B on (i, i). Shapes: (n_bonds,) and (n_bonds, 3)."""
    n = len(offsets) - 1
    indptr, indices, data = bond_blocks_csr(offsets, nbr, n_vec, stretch, geometric)
    return sp.csr_matrix((data, indices, indptr), shape=(3 * n, 3 * n))


def _dilatation_jacobian(lin: BondLinearisation, length, owners, nbr, n_vec, w) -> sp.csr_matrix:
    """d f_i = sum_j w_ij L_ij n_ij (dP_i + dP_j) as the product H G (see module); ``w`` the
    intact bonds' weights (n_bonds,), m^3, ``length`` L (n_bonds,), m."""
    n = len(lin.theta_coef)
    wl = w * length
    a = np.arange(3)
    h_rows = (3 * owners[:, None] + a).ravel()
    h_vals = (wl[:, None] * n_vec).ravel()
    to_j = sp.coo_matrix((h_vals, (h_rows, np.repeat(nbr, 3))), shape=(3 * n, n))
    to_i = sp.coo_matrix((h_vals, (h_rows, np.repeat(owners, 3))), shape=(3 * n, n))
    h = (to_j + to_i).tocsr()
    g_vals = ((lin.p_coef * lin.theta_coef)[owners] * wl)[:, None] * n_vec
    g_vals = g_vals.ravel()
    g_cols_j = (3 * nbr[:, None] + a).ravel()
    g_cols_i = (3 * owners[:, None] + a).ravel()
    g_rows = np.repeat(owners, 3)
    g = sp.coo_matrix(
        (
            np.concatenate([g_vals, -g_vals]),
            (np.concatenate([g_rows, g_rows]), np.concatenate([g_cols_j, g_cols_i])),
        ),
        shape=(n, 3 * n),
    ).tocsr()
    return (h @ g).tocsr()
