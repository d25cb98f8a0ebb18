"""Lowest modes of K x = lambda M x over MPI ranks: LOBPCG on distributed blocks.

scipy's ``lobpcg`` (the serial path, ``solvers.eigen_iterative``) holds whole vectors. Here each
rank holds the rows of its owned free dofs (``linalg.distributed.RankDofs``), K is applied
matrix-free with one halo exchange per block (``RankStiffness``), the preconditioner is the
serial AMG V-cycle of each rank's own block (block Jacobi, ``rank_preconditioner``), and every
inner product is a small Gram matrix summed over the ranks by one allreduce.

The iteration is Knyazev's LOBPCG (2001): the Rayleigh-Ritz step on [X, W, P] (current
vectors, preconditioned residuals of the unconverged ones, previous directions), with the
search blocks W and P made M-orthonormal against X and each other (twice, dropping dependent
directions: SVQB, Stathopoulos and Wu 2002) so that the Ritz problem is a plain symmetric
eigenproblem however small the residuals become. The rigid modes are exact and kept out of the
search space as constraints (as in serial), and a mode is converged at the serial target: the
relative residual ||K x - lambda M x|| / ||K x|| below ``eigen_iterative.RESIDUAL_TARGET``,
checked with a fresh K x before returning. The frequencies then agree with a serial run's to
about the square of that residual; the iterates differ from serial by the order of the sums
(rank order), so the answers agree to the tolerance, not bit for bit.
"""

from __future__ import annotations

import numpy as np

from peridyn import interrupts
from peridyn.errors import InputError
from peridyn.linalg.distributed import RankDofs, RankStiffness, rank_preconditioner
from peridyn.solvers.eigen_iterative import GUARD_VECTORS, RESIDUAL_TARGET
from peridyn.solvers.modal import ModalResult, classify_result


def distributed_modes(
    dofs: RankDofs, n_modes: int, max_iterations: int = 1000, seed: int = 0
) -> tuple[ModalResult | None, dict]:
    """The ``n_modes`` lowest modes of the whole body, rigid ones included (collective).

    Returns
    -------
    result : ModalResult on rank 0 (mode shapes of the whole body, (n_modes, n_global, 3)),
        None elsewhere.
    stats : dict
        ``iterations`` (LOBPCG) and ``stiffness_columns`` (block columns K was applied to), on
        every rank.
    """
    if n_modes < 1:
        raise InputError(f"number of modes must be positive, got {n_modes}")
    if n_modes >= dofs.n_total:
        raise InputError(f"asked for {n_modes} modes of a model with {dofs.n_total} free dofs")
    K = RankStiffness(dofs)
    m = dofs.mass
    rigid = dofs.rigid_body_modes()
    rigid = rigid / np.sqrt(dofs.domain.allsum(np.einsum("ij,i,ij->j", rigid, m, rigid)))
    n_rigid = min(rigid.shape[1], n_modes)
    n_elastic = n_modes - n_rigid
    lam = np.einsum("ij,ij->j", rigid, K @ rigid)[:n_rigid]
    lam = dofs.domain.allsum(lam)
    vecs, iterations = rigid[:, :n_rigid], 0
    if n_elastic:
        block = min(n_elastic + GUARD_VECTORS, dofs.n_total // 5)
        if block < n_elastic:
            raise InputError(
                f"lobpcg: {n_elastic} elastic modes need at least {5 * n_elastic} free "
                f"dofs, the model has {dofs.n_total}; use fewer ranks or modes"
            )
        rng = np.random.default_rng([seed, dofs.domain.comm.rank])
        x = rng.standard_normal((len(m), block))
        precond = rank_preconditioner(dofs)
        lam_e, x, iterations = block_lobpcg(
            K, precond, dofs, x, rigid if rigid.shape[1] else None, n_elastic, max_iterations
        )
        lam = np.concatenate([lam, lam_e[:n_elastic]])
        vecs = np.hstack([vecs, x[:, :n_elastic]])
    stats = {"iterations": iterations, "stiffness_columns": K.columns}
    known_rigid = np.arange(n_modes) < n_rigid
    order = np.argsort(lam)
    lam, vecs, known_rigid = lam[order], vecs[:, order], known_rigid[order]
    kx = K @ vecs
    resid = dofs.column_norms(kx - (m[:, None] * vecs) * lam)
    k_max = float(dofs.domain.max(np.max(dofs.model.stiffness_bound() * dofs.model.body.volumes)))
    scale_rigid = k_max * dofs.column_norms(vecs)
    scale_elastic = dofs.column_norms(kx)
    shapes = dofs.gather_fields(vecs)
    if shapes is None:
        return None, stats
    return classify_result(lam, shapes, resid, scale_rigid, scale_elastic, known_rigid), stats


def block_lobpcg(
    K, precond, dofs: RankDofs, x: np.ndarray, y: np.ndarray | None, n_wanted: int, max_iterations
):
    """The lowest eigenpairs of K x = lambda M x (M = diag(``dofs.mass``)) M-orthogonal to the
    columns of ``y`` (n_free, r), from the start block ``x`` (n_free, k) (collective).

    Returns the k Ritz values (ascending), the block (n_free, k), M-orthonormal, and the number
    of iterations; the first ``n_wanted`` pairs reach the relative residual ``RESIDUAL_TARGET``.
    Raises InputError when they do not within ``max_iterations``.
    """
    m = dofs.mass[:, None]
    agree = dofs.domain.max
    if y is not None:
        gy = dofs.gram(y, m * y)
        x = x - y @ np.linalg.solve(gy, dofs.gram(y, m * x))
    x, _ = _m_orthonormal(dofs, x, None, [])
    kx = K @ x
    lam, c = np.linalg.eigh(_symmetric(dofs.gram(x, kx)))
    x, kx = x @ c, kx @ c
    p = kp = None
    k = x.shape[1]
    worst = np.inf
    for it in range(1, max_iterations + 1):
        interrupts.check(where="computing the modes", agree=agree)
        relative = _relative_residuals(dofs, x, kx, lam)
        if relative[:n_wanted].max() < RESIDUAL_TARGET:
            kx = K @ x  # the updated K x drifts by round-off: check with a fresh one
            relative = _relative_residuals(dofs, x, kx, lam)
            if relative[:n_wanted].max() < RESIDUAL_TARGET:
                return lam, x, it
        worst = relative[:n_wanted].max()
        active = relative >= RESIDUAL_TARGET
        w = precond @ (kx[:, active] - (m * x[:, active]) * lam[active])
        if y is not None:
            w = w - y @ np.linalg.solve(gy, dofs.gram(y, m * w))
        w, _ = _m_orthonormal(dofs, w, None, [x])
        kw = K @ w
        blocks, images = [x, w], [kx, kw]
        if p is not None:
            pa, kpa = _m_orthonormal(dofs, p[:, active], kp[:, active], [x, w], [kx, kw])
            blocks.append(pa)
            images.append(kpa)
        lam_all, c = np.linalg.eigh(_symmetric(_block_gram(dofs, blocks, images)))
        lam, c = lam_all[:k], c[:, :k]
        p, kp = _combine(blocks[1:], c[k:]), _combine(images[1:], c[k:])
        x, kx = _combine(blocks, c), _combine(images, c)
    raise InputError(
        f"lobpcg did not reach the residual {RESIDUAL_TARGET:g} in {max_iterations} iterations "
        f"(worst {worst:.2e})"
    )


def _relative_residuals(dofs: RankDofs, x, kx, lam) -> np.ndarray:
    """(k,) ||K x - lambda M x|| / ||K x|| of each column (collective)."""
    r = kx - (dofs.mass[:, None] * x) * lam
    return dofs.column_norms(r) / np.maximum(dofs.column_norms(kx), 1e-300)


def _m_orthonormal(dofs: RankDofs, v, kv, against: list, against_k: list = ()):
    """``v`` (n_free, j) made M-orthogonal to the M-orthonormal blocks ``against`` and
    M-orthonormal itself, dependent directions dropped (two passes); ``kv`` (K v, or None) is
    carried along with ``against_k`` (K of ``against``). Returns (v, kv)."""
    m = dofs.mass[:, None]
    for _ in range(2):
        for i, a in enumerate(against):
            coef = dofs.gram(a, m * v)
            v = v - a @ coef
            if kv is not None:
                kv = kv - against_k[i] @ coef
        c = dofs.orthonormaliser(dofs.gram(v, m * v))
        v = v @ c
        if kv is not None:
            kv = kv @ c
    return v, kv


def _block_gram(dofs: RankDofs, blocks: list, images: list) -> np.ndarray:
    """``[b_0 b_1 ...]^T [k_0 k_1 ...]`` over every rank's rows (one allreduce), without
    stacking the blocks (n_free, k_i) side by side: a stacked copy of the search space and of its
    image would be the largest arrays of an iteration."""
    bounds = np.cumsum([0] + [b.shape[1] for b in blocks])
    local = np.empty((bounds[-1], bounds[-1]))
    for i, b in enumerate(blocks):
        for j, kb in enumerate(images):
            local[bounds[i] : bounds[i + 1], bounds[j] : bounds[j + 1]] = b.T @ kb
    return dofs.domain.allsum(local)


def _combine(blocks: list, c: np.ndarray) -> np.ndarray:
    """``[b_0 b_1 ...] @ c`` for blocks (n_free, k_i) and ``c`` (sum k_i, m), block by block."""
    start = blocks[0].shape[1]
    out = blocks[0] @ c[:start]
    for b in blocks[1:]:
        out += b @ c[start : start + b.shape[1]]
        start += b.shape[1]
    return out


def _symmetric(a: np.ndarray) -> np.ndarray:
    return 0.5 * (a + a.T)
