"""Lowest modes of K x = lambda M x by LOBPCG, for bodies whose factorisation would not fit.

Shift-invert (``solvers.modal``) factorises K + s M; with a wide horizon the factor
grows beyond the machine (``solvers.ordering.estimated_factor_entries``). Here nothing
is factorised:

- K is applied matrix-free to the whole block (``solvers.block_operator``);
- the rigid-body modes are known exactly (translations and rotations of the points
  that the fixed dofs allow) and are kept out of the search space by M-orthogonality
  (``Y`` of ``scipy.sparse.linalg.lobpcg``, Knyazev 2001);
- the preconditioner is one V-cycle of smoothed-aggregation AMG (pyamg; Vanek, Mandel
  and Brezina 1996), applied to the whole block at once (``solvers.block_amg``), with the
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
from scipy.linalg import null_space
from scipy.sparse.linalg import LinearOperator, lobpcg

from peridyn.errors import InputError
from peridyn.physics.materials.base import Model
from peridyn.linalg.block_amg import BlockVCycle, smoothed_aggregation_hierarchy
from peridyn.linalg.block_operator import block_stiffness_operator
from peridyn.linalg.stiffness import _pair_matrix

#: Bonds kept in the preconditioner's proxy: length <= this times the shortest bond
#: (1.5: the 18 nearest neighbours of a cubic grid).
PROXY_REACH = 1.5
#: Extra block vectors beyond the wanted modes (they speed convergence of the highest wanted).
GUARD_VECTORS = 3
#: Relative residual ||K x - lambda M x|| / ||K x|| every elastic mode must reach.
RESIDUAL_TARGET = 1e-7
#: LOBPCG iterations of the first pass (eigenvalue estimates) and rounds of tightening.
FIRST_PASS = 15
TOLERANCE_ROUNDS = 4


def rigid_fields(points: np.ndarray) -> np.ndarray:
    """The six rigid motions of the points (3 n, 6): translations x, y, z, then rotations about
    the x, y, z axes through the centroid (scaled to unit largest entry)."""
    n = len(points)
    r = points - points.mean(axis=0)
    fields = np.zeros((n, 3, 6))
    for a in range(3):
        fields[:, a, a] = 1.0
        axis = np.zeros(3)
        axis[a] = 1.0
        fields[:, :, 3 + a] = np.cross(axis, r) / max(np.abs(r).max(), 1e-300)
    return fields.reshape(3 * n, 6)


def rigid_body_modes(points: np.ndarray, dofs: np.ndarray) -> np.ndarray:
    """Rigid motions the constraints allow, on the ``dofs``: (len(dofs), r) orthonormal columns.

    Only the combinations of ``rigid_fields`` that vanish on every dof outside ``dofs``
    (fixed dofs, the z dofs of a 2D body) are kept: six for a free 3D body, three for a
    free 2D one, none once enough dofs are fixed.
    """
    fields = rigid_fields(points)
    held = np.ones(len(fields), dtype=bool)
    held[dofs] = False
    allowed = null_space(fields[held], rcond=1e-10) if held.any() else np.eye(6)
    return _orthonormal(fields[dofs] @ allowed)


def _orthonormal(basis: np.ndarray) -> np.ndarray:
    """Orthonormal basis of the range of ``basis`` (columns), rank-revealing."""
    if basis.shape[1] == 0:
        return basis
    u, s, _ = np.linalg.svd(basis, full_matrices=False)
    return u[:, s > 1e-10 * max(s.max(), 1e-300)]


def _short_bonds(model: Model) -> np.ndarray:
    """Mask of the intact bonds no longer than ``PROXY_REACH`` times the shortest."""
    b = model.bonds
    return b.intact & (b.length <= PROXY_REACH * b.length[b.intact].min())


def proxy_stiffness(model: Model, dofs: np.ndarray) -> sp.csr_matrix:
    """Sparse SPD-up-to-rigid-modes proxy of K on the ``dofs`` (arbitrary scale).

    Pair matrix (``stiffness._pair_matrix``) of the intact bonds no longer than
    ``PROXY_REACH`` times the shortest, each with coefficient V_i / |xi|^2 (a bond-based
    elastic body): broken bonds and cracks are seen as in K.
    """
    b = model.bonds
    owners = b.owners()
    short = _short_bonds(model)
    x = model.body.points
    i, j = owners[short], b.neighbours[short]
    n_vec = (x[j] - x[i]) / b.length[short, None]
    coef = model.body.volumes[i] / b.length[short] ** 2
    pair = _pair_matrix(i, j, n_vec, coef, model.body.n_points)
    proxy = pair[dofs][:, dofs].tocsr()
    proxy.eliminate_zeros()  # an axis-parallel bond couples one component of each point only
    return proxy


def proxy_aggregates(model: Model, dofs: np.ndarray) -> sp.csr_matrix:
    """First-level aggregates of the preconditioner: (len(dofs), n_aggregates) 0/1 matrix.

    Points are aggregated (pyamg's standard aggregation) on the graph joining points up to
    two short bonds apart, so an aggregate is a point with its neighbours' neighbours (93
    points on average for the 40 000-point plate) and all dofs of a point share its
    aggregate: the coarse level has a ninth of the unknowns of pyamg's aggregation of the
    dofs and is sparser than the fine one (operator complexity 1.04 instead of 6.2 there).
    Cut bonds are not in the graph: an aggregate does not reach across a crack.
    """
    from pyamg.aggregation import standard_aggregation

    b = model.bonds
    short = _short_bonds(model)
    n = model.body.n_points
    graph = sp.csr_matrix((np.ones(int(short.sum())), (b.owners()[short], b.neighbours[short])),
                          shape=(n, n))
    two_bonds = (graph @ graph + graph).tocsr()
    two_bonds.data[:] = 1.0
    found = standard_aggregation(two_bonds)[0].tocsr()
    point_aggregate = np.full(n, -1)
    point_aggregate[np.repeat(np.arange(n), np.diff(found.indptr))] = found.indices
    lonely = point_aggregate < 0  # a point whose short bonds are all cut: its own aggregate
    point_aggregate[lonely] = found.shape[1] + np.arange(int(lonely.sum()))
    used, dof_aggregate = np.unique(point_aggregate[dofs // 3], return_inverse=True)
    return sp.csr_matrix((np.ones(len(dofs)), (np.arange(len(dofs)), dof_aggregate)),
                         shape=(len(dofs), len(used)))


def amg_preconditioner(proxy: sp.csr_matrix, mass: np.ndarray, near_null: np.ndarray,
                       shift: float, aggregates: sp.csr_matrix | None = None) -> LinearOperator:
    """One smoothed-aggregation V-cycle on ``proxy + shift * diag(mass)``, applied to the whole
    block at once (``solvers.block_amg``)."""
    a = (proxy + sp.diags(shift * mass)).tocsr()
    cycle = BlockVCycle(smoothed_aggregation_hierarchy(a, near_null, aggregates))
    return LinearOperator(a.shape, matvec=cycle, matmat=cycle, dtype=np.float64)


def lobpcg_modes(model: Model, n_modes: int, dofs: np.ndarray, max_iterations: int = 1000,
                 seed: int = 0):
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
    near_null = _orthonormal(rigid_fields(model.body.points)[dofs])
    precond = amg_preconditioner(proxy, m, near_null, shift, proxy_aggregates(model, dofs))
    block = min(n_elastic + GUARD_VECTORS, len(dofs) // 5)
    if block < n_elastic:
        raise InputError(f"lobpcg: {n_elastic} elastic modes need at least {5 * n_elastic} free "
                         f"dofs, the model has {len(dofs)}; use eigensolver shift-invert")
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
        relative = np.linalg.norm(kx - (M @ x[:, :n_elastic]) * lam[:n_elastic], axis=0) / \
            np.linalg.norm(kx, axis=0)
        if relative.max() < RESIDUAL_TARGET:
            break
        tol = 0.3 * RESIDUAL_TARGET * float(np.min(np.abs(lam[:n_elastic]) * mx))
        lam, x = _quiet_lobpcg(K, x, M, precond, y, tol, max_iterations)
    else:
        raise InputError(f"lobpcg did not reach the residual {RESIDUAL_TARGET:g} in "
                         f"{TOLERANCE_ROUNDS} rounds of {max_iterations} iterations (worst "
                         f"{relative.max():.2e}); use eigensolver shift-invert")
    return (np.concatenate([lam_rigid, lam[:n_elastic]]),
            np.hstack([rigid[:, :n_rigid], x[:, :n_elastic]]), n_rigid, K)


def _quiet_lobpcg(K, x, M, precond, y, tol, max_iterations):
    """scipy's lobpcg for the smallest eigenpairs; its warning on an unmet tolerance is
    silenced because the caller checks the residuals itself."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UserWarning)
        return lobpcg(K, x, B=M, M=precond, Y=y, tol=tol, maxiter=max_iterations, largest=False)
