"""Sparse LU of the shifted stiffness K + s M (or of its augmented form), as an operator.

For LPS the stiffness is kept factored, K = K_pair + G^T diag(c) G (``linalg.stiffness``), and
the augmented system [[K_pair + s M, G^T], [G, -diag(1 / c)]] is factorised instead: its Schur
complement on the dofs is K + s M, and it is as sparse as the bonds, where K reaches two
horizons. Used by the shift-invert eigensolver (``solvers.modal``) and the fatigue statics;
``ordered_lu`` by the Newton and Newmark systems too (``linalg.tangent_solve``).
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
from scipy.sparse.linalg import LinearOperator, splu

from peridyn import interrupts
from peridyn.linalg.ordering import order_unknowns
from peridyn.linalg.stiffness import StiffnessParts


def shifted_inverse(
    parts: StiffnessParts, dofs: np.ndarray, shift_mass: np.ndarray, points: np.ndarray, reach: float
) -> LinearOperator:
    """(K + s M)^-1 on the ``dofs`` as an operator, factorised once (``factorise_shifted``)."""
    lu, perm = factorise_shifted(parts, dofs, shift_mass, points, reach)
    n = len(dofs)
    rhs = np.zeros(len(perm))
    inverse = np.empty_like(perm)
    inverse[perm] = np.arange(len(perm))

    def solve(b):
        interrupts.check(where="computing the modes")
        rhs[:n] = b
        return lu.solve(rhs[perm])[inverse[:n]]

    return LinearOperator((n, n), matvec=solve, dtype=np.float64)


def factorise_shifted(
    parts: StiffnessParts, dofs: np.ndarray, shift_mass: np.ndarray, points: np.ndarray, reach: float
):
    """Sparse LU of K + s M on the ``dofs`` (or of the augmented system), and its order.

    ``shift_mass`` ((len(dofs),) N/m) is s M on those dofs; ``points`` (n, 3) m and
    ``reach`` (m, the horizon) give the nested-dissection order of the unknowns
    (``linalg.ordering``). With a dilatation part the augmented system of the module
    docstring is factorised instead of K + s M; its first len(dofs) unknowns are the dofs.

    Returns
    -------
    lu : scipy SuperLU of the permuted matrix A[perm][:, perm]
    perm : (n_unknowns,) int64
    """
    P = parts.pair[dofs][:, dofs] + sp.diags(shift_mass)
    unknown_points = dofs // 3
    if parts.G is None:
        A = P
    else:
        active = np.flatnonzero(parts.dilatation != 0.0)
        # scale the multipliers so that both diagonal blocks have the size of P's diagonal
        scale = np.sqrt(np.median(P.diagonal()) * np.abs(parts.dilatation[active]))
        SG = sp.diags(scale) @ parts.G[active][:, dofs]  # unknowns y' = y / scale
        A = sp.bmat([[P, SG.T], [SG, sp.diags(-(scale**2) / parts.dilatation[active])]])
        unknown_points = np.concatenate([unknown_points, active])
    return ordered_lu(A, unknown_points, points, reach)


def ordered_lu(A: sp.spmatrix, unknown_points: np.ndarray, points: np.ndarray, reach: float):
    """Sparse LU of the symmetric ``A`` in the nested-dissection order of its unknowns' points
    (``linalg.ordering``; ``unknown_points`` (m,) the point of each unknown, ``points`` (n, 3) m,
    ``reach`` m the longest coupling), pivoting on the diagonal where it can.

    Returns
    -------
    lu : scipy SuperLU of the permuted matrix A[perm][:, perm]
    perm : (m,) int64
    """
    perm = order_unknowns(unknown_points, points, reach)
    lu = splu(
        A.tocsr()[perm][:, perm].tocsc(),
        permc_spec="NATURAL",
        diag_pivot_thresh=0.1,
        options={"SymmetricMode": True},
    )
    return lu, perm
