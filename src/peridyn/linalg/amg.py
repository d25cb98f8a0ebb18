"""Smoothed-aggregation AMG preconditioner of the stiffness, built on a sparse proxy.

The proxy is the pair stiffness of the body's bonds no longer than ``PROXY_REACH`` spacings:
spectrally equivalent to K (both are elasticity operators on the same points and bonds, and
the LPS dilatation energy is bounded by its bond energy by Cauchy-Schwarz) but five to ten
times sparser at a horizon of three spacings. The rigid motions of the points are its
near-null space; points are aggregated with their neighbours up to two short bonds away
(``proxy_aggregates``). One V-cycle (``linalg.block_amg``) is applied to a whole block of
vectors. Used by LOBPCG (``solvers.eigen_iterative``) and the fatigue statics.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
from scipy.linalg import null_space
from scipy.sparse.linalg import LinearOperator

from peridyn.linalg.block_amg import BlockVCycle, smoothed_aggregation_hierarchy
from peridyn.linalg.stiffness import pair_matrix
from peridyn.physics.materials.base import Model

#: Bonds kept in the preconditioner's proxy: length <= this times the shortest bond
#: (1.5: the 18 nearest neighbours of a cubic grid).
PROXY_REACH = 1.5


def rigid_fields(
    points: np.ndarray, centroid: np.ndarray | None = None, scale: float | None = None
) -> np.ndarray:
    """The six rigid motions of the points (3 n, 6): translations x, y, z, then rotations about
    the x, y, z axes through the centroid (scaled to unit largest entry).

    ``centroid`` (3,), m, and ``scale``, m (the largest |coordinate - centroid|): those of a
    larger body of which ``points`` are a part (one rank's, ``linalg.distributed``); None: of
    ``points``."""
    n = len(points)
    r = points - (points.mean(axis=0) if centroid is None else centroid)
    scale = np.abs(r).max() if scale is None else scale
    fields = np.zeros((n, 3, 6))
    for a in range(3):
        fields[:, a, a] = 1.0
        axis = np.zeros(3)
        axis[a] = 1.0
        fields[:, :, 3 + a] = np.cross(axis, r) / max(scale, 1e-300)
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
    return orthonormal(fields[dofs] @ allowed)


def orthonormal(basis: np.ndarray) -> np.ndarray:
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

    Pair matrix (``stiffness.pair_matrix``) of the intact bonds no longer than
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
    # an axis-parallel bond couples one component of each point only: most entries are zeros
    proxy = pair_matrix(i, j, n_vec, coef, model.body.n_points, drop_zeros=True)
    if not np.array_equal(dofs, np.arange(proxy.shape[0])):  # no copy of a free body's matrix
        proxy = proxy[dofs][:, dofs].tocsr()
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
    graph = sp.csr_matrix((np.ones(int(short.sum())), (b.owners()[short], b.neighbours[short])), shape=(n, n))
    two_bonds = (graph @ graph + graph).tocsr()
    two_bonds.data[:] = 1.0
    found = standard_aggregation(two_bonds)[0].tocsr()
    point_aggregate = np.full(n, -1)
    point_aggregate[np.repeat(np.arange(n), np.diff(found.indptr))] = found.indices
    lonely = point_aggregate < 0  # a point whose short bonds are all cut: its own aggregate
    point_aggregate[lonely] = found.shape[1] + np.arange(int(lonely.sum()))
    used, dof_aggregate = np.unique(point_aggregate[dofs // 3], return_inverse=True)
    return sp.csr_matrix(
        (np.ones(len(dofs)), (np.arange(len(dofs)), dof_aggregate)), shape=(len(dofs), len(used))
    )


def amg_preconditioner(
    proxy: sp.csr_matrix,
    mass: np.ndarray,
    near_null: np.ndarray,
    shift: float,
    aggregates: sp.csr_matrix | None = None,
) -> LinearOperator:
    """One smoothed-aggregation V-cycle on ``proxy + shift * diag(mass)``, applied to the whole
    block at once (``linalg.block_amg``)."""
    a = (proxy + sp.diags(shift * mass)).tocsr()
    cycle = BlockVCycle(smoothed_aggregation_hierarchy(a, near_null, aggregates))
    return LinearOperator(a.shape, matvec=cycle, matmat=cycle, dtype=np.float64)
