"""Stiffness and mass matrices of the linearised models, and the matrix-free operator.

Degrees of freedom are ordered point-major: dof = 3 i + a (a = x, y, z); 2D
bodies keep their z dofs (they carry no stiffness: constrain or drop them with
``free_dofs``). Forces are integrated over the volumes, so ``K u = -V f(u)`` for
small ``u`` (N), and the lumped mass is ``M = rho V`` (kg).

PMB: each directed bond i->j adds the energy (V_i k_ij / |xi|) (n . eta)^2 / 2.
LPS: the energy of point p is V_p [c_p theta_p^2 + (alpha_p / 2) sum_j g_pj w e^2] with
c_p = kappa / 2 - alpha_p m~_p / (2 d^2) (``peridyn.physics.materials.lps``; without surface
correction g = 1, m~ = m and sum w (e^d)^2 = sum w e^2 - m theta^2 / d^2);
theta_p = g_p . u couples p with its whole family, so each point adds a dense
block 2 c_p V_p g_p g_p^T over its family: the matrix reaches two horizons
(about (n_family + 1)^2 blocks per point). ``stiffness_parts`` keeps it factored
as K = K_pair + G^T diag(2 c V) G, with G (n, 3 n) as sparse as the bonds: the
eigensolver factorises the augmented matrix built from it instead of K. For
large families ``stiffness_operator`` applies K without storing it.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
from scipy.sparse.linalg import LinearOperator

from peridyn.kernels.linear import lps_linear_force, pmb_linear_force
from peridyn.physics.materials import LPSModel, Model, PMBModel


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
        return pmb_linear_force(
            x, u, b.offsets, b.neighbours, b.length, model.bond_stiffness.astype(np.float64), b.intact
        )
    if isinstance(model, LPSModel):
        return lps_linear_force(
            x,
            u,
            b.offsets,
            b.neighbours,
            b.length,
            model.w.astype(np.float64),
            model.dev.astype(np.float64),
            b.intact,
            model.theta_coef,
            model._p_coef.astype(np.float64),
        )
    raise TypeError(f"no linearisation for {type(model).__name__}")


def stiffness_operator(model: Model) -> LinearOperator:
    """K as a LinearOperator (3 n, 3 n), N/m: v -> -V f_lin(v); no matrix is stored."""
    n = model.body.n_points
    vol = np.repeat(model.body.volumes, 3)

    def matvec(v):
        return -vol * linear_force(model, np.reshape(v, (n, 3))).ravel()

    return LinearOperator((3 * n, 3 * n), matvec=matvec, rmatvec=matvec, dtype=np.float64)


@dataclass
class StiffnessParts:
    """The stiffness split as ``K = pair + G^T diag(dilatation) G`` (all N/m, dofs point-major).

    Attributes
    ----------
    pair : (3 n, 3 n) csr_matrix
        Bond-pair part: sum over bonds of coef (n n^T) on the ii, jj, -ij, -ji blocks.
    G : (n, 3 n) csr_matrix or None
        LPS dilatation gradients, theta_p = (G u)_p; None for PMB.
    dilatation : (n,) float64 or None, J
        2 c_p V_p: the second derivative of each point's energy V_p c_p theta_p^2.
    """

    pair: sp.csr_matrix
    G: sp.csr_matrix | None = None
    dilatation: np.ndarray | None = None

    def diagonal(self) -> np.ndarray:
        """diag(K) (3 n,), N/m, without assembling K."""
        d = self.pair.diagonal()
        if self.G is not None:
            d = d + self.G.multiply(self.G).T @ self.dilatation
        return d

    def restricted(self, dofs: np.ndarray) -> LinearOperator:
        """K on the ``dofs`` (K[dofs][:, dofs]) as an operator, without assembling K."""
        pair = self.pair[dofs][:, dofs]
        G = None if self.G is None else self.G[:, dofs].tocsr()

        def matvec(v):
            out = pair @ v
            if G is not None:
                gv = G @ v
                out += G.T @ (self.dilatation.reshape(-1, *[1] * (gv.ndim - 1)) * gv)
            return out

        n = len(dofs)
        return LinearOperator((n, n), matvec=matvec, rmatvec=matvec, dtype=np.float64)

    def assemble(self) -> sp.csr_matrix:
        """The full stiffness (3 n, 3 n)."""
        if self.G is None:
            return self.pair
        return (self.pair + self.G.T @ sp.diags(self.dilatation) @ self.G).tocsr()


def stiffness_parts(model: Model, energy_of: np.ndarray | None = None) -> StiffnessParts:
    """The two sparse parts of the stiffness; see :class:`StiffnessParts`.

    ``energy_of`` ((n,) bool, default all points): the Hessian of the energy of these
    points only (``sum_p V_p W_p`` over them), e.g. one periodic cell's share.
    """
    b = model.bonds
    x = model.body.points
    owners = b.owners()
    n_vec = (x[b.neighbours] - x[owners]) / b.length[:, None]
    vol = model.body.volumes
    if energy_of is not None:
        vol = np.where(energy_of, vol, 0.0)
    counted = b.intact & (vol[owners] > 0)
    n = model.body.n_points
    if isinstance(model, PMBModel):
        pair = vol[owners] * model.bond_stiffness.astype(np.float64) / b.length  # W = k e^2 / 4L
        return StiffnessParts(
            pair_matrix(owners[counted], b.neighbours[counted], n_vec[counted], pair[counted], n)
        )
    if isinstance(model, LPSModel):
        w = np.where(counted, model.w.astype(np.float64), 0.0)
        # (V alpha g w / 2) e^2 per bond
        pair = 2.0 * vol[owners] * model.alpha[owners] * model.dev_factor * w
        k_pair = pair_matrix(owners[counted], b.neighbours[counted], n_vec[counted], pair[counted], n)
        d = model.dim
        c = 0.5 * model.bulk - model.alpha * model.dev_weighted_volume / (2 * d * d)
        a = model.theta_coef[owners] * w * b.length  # d theta_p / d e_pj
        return StiffnessParts(k_pair, _dilatation_gradients(owners, b.neighbours, n_vec, a, n), 2.0 * c * vol)
    raise TypeError(f"no stiffness for {type(model).__name__}")


def assemble_stiffness(model: Model, energy_of: np.ndarray | None = None) -> sp.csr_matrix:
    """Assembled stiffness (3 n, 3 n), N/m, symmetric for equal cells (grids).

    ``energy_of``: see :func:`stiffness_parts`.
    """
    return stiffness_parts(model, energy_of).assemble()


def pair_matrix(i, j, n_vec, coef, n_points) -> sp.csr_matrix:
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
    return sp.coo_matrix(
        (np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))), shape=shape
    ).tocsr()


def _dilatation_gradients(owners, nbr, n_vec, a, n_points) -> sp.csr_matrix:
    """G (n, 3 n): row p holds g_p = sum_j a_pj n_pj (e_j - e_p), so theta_p = g_p . u."""
    g = a[:, None] * n_vec  # (nb, 3)
    comp = np.arange(3)
    rows = np.concatenate([np.repeat(owners, 3), np.repeat(owners, 3)])
    cols = np.concatenate([(3 * nbr[:, None] + comp).ravel(), (3 * owners[:, None] + comp).ravel()])
    vals = np.concatenate([g.ravel(), -g.ravel()])
    return sp.coo_matrix((vals, (rows, cols)), shape=(n_points, 3 * n_points)).tocsr()
