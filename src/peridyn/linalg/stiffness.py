"""Stiffness and mass matrices of the linearised models, and the matrix-free operator.

Everything here is asked of the material through ``Model.linearisation()``
(``peridyn.physics.materials.linearisation.BondLinearisation``): the linear bond form
t_ij = axial_ij (P_i + P_j) + extension_ij e_ij, e = n . (u_j - u_i), and the energy
density W_p = (1/4) sum_j pair_pj e_pj^2 + c_p theta_p^2, theta_p = theta_coef_p sum_j
weight_pj |xi| e_pj. No material is named: a bond-based material (PMB) has no dilatation part,
a state-based one (LPS) has one.

Degrees of freedom are ordered point-major: dof = 3 i + a (a = x, y, z); 2D
bodies keep their z dofs (they carry no stiffness: constrain or drop them with
``free_dofs``). Forces are integrated over the volumes, so ``K u = -V f(u)`` for
small ``u`` (N), and the lumped mass is ``M = rho V`` (kg).

Each directed bond p->j adds the energy V_p pair_pj (n . eta)^2 / 4 (eta = u_j - u_p).
With a dilatation, theta_p = g_p . u couples p with its whole family, so each point adds a
dense block 2 c_p V_p g_p g_p^T over its family: the matrix reaches two horizons
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

from peridyn.kernels.pairs import pair_row_counts, pair_rows
from peridyn.physics.materials.base import Model


def mass_matrix(model: Model) -> sp.dia_matrix:
    """Lumped mass (3 n, 3 n), kg: rho_i V_i on the three dofs of point i."""
    m = np.repeat(model.density * model.body.volumes, 3)
    return sp.diags(m)


def linear_force(model: Model, u: np.ndarray) -> np.ndarray:
    """Linearised internal force density (n_points, 3), N/m^3, of ``u`` (n_points, 3), m
    (``kernels.linear``; the coefficients of ``model.linearisation()``)."""
    return model.linearisation().force(model.body.points, model.bonds, u)


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
        Dilatation gradients, theta_p = (G u)_p; None for a material without dilatation.
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
    lin = model.linearisation()
    pair = vol[owners] * lin.pair  # the energy V_p pair e^2 / 4 per bond
    k_pair = pair_matrix(owners[counted], b.neighbours[counted], n_vec[counted], pair[counted], n)
    if not lin.has_dilatation:
        return StiffnessParts(k_pair)
    w = np.where(counted, lin.weight, 0.0)
    a = lin.theta_coef[owners] * w * b.length  # d theta_p / d e_pj
    gradients = _dilatation_gradients(owners, b.neighbours, n_vec, a, n)
    return StiffnessParts(k_pair, gradients, 2.0 * lin.dilatation_energy * vol)


def assemble_stiffness(model: Model, energy_of: np.ndarray | None = None) -> sp.csr_matrix:
    """Assembled stiffness (3 n, 3 n), N/m, symmetric for equal cells (grids).

    ``energy_of``: see :func:`stiffness_parts`.
    """
    return stiffness_parts(model, energy_of).assemble()


#: Entries (duplicates included) of the pair-matrix rows handled at once: 12 B each, 48 MB (400
#: MB at 2**25 was the peak of an MPI rank's modal run: 990 of 1031 MiB for the 135k plate's
#: proxy, whose matrix holds 44 MB; the rows' sums are the same bits at any chunk size).
PAIR_CHUNK_ENTRIES = 2**22


def pair_matrix(i, j, n_vec, coef, n_points, drop_zeros: bool = False) -> sp.csr_matrix:
    """Sum over bonds of coef (n n^T) / 2 on the blocks ii, jj and -coef (n n^T) / 2 on ij, ji.

    ``i``, ``j``: (n_bonds,) int; ``n_vec``: (n_bonds, 3) float64; ``coef``: (n_bonds,) float64.
    Returns (3 n_points, 3 n_points) CSR, canonical (sorted, no duplicates); ``drop_zeros``:
    without the entries that sum to zero (most of an axis-parallel bond's block), dropped chunk
    by chunk, so that they are never all held at once. The rows are
    written with their duplicates by ``kernels.pairs`` a chunk of about ``PAIR_CHUNK_ENTRIES``
    entries at a time and summed by scipy, in the same order as scipy's COO conversion of the
    whole list (the same bits), without the 24 B per entry of a COO list of 36 entries per bond.
    """
    i = np.ascontiguousarray(i)
    j = np.ascontiguousarray(j)
    n_vec = np.ascontiguousarray(n_vec, dtype=np.float64)
    coef = np.ascontiguousarray(coef, dtype=np.float64)
    counts = pair_row_counts(i, j, n_points)
    ends = np.cumsum(counts)
    chunks = []
    row = 0
    while row < 3 * n_points:
        before = ends[row - 1] if row else 0
        stop = max(row + 1, int(np.searchsorted(ends, before + PAIR_CHUNK_ENTRIES, side="right")))
        stop = min(stop, 3 * n_points)
        indptr = np.concatenate([[0], ends[row:stop] - before])
        indices = np.empty(indptr[-1], dtype=np.int32)
        data = np.empty(indptr[-1])
        pair_rows(i, j, n_vec, coef, row, indptr, indices, data)
        chunk = sp.csr_matrix((data, indices, indptr), shape=(stop - row, 3 * n_points))
        chunk.has_sorted_indices = False  # sort every row, as scipy sorts a whole unsorted matrix
        chunk.sum_duplicates()
        if drop_zeros:
            chunk.eliminate_zeros()
        chunks.append(chunk)
        row = stop
    if len(chunks) <= 1:
        return chunks[0] if chunks else sp.csr_matrix((0, 0))
    return sp.vstack(chunks, format="csr")


def _dilatation_gradients(owners, nbr, n_vec, a, n_points) -> sp.csr_matrix:
    """G (n, 3 n): row p holds g_p = sum_j a_pj n_pj (e_j - e_p), so theta_p = g_p . u."""
    g = a[:, None] * n_vec  # (nb, 3)
    comp = np.arange(3)
    rows = np.concatenate([np.repeat(owners, 3), np.repeat(owners, 3)])
    cols = np.concatenate([(3 * nbr[:, None] + comp).ravel(), (3 * owners[:, None] + comp).ravel()])
    vals = np.concatenate([g.ravel(), -g.ravel()])
    return sp.coo_matrix((vals, (rows, cols)), shape=(n_points, 3 * n_points)).tocsr()
