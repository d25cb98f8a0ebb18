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

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
from scipy.sparse.linalg import LinearOperator

from peridyn.kernels.tangent import bond_blocks_csr, deformed_bonds, tangent_action, tangent_extension
from peridyn.physics.materials.base import Model


@dataclass(frozen=True)
class BondTangent:
    """The tangent's per-bond quantities at one displacement (all (n_bonds,) float64 unless said).

    Attributes
    ----------
    bond : (n_bonds, 3) deformed bond vectors Y, m
    r : deformed bond lengths |Y|, m
    stretch : dT/dr (0 on broken bonds), N/m^4
    geometric : T / r, the rotation term (0 on broken bonds), N/m^4
    axial : w |xi| on intact bonds (m^4), or None without dilatation
    dilatation : (n_points,) p_coef theta_coef, or None without dilatation
    """

    bond: np.ndarray
    r: np.ndarray
    stretch: np.ndarray
    geometric: np.ndarray
    axial: np.ndarray | None
    dilatation: np.ndarray | None

    @property
    def n_vec(self) -> np.ndarray:
        """(n_bonds, 3) deformed unit vectors Y / r."""
        return self.bond / self.r[:, None]


def bond_tangent(model: Model, u: np.ndarray) -> BondTangent:
    """The ``BondTangent`` of ``model`` at displacement ``u`` (n, 3), m (of a material linear in
    u, ``Model.is_linear``, the one at rest)."""
    if model.is_linear:
        u = np.zeros_like(u, dtype=np.float64)
    b = model.bonds
    owners = b.owners()
    nbr = b.neighbours.astype(np.int64)
    x = model.body.points
    u = np.asarray(u, dtype=np.float64)
    bond = deformed_bonds(x, u, b.offsets, nbr, np.empty((len(nbr), 3)))
    r = np.linalg.norm(bond, axis=1)
    length = b.length
    lin = model.linearisation()
    e = r - length
    k = np.where(b.intact, lin.extension, 0.0)
    force = k * e
    axial = dilatation = None
    if lin.has_dilatation:
        axial = np.where(b.intact, lin.weight, 0.0) * length
        dilatation = lin.p_coef * lin.theta_coef
        p = lin.theta_coef * np.bincount(owners, weights=axial * e, minlength=len(x)) * lin.p_coef
        force = axial * (p[owners] + p[nbr]) + force
    return BondTangent(bond, r, k, force / r, axial, dilatation)


def tangent_stiffness(model: Model, u: np.ndarray) -> sp.csr_matrix:
    """Consistent tangent K(u) = -d(V f)/du (3 n, 3 n), N/m, at displacement ``u`` (n, 3), m;
    of a material linear in u (``Model.is_linear``) its one tangent, the one at rest."""
    t = bond_tangent(model, u)
    b = model.bonds
    nbr = b.neighbours.astype(np.int64)
    n_vec = t.n_vec
    jacobian = _bond_blocks(b.offsets, nbr, n_vec, t.stretch, t.geometric)
    if t.axial is not None:
        jacobian = jacobian + _dilatation_jacobian(t, n_vec, b.owners(), nbr)
    vol = sp.diags(np.repeat(model.body.volumes, 3))
    return (-(vol @ jacobian)).tocsr()


def tangent_operator(model: Model, u: np.ndarray, dofs: np.ndarray) -> LinearOperator:
    """K(u)[dofs][:, dofs] (N/m) applied matrix-free: two passes over the bonds per product
    (``kernels.tangent.tangent_extension`` and ``tangent_action``), nothing assembled, so the
    memory is the bonds' whatever the horizon (the assembled LPS tangent reaches two horizons:
    85 million entries for a 38 400-point plate at a horizon of two spacings).

    d f_i = sum_j [dT n + (T / r) (dY - n (n . dY))] with dT = stretch (n . dY) + axial (dP_i + dP_j)
    (module docstring): bond forces along the deformed directions with the coefficient
    stretch - T / r, plus T / r times the difference of the two ends' dY."""
    t = bond_tangent(model, u)
    b = model.bonds
    n = model.body.n_points
    vol = model.body.volumes[:, None]
    n_vec = t.n_vec
    along = t.stretch - t.geometric
    axial = np.zeros(b.n_bonds) if t.axial is None else t.axial
    dilatation = np.zeros(n) if t.dilatation is None else t.dilatation
    nbr = b.neighbours
    extension, theta, df = np.empty(b.n_bonds), np.empty(n), np.empty((n, 3))
    size = len(dofs)

    def matvec(v):
        full = np.zeros(3 * n)
        full[dofs] = np.ravel(v)
        dv = full.reshape(n, 3)
        tangent_extension(b.offsets, nbr, n_vec, axial, dv, extension, theta)
        tangent_action(
            b.offsets, nbr, n_vec, axial, along, t.geometric, dilatation * theta, extension, dv, df
        )
        return (-vol * df).reshape(-1)[dofs].reshape(np.shape(v))

    return LinearOperator((size, size), matvec=matvec, rmatvec=matvec, dtype=np.float64)


def _bond_blocks(offsets, nbr, n_vec, stretch, geometric) -> sp.csr_matrix:
    """df/du of f_i = sum_j T n: block B = stretch n n^T + geometric (I - n n^T) per bond,
    +B on (i, j) and -B on (i, i). Shapes: (n_bonds,) and (n_bonds, 3)."""
    n = len(offsets) - 1
    indptr, indices, data = bond_blocks_csr(offsets, nbr, n_vec, stretch, geometric)
    return sp.csr_matrix((data, indices, indptr), shape=(3 * n, 3 * n))


def _dilatation_jacobian(t: BondTangent, n_vec, owners, nbr) -> sp.csr_matrix:
    """d f_i = sum_j w_ij L_ij n_ij (dP_i + dP_j) as the product H G (see module) at the
    ``BondTangent`` ``t``; ``n_vec`` (n_bonds, 3) its unit vectors, ``owners`` and ``nbr``
    (n_bonds,) the bonds' end points."""
    n = len(t.dilatation)
    wl = t.axial
    a = np.arange(3)
    h_rows = (3 * owners[:, None] + a).ravel()
    h_vals = (wl[:, None] * n_vec).ravel()
    to_j = sp.coo_matrix((h_vals, (h_rows, np.repeat(nbr, 3))), shape=(3 * n, n))
    to_i = sp.coo_matrix((h_vals, (h_rows, np.repeat(owners, 3))), shape=(3 * n, n))
    h = (to_j + to_i).tocsr()
    g_vals = (t.dilatation[owners] * wl)[:, None] * n_vec
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
