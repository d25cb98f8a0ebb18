"""Deflated preconditioned conjugate gradients, recycling directions between related solves.

Saad, Yeung, Erhel and Guyomarc'h (2000), "A deflated version of the conjugate gradient
algorithm", SIAM J. Sci. Comput. 21: given a subspace W where the preconditioned operator is
poor, the initial residual is made orthogonal to W (Galerkin correction) and every search
direction A-orthogonal to W, so CG only works on the rest of the spectrum.

The fatigue loop solves a sequence of systems whose matrices differ by the bonds broken so far,
all preconditioned by one old factorisation; the search directions of the earlier solves span
where that factorisation is off, so they make a good W for the next solve
(``RecycledDirections``). W is multiplied by the new A at each solve as one block (one pass over
the bonds for all directions, ``linalg.block_operator``), which costs about as much as a few
single products.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from peridyn import interrupts

#: Eigenvalues of W^T A W below this fraction of the largest drop their direction (dependent).
DEPENDENT = 1e-10


@dataclass
class RecycledDirections:
    """Search directions kept from earlier solves, the newest last, at most ``limit`` of them.

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


@dataclass
class PCGResult:
    """x (n,), iterations, converged (||b - A x|| <= rtol ||b||), and the search directions."""

    x: np.ndarray
    iterations: int
    converged: bool
    directions: list


def deflated_pcg(
    matvec: Callable,
    precondition: Callable,
    b: np.ndarray,
    x0: np.ndarray | None,
    rtol: float,
    maxiter: int,
    deflation: tuple[np.ndarray, np.ndarray] | None = None,
) -> PCGResult:
    """Solve A x = b (A symmetric positive definite) by preconditioned CG deflated by W.

    Parameters
    ----------
    matvec, precondition : v -> A v and r -> M^-1 r on (n,) arrays
    x0 : (n,) start, or None for zero
    rtol : stop when ||b - A x|| <= rtol ||b|| (the recursively updated residual)
    maxiter : iterations at most (each one product with A and one preconditioner solve)
    deflation : (W, A W) with W^T A W = I (``RecycledDirections.basis``), or None
    """
    x = np.zeros_like(b) if x0 is None else np.array(x0, dtype=np.float64)
    r = b - matvec(x) if x0 is not None else b.copy()
    if deflation is not None:
        W, AW = deflation
        c = W.T @ r
        x += W @ c
        r -= AW @ c
    target = rtol * np.linalg.norm(b)
    directions = []
    if np.linalg.norm(r) <= target:
        return PCGResult(x, 0, True, directions)
    z = precondition(r)
    p = z if deflation is None else z - W @ (AW.T @ z)
    rz = r @ z
    for it in range(1, maxiter + 1):
        interrupts.check(where="solving for equilibrium")
        ap = matvec(p)
        alpha = rz / (p @ ap)
        x += alpha * p
        r = r - alpha * ap  # not in place: the preconditioner may return r itself
        directions.append(p)
        if np.linalg.norm(r) <= target:
            return PCGResult(x, it, True, directions)
        z = precondition(r)
        rz, rz_old = r @ z, rz
        p = z + (rz / rz_old) * p
        if deflation is not None:
            p -= W @ (AW.T @ z)
    return PCGResult(x, maxiter, False, directions)
