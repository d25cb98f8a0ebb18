"""Stiffness and mass matrices of the linearised models, and the matrix-free operator.

Degrees of freedom are ordered point-major: dof = 3 i + a (a = x, y, z); 2D
bodies keep their z dofs (they carry no stiffness: constrain or drop them with
``free_dofs``). Forces are integrated over the volumes, so ``K u = -V f(u)`` for
small ``u`` (N), and the lumped mass is ``M = rho V`` (kg).

PMB: each directed bond i->j adds the energy (V_i k_ij / |xi|) (n . eta)^2 / 2.
LPS: the energy of point p is V_p [c_p theta_p^2 + (alpha_p / 2) sum_j w e^2] with
c_p = kappa / 2 - alpha_p m_p / (2 d^2) (since sum w (e^d)^2 = sum w e^2 - m theta^2 / d^2);
theta_p = g_p . u couples p with its whole family, so each point adds a dense
block 2 c_p V_p g_p g_p^T over its family: the matrix reaches two horizons
(about (n_family + 1)^2 blocks per point). For large families use
``stiffness_operator``, which applies K without storing it.
"""

from __future__ import annotations

import numba
import numpy as np
import scipy.sparse as sp
from scipy.sparse.linalg import LinearOperator

from peridyn.kernels.linear import lps_linear_force, pmb_linear_force
from peridyn.materials import LPSModel, Model, PMBModel


def mass_matrix(model: Model) -> sp.dia_matrix:
    """Lumped mass (3 n, 3 n), kg: rho_i V_i on the three dofs of point i."""
    m = np.repeat(model.density * model.body.volumes, 3)
    return sp.diags(m)


def linear_force(model: Model, u: np.ndarray) -> np.ndarray:
    """Linearised internal force density (n_points, 3), N/m^3 (see ``kernels.linear``)."""
    b = model.bonds
    x = model.body.points
    u = np.ascontiguousarray(u, dtype=np.float64)
    if isinstance(model, PMBModel):
        return pmb_linear_force(x, u, b.offsets, b.neighbours, b.length,
                                model.bond_stiffness.astype(np.float64), b.intact)
    if isinstance(model, LPSModel):
        return lps_linear_force(x, u, b.offsets, b.neighbours, b.length,
                                model.w.astype(np.float64), b.intact, model.theta_coef,
                                model._p_coef.astype(np.float64), model.alpha)
    raise TypeError(f"no linearisation for {type(model).__name__}")


def stiffness_operator(model: Model) -> LinearOperator:
    """K as a LinearOperator (3 n, 3 n), N/m: v -> -V f_lin(v); no matrix is stored."""
    n = model.body.n_points
    vol = np.repeat(model.body.volumes, 3)

    def matvec(v):
        return -vol * linear_force(model, np.reshape(v, (n, 3))).ravel()

    return LinearOperator((3 * n, 3 * n), matvec=matvec, rmatvec=matvec, dtype=np.float64)


def assemble_stiffness(model: Model, energy_of: np.ndarray | None = None) -> sp.csr_matrix:
    """Assembled stiffness (3 n, 3 n), N/m, symmetric for equal cells (grids).

    ``energy_of`` ((n,) bool, default all points): assemble the Hessian of the energy
    of these points only (``sum_p V_p W_p`` over them), e.g. one periodic cell's share.
    """
    b = model.bonds
    x = model.body.points
    owners = b.owners()
    n_vec = (x[b.neighbours] - x[owners]) / b.length[:, None]
    vol = model.body.volumes
    if energy_of is not None:
        vol = np.where(energy_of, vol, 0.0)
    counted = b.intact & (vol[owners] > 0)
    if isinstance(model, PMBModel):
        pair = vol[owners] * model.bond_stiffness.astype(np.float64) / b.length  # W = k e^2 / 4L
        return _pair_matrix(owners[counted], b.neighbours[counted], n_vec[counted], pair[counted],
                            model.body.n_points)
    if isinstance(model, LPSModel):
        w = np.where(b.intact, model.w.astype(np.float64), 0.0)
        pair = 2.0 * vol[owners] * model.alpha[owners] * w  # (V alpha w / 2) e^2 per bond
        k_pair = _pair_matrix(owners[counted], b.neighbours[counted], n_vec[counted], pair[counted],
                              model.body.n_points)
        d = model.dim
        c = 0.5 * model.bulk - model.alpha * model.weighted_volume / (2 * d * d)
        a = model.theta_coef[owners] * w * b.length  # d theta_p / d e_pj
        rows, cols, vals = _dilatation_blocks(b.offsets, b.neighbours, n_vec, a, 2.0 * c * vol)
        k_dil = sp.coo_matrix((vals, (rows, cols)), shape=k_pair.shape).tocsr()
        return (k_pair + k_dil).tocsr()
    raise TypeError(f"no stiffness for {type(model).__name__}")


def _pair_matrix(i, j, n_vec, coef, n_points) -> sp.csr_matrix:
    """Sum over bonds of coef (n n^T) on the blocks ii, jj and -coef (n n^T) on ij, ji."""
    outer = coef[:, None, None] * n_vec[:, :, None] * n_vec[:, None, :]  # (nb, 3, 3)
    a = np.arange(3)
    rows = []
    cols = []
    vals = []
    for p, q, sign in ((i, i, 1.0), (j, j, 1.0), (i, j, -1.0), (j, i, -1.0)):
        rows.append((3 * p[:, None, None] + a[None, :, None]).repeat(3, axis=2).ravel())
        cols.append((3 * q[:, None, None] + a[None, None, :]).repeat(3, axis=1).ravel())
        vals.append(sign * 0.5 * outer.ravel())
    shape = (3 * n_points, 3 * n_points)
    return sp.coo_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
                         shape=shape).tocsr()


@numba.njit(cache=True)
def _dilatation_blocks(offsets, nbr, n_vec, a, scale):
    """COO triplets of sum_p scale_p g_p g_p^T, g_p = sum_j a_pj n_pj (e_j - e_p)."""
    n = offsets.shape[0] - 1
    total = 0
    for p in range(n):
        if scale[p] == 0.0:
            continue
        m = offsets[p + 1] - offsets[p] + 1
        total += 9 * m * m
    rows = np.empty(total, dtype=np.int64)
    cols = np.empty(total, dtype=np.int64)
    vals = np.empty(total)
    pos = 0
    for p in range(n):
        if scale[p] == 0.0:
            continue
        lo, hi = offsets[p], offsets[p + 1]
        m = hi - lo + 1
        nodes = np.empty(m, dtype=np.int64)
        g = np.zeros((m, 3))
        nodes[0] = p
        for k in range(lo, hi):
            nodes[k - lo + 1] = nbr[k]
            for c in range(3):
                g[k - lo + 1, c] = a[k] * n_vec[k, c]
                g[0, c] -= a[k] * n_vec[k, c]
        for r in range(m):
            for s in range(m):
                for c1 in range(3):
                    for c2 in range(3):
                        rows[pos] = 3 * nodes[r] + c1
                        cols[pos] = 3 * nodes[s] + c2
                        vals[pos] = scale[p] * g[r, c1] * g[s, c2]
                        pos += 1
    return rows, cols, vals
