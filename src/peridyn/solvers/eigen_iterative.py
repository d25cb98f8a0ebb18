"""Lowest modes of K x = lambda M x by LOBPCG, for bodies whose factorisation would not fit.

Shift-invert (``solvers.modal``) factorises K + s M; with a wide horizon the factor
grows beyond the machine (``linalg.ordering.estimated_factor_entries``). Here nothing
is factorised:

- K is applied matrix-free to the whole block (``linalg.block_operator``);
- the rigid-body modes are known exactly (translations and rotations of the points
  that the fixed dofs allow) and are kept out of the search space by M-orthogonality
  (``Y`` of ``scipy.sparse.linalg.lobpcg``, Knyazev 2001);
- the preconditioner is one V-cycle of smoothed-aggregation AMG (pyamg; Vanek, Mandel
  and Brezina 1996), applied to the whole block at once (``linalg.block_amg``), with the
  rigid modes as near-null space and points aggregated with their neighbours up to two
  short bonds away (``proxy_aggregates``), built on a sparse proxy:
  the pair stiffness of the body's bonds no longer than ``PROXY_REACH`` spacings. This
  proxy is spectrally equivalent to K (both are elasticity operators on the same points
  and bonds, and the LPS dilatation energy is bounded by its bond energy by
  Cauchy-Schwarz) but five to ten times sparser than K at a horizon of three spacings;
  LOBPCG is invariant to the scale of the preconditioner, so only the proxy's shape matters.
"""

from __future__ import annotations

import warnings

import numpy as np
import scipy.sparse as sp
from scipy.sparse.linalg import LinearOperator, lobpcg

from peridyn import interrupts
from peridyn.errors import InputError
from peridyn.linalg.amg import (
    amg_preconditioner,
    orthonormal,
    proxy_aggregates,
    proxy_stiffness,
    rigid_body_modes,
    rigid_fields,
)
from peridyn.linalg.block_operator import block_stiffness_operator
from peridyn.physics.materials.base import Model

#: Extra block vectors beyond the wanted modes (they speed convergence of the highest wanted).
GUARD_VECTORS = 3
#: Relative residual ||K x - lambda M x|| / ||K x|| every elastic mode must reach.
RESIDUAL_TARGET = 1e-7
#: LOBPCG iterations of the first pass (eigenvalue estimates) and rounds of tightening.
FIRST_PASS = 15
TOLERANCE_ROUNDS = 4


def lobpcg_modes(model: Model, n_modes: int, dofs: np.ndarray, max_iterations: int = 1000, seed: int = 0):
    """The ``n_modes`` lowest eigenpairs on the ``dofs``, rigid modes first.

    Returns
    -------
    lam : (n_modes,) float64, 1/s^2
    vecs : (len(dofs), n_modes) float64, mass-normalised
    n_rigid : int
        The first ``n_rigid`` pairs are the exact rigid modes (lambda = x^T K x ~ 0).
    K : LinearOperator, the stiffness on the dofs (N/m)
    """
    K = block_stiffness_operator(model, dofs)
    m = np.repeat(model.density * model.body.volumes, 3)[dofs]
    rigid = rigid_body_modes(model.body.points, dofs)
    rigid = rigid / np.sqrt(np.einsum("ij,i,ij->j", rigid, m, rigid))  # M-normalised
    n_rigid = min(rigid.shape[1], n_modes)
    n_elastic = n_modes - n_rigid
    lam_rigid = np.einsum("ij,ij->j", rigid, K @ rigid)[:n_rigid]
    if n_elastic == 0:
        return lam_rigid, rigid[:, :n_rigid], n_rigid, K
    proxy = proxy_stiffness(model, dofs)
    shift = 1e-6 * float(np.median(proxy.diagonal() / m))
    # near-null space: the local rigid motions, whatever the constraints (Vanek et al. 1996)
    near_null = orthonormal(rigid_fields(model.body.points)[dofs])
    precond = _interruptible(amg_preconditioner(proxy, m, near_null, shift, proxy_aggregates(model, dofs)))
    del proxy  # the V-cycle keeps its own copy (shifted, in blocks)
    block = min(n_elastic + GUARD_VECTORS, len(dofs) // 5)
    if block < n_elastic:
        raise InputError(
            f"lobpcg: {n_elastic} elastic modes need at least {5 * n_elastic} free "
            f"dofs, the model has {len(dofs)}; use eigensolver shift-invert"
        )
    x = np.random.default_rng(seed).standard_normal((len(dofs), block))
    M = sp.diags(m)
    y = rigid if rigid.shape[1] else None
    # a first pass gives eigenvalue estimates, hence the absolute tolerance of lobpcg
    # (on ||K x - lambda M x|| of M-normalised x) that meets the relative target
    lam, x = _quiet_lobpcg(K, x, M, precond, y, 1e-300, FIRST_PASS)
    relative = np.full(n_elastic, np.inf)
    for _ in range(TOLERANCE_ROUNDS):
        order = np.argsort(lam)
        lam, x = lam[order], x[:, order]
        mx = np.linalg.norm(M @ x[:, :n_elastic], axis=0)
        kx = K @ x[:, :n_elastic]
        relative = np.linalg.norm(kx - (M @ x[:, :n_elastic]) * lam[:n_elastic], axis=0) / np.linalg.norm(
            kx, axis=0
        )
        if relative.max() < RESIDUAL_TARGET:
            break
        tol = 0.3 * RESIDUAL_TARGET * float(np.min(np.abs(lam[:n_elastic]) * mx))
        lam, x = _quiet_lobpcg(K, x, M, precond, y, tol, max_iterations)
    else:
        raise InputError(
            f"lobpcg did not reach the residual {RESIDUAL_TARGET:g} in "
            f"{TOLERANCE_ROUNDS} rounds of {max_iterations} iterations (worst "
            f"{relative.max():.2e}); use eigensolver shift-invert"
        )
    return (
        np.concatenate([lam_rigid, lam[:n_elastic]]),
        np.hstack([rigid[:, :n_rigid], x[:, :n_elastic]]),
        n_rigid,
        K,
    )


def _interruptible(op: LinearOperator) -> LinearOperator:
    """``op`` with a safe point for SIGINT/SIGTERM (``peridyn.interrupts``) before each product."""

    def apply(x):
        interrupts.check(where="computing the modes")
        return op @ x

    return LinearOperator(op.shape, matvec=apply, matmat=apply, dtype=op.dtype)


def _quiet_lobpcg(K, x, M, precond, y, tol, max_iterations):
    """scipy's lobpcg for the smallest eigenpairs; its warning on an unmet tolerance is
    silenced because the caller checks the residuals itself."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UserWarning)
        return lobpcg(K, x, B=M, M=precond, Y=y, tol=tol, maxiter=max_iterations, largest=False)
