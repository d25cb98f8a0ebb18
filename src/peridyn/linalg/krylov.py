"""Krylov solvers of the package, in one place: what scipy offers is used from scipy, what it
cannot do is written here once.

- :func:`solve_spd`: a symmetric positive definite sparse system by scipy's conjugate gradients
  (``scipy.sparse.linalg.cg``), preconditioned by the diagonal or by pyamg's smoothed
  aggregation or by the caller's operator (``linalg.amg``), with the interrupt check in its
  callback (the Newton and Newmark systems of ``linalg.tangent_solve``).
- :func:`pcg`: preconditioned CG for what scipy's cannot do: inner products and norms over the
  dofs of every MPI rank (``dot`` and ``residual_norm`` given by the caller, summed in rank
  order), deflation by a subspace ``W`` (Saad, Yeung, Erhel and Guyomarc'h 2000, "A deflated
  version of the conjugate gradient algorithm", SIAM J. Sci. Comput. 21), a stop on a norm
  of the caller's choice (a force density), and the search directions handed back. Used by
  the serial fatigue statics (deflated), the distributed static solve and the distributed
  fatigue statics.
- :class:`RecycledDirections`: the deflation subspace kept from earlier solves of a sequence
  of related systems.

Each step of :func:`pcg` rounds as the loops it replaced did (same operations, same order), so
the runs that used them give the same numbers.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np
import scipy.sparse as sp
from scipy.sparse.linalg import LinearOperator, cg

from peridyn import interrupts
from peridyn.errors import InputError

#: Eigenvalues of W^T A W below this fraction of the largest drop their direction (dependent).
DEPENDENT = 1e-10

#: Preconditioners of :func:`solve_spd`.
PRECONDITIONERS = ("jacobi", "amg")


@dataclass
class KrylovResult:
    """x (n,), iterations, converged (the residual norm reached the target), and the search
    directions of the iterations (filled when asked for: ``pcg(..., keep_directions=True)``)."""

    x: np.ndarray
    iterations: int
    converged: bool
    directions: list = field(default_factory=list)


def _euclidean(a: np.ndarray, b: np.ndarray) -> float:
    return a @ b


def pcg(
    matvec: Callable,
    precondition: Callable,
    b: np.ndarray,
    target: float,
    maxiter: int,
    x0: np.ndarray | None = None,
    deflation: tuple[np.ndarray, np.ndarray] | None = None,
    dot: Callable = _euclidean,
    residual_norm: Callable = np.linalg.norm,
    agree: Callable | None = None,
    keep_directions: bool = False,
) -> KrylovResult:
    """Solve A x = b (A symmetric positive definite) by preconditioned CG, optionally deflated.

    Parameters
    ----------
    matvec, precondition : v -> A v and r -> M^-1 r on (n,) arrays (n: this process's dofs)
    b : (n,) right-hand side
    target : stop when ``residual_norm(r) <= target`` (r the recursively updated residual),
        checked before the first iteration and after each one
    maxiter : iterations at most (each one product with A and one preconditioner solve)
    x0 : (n,) start, or None for zero
    deflation : (W, A W), each (n, k), with W^T A W = I (:meth:`RecycledDirections.basis`), or None
    dot : (a, b) -> the inner product over every process's dofs (default ``a @ b``)
    residual_norm : r -> the norm the stop compares (default the Euclidean norm)
    agree : combines the interrupt check over the MPI ranks (``interrupts.check``), or None
    keep_directions : hand back each iteration's search direction (for recycling)
    """
    x = np.zeros_like(b) if x0 is None else np.array(x0, dtype=np.float64)
    r = b - matvec(x) if x0 is not None else b.copy()
    if deflation is not None:
        W, AW = deflation
        c = W.T @ r
        x += W @ c
        r -= AW @ c
    directions = []
    if residual_norm(r) <= target:
        return KrylovResult(x, 0, True, directions)
    z = precondition(r)
    p = z if deflation is None else z - W @ (AW.T @ z)
    rz = dot(r, z)
    for it in range(1, maxiter + 1):
        interrupts.check(where="solving for equilibrium", agree=agree)
        ap = matvec(p)
        alpha = rz / dot(p, ap)
        x += alpha * p
        r = r - alpha * ap  # not in place: the preconditioner may return r itself
        if keep_directions:
            directions.append(p)
        if residual_norm(r) <= target:
            return KrylovResult(x, it, True, directions)
        z = precondition(r)
        rz, rz_old = dot(r, z), rz
        p = z + (rz / rz_old) * p
        if deflation is not None:
            p -= W @ (AW.T @ z)
    return KrylovResult(x, maxiter, False, directions)


def solve_spd(
    a: sp.spmatrix | LinearOperator,
    rhs: np.ndarray,
    rtol: float,
    preconditioner: str | LinearOperator = "jacobi",
) -> np.ndarray:
    """x with ``a x = rhs`` to ``||rhs - a x|| <= rtol ||rhs||`` by scipy's CG.

    Parameters
    ----------
    a : (n, n) symmetric positive definite sparse matrix, or an operator (e.g. the matrix-free
        tangent of ``linalg.tangent``)
    rhs : (n,)
    preconditioner : ``"jacobi"`` (the inverse diagonal) or ``"amg"`` (one V-cycle of pyamg's
        smoothed aggregation) of the matrix ``a``, or an SPD operator approximating a^-1
        (``linalg.amg.amg_preconditioner``)

    Raises InputError when CG does not converge in 10 n iterations (an indefinite matrix).
    """
    n = a.shape[0]
    if isinstance(preconditioner, LinearOperator):
        m = preconditioner
    elif preconditioner not in PRECONDITIONERS:
        raise InputError(f"unknown preconditioner {preconditioner!r}; choose one of {PRECONDITIONERS}")
    elif preconditioner == "amg":
        import pyamg  # here: 30 MB a process that runs no AMG-preconditioned solve

        m = pyamg.smoothed_aggregation_solver(sp.csr_matrix(a), symmetry="symmetric").aspreconditioner(
            cycle="V"
        )
    else:
        inv_diag = 1.0 / sp.csr_matrix(a).diagonal()
        m = LinearOperator((n, n), matvec=lambda v: inv_diag * v.ravel(), dtype=np.float64)
    x, info = cg(
        a,
        rhs,
        rtol=rtol,
        atol=0.0,
        maxiter=10 * n,
        M=m,
        callback=lambda _xk: interrupts.check(where="solving for equilibrium"),
    )
    if info != 0:
        raise InputError(
            f"conjugate gradients did not reach {rtol:g} in {10 * n} iterations "
            "(is the matrix indefinite?): use linear_solver 'lu'"
        )
    return x


@dataclass
class RecycledDirections:
    """Search directions kept from earlier solves, the newest last, at most ``limit`` of them.

    The fatigue loop solves a sequence of systems whose matrices differ by the bonds broken so
    far, all preconditioned by one old factorisation; the search directions of the earlier
    solves span where that factorisation is off, so they make a good deflation subspace W for
    the next solve. W is multiplied by the new A at each solve as one block (one pass over the
    bonds for all directions, ``linalg.block_operator``), which costs about as much as a few
    single products.

    Attributes
    ----------
    vectors : list of (n,) float64 arrays
    """

    limit: int
    vectors: list = field(default_factory=list)

    def add(self, directions: list) -> None:
        """Keep ``directions`` (newest last), dropping the oldest beyond ``limit``."""
        self.vectors = (self.vectors + list(directions))[-self.limit :] if self.limit else []

    def clear(self) -> None:
        """Forget every direction (e.g. after a new factorisation)."""
        self.vectors = []

    def basis(self, matmat: Callable) -> tuple[np.ndarray, np.ndarray] | None:
        """A-orthonormal basis of the kept directions for the A of ``matmat`` ((n, k) -> A of each
        column, (n, k)): (W, A W), each (n, k), with W^T A W = I; None when none are kept."""
        if not self.vectors:
            return None
        W = np.column_stack(self.vectors)
        AW = matmat(W)
        lam, Q = np.linalg.eigh(0.5 * (W.T @ AW + AW.T @ W))
        keep = lam > DEPENDENT * lam.max()
        scale = Q[:, keep] / np.sqrt(lam[keep])
        return W @ scale, AW @ scale
