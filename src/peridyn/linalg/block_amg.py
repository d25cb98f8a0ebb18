"""One smoothed-aggregation AMG V-cycle applied to a block of vectors at once.

LOBPCG asks its preconditioner for a dozen vectors at every iteration. pyamg's cycle
works on one vector, so each column would read every level's matrix again; here the
k columns sit next to each other (shape (n_blocks, block_rows, k)) and each matrix entry
is read once per sweep for all of them. The columns are split into one group per
thread (``numba`` threads, each group its own contiguous array), so both cores work
without sharing a cache line.

The cycle is pyamg's V-cycle (``pyamg.MultilevelSolver``) for the hierarchy that
``smoothed_aggregation_hierarchy`` builds: one symmetric block Gauss-Seidel sweep before
and after the coarse correction on every level (block = the BSR block of that level),
restriction R = P^T, and pyamg's pseudo-inverse on the coarsest level, here a Cholesky solve
on its non-zero rows (``_CoarseSolver``). Pre- and post-smoother are
each other's adjoints and R = P^T, so the cycle is a symmetric positive definite
operator when the matrix is (Vassilevski 2008, Multilevel Block Factorization
Preconditioners, ch. 5).
"""

from __future__ import annotations

import numba
import numpy as np
import scipy.linalg
import scipy.sparse as sp

from peridyn.kernels.bsr import bsr_matmat, symmetric_block_gauss_seidel

#: pyamg options of the hierarchy this cycle reproduces (smoothers and coarse solver).
SMOOTHER = ("block_gauss_seidel", {"sweep": "symmetric", "iterations": 1})
COARSE_SOLVER = "pinv"


def smoothed_aggregation_hierarchy(
    a: sp.bsr_matrix, near_null: np.ndarray, first_aggregates=None, max_coarse: int = 500
):
    """pyamg smoothed-aggregation hierarchy of the SPD ``a`` with the smoother and coarse solver
    that ``BlockVCycle`` applies; ``first_aggregates`` (n_block_rows, n_aggregates) sparse, or
    None for pyamg's standard aggregation on the first level too."""
    import pyamg

    aggregate = (
        "standard"
        if first_aggregates is None
        else [("predefined", {"AggOp": first_aggregates.tocsr()}), "standard"]
    )
    return pyamg.smoothed_aggregation_solver(
        a,
        B=near_null,
        symmetry="hermitian",
        strength=("symmetric", {"theta": 0.0}),
        aggregate=aggregate,
        presmoother=SMOOTHER,
        postsmoother=SMOOTHER,
        coarse_solver=COARSE_SOLVER,
        max_coarse=max_coarse,
    )


class _BSR:
    """A sparse matrix's BSR arrays (float64, sorted block indices) and its product with blocks."""

    def __init__(self, matrix, blocksize=None):
        m = sp.bsr_matrix(matrix, blocksize=blocksize)
        m.sort_indices()
        self.indptr, self.indices = m.indptr, m.indices
        self.data = np.ascontiguousarray(m.data, dtype=np.float64)
        self.blocksize = m.blocksize
        self.shape = m.shape

    def __matmul__(self, x):
        out = np.empty(
            (x.shape[0], self.shape[0] // self.blocksize[0], self.blocksize[0], x.shape[3]), dtype=x.dtype
        )
        return bsr_matmat(self.indptr, self.indices, self.data, x, out)


class _CoarseSolver:
    """Solution of the coarsest system by Cholesky, zero on the unknowns whose row is zero (the
    columns of the tentative prolongator an aggregate with too few points cannot fill): the
    same as pyamg's pseudo-inverse when the remaining matrix is SPD, at a fraction of an SVD's
    cost (2 592 unknowns: 50 s for the SVD on this machine)."""

    def __init__(self, a: np.ndarray):
        self.active = np.flatnonzero(np.abs(a).max(axis=1) > 0)
        self.factor = scipy.linalg.cho_factor(a[np.ix_(self.active, self.active)])
        self.size = len(a)

    def __call__(self, b: np.ndarray) -> np.ndarray:
        x = np.zeros_like(b)
        x[self.active] = scipy.linalg.cho_solve(self.factor, b[self.active])
        return x


class BlockVCycle:
    """pyamg's V-cycle of ``hierarchy`` (from ``smoothed_aggregation_hierarchy``) on (n,) or
    (n, k) float64 arrays, all k columns at once."""

    def __init__(self, hierarchy):
        from pyamg.util.utils import get_block_diag

        self.A, self.diag_inv, self.P, self.R = [], [], [], []
        blocks = [sp.bsr_matrix(level.A).blocksize[0] for level in hierarchy.levels]
        for level, fine, coarse in zip(hierarchy.levels[:-1], blocks[:-1], blocks[1:], strict=True):
            a = sp.bsr_matrix(level.A)
            self.A.append(_BSR(a))
            self.diag_inv.append(
                np.ascontiguousarray(get_block_diag(a, blocksize=fine, inv_flag=True), dtype=np.float64)
            )
            self.P.append(_BSR(level.P, (fine, coarse)))
            self.R.append(_BSR(level.R, (coarse, fine)))
        self.coarse = _CoarseSolver(hierarchy.levels[-1].A.toarray())
        self.shape = hierarchy.levels[0].A.shape
        self.rows = blocks[0]
        self.groups = numba.get_num_threads()

    def __call__(self, v: np.ndarray) -> np.ndarray:
        v = np.asarray(v)
        block = v.reshape(len(v), -1)
        k = block.shape[1]
        groups = max(1, min(self.groups, k))
        kg = -(-k // groups)
        padded = np.zeros((len(v), groups * kg))
        padded[:, :k] = block
        b = np.ascontiguousarray(padded.reshape(-1, self.rows, groups, kg).transpose(2, 0, 1, 3))
        x = self._cycle(0, b)
        out = x.transpose(1, 2, 0, 3).reshape(len(v), groups * kg)[:, :k]
        return np.ascontiguousarray(out).reshape(v.shape)

    def _cycle(self, level, b):
        """V-cycle from zero on ``level`` for the right-hand sides ``b`` (groups, n_blocks, R, kg)."""
        if level == len(self.A):
            groups, kg = b.shape[0], b.shape[3]
            x = self.coarse(b.transpose(1, 2, 0, 3).reshape(-1, groups * kg))
            return np.ascontiguousarray(x.reshape(-1, b.shape[2], groups, kg).transpose(2, 0, 1, 3))
        A = self.A[level]
        x = np.zeros_like(b)
        symmetric_block_gauss_seidel(A.indptr, A.indices, A.data, self.diag_inv[level], x, b)
        residual = b - A @ x
        x += self.P[level] @ self._cycle(level + 1, self.R[level] @ residual)
        symmetric_block_gauss_seidel(A.indptr, A.indices, A.data, self.diag_inv[level], x, b)
        return x
