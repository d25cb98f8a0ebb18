"""The stiffness and its preconditioner on one rank's part of the body (MPI runs), matrix-free.

A vector of the distributed problem is the rank's block of rows: the free dofs of its owned
points (``RankDofs.dofs``, local dof numbering 3 i + a, owned points first). ``RankStiffness``
applies the rows of K that belong to them: the block is placed in a (n_local, 3, k) array, the
ghost rows are filled by the part's halo exchange (``Domain.exchange``, the explicit runs'
exchange), and ``linalg.block_operator.block_linear_force`` runs on the part's bonds. Every
owned point and every neighbour of it has its whole family on the rank (two ghost layers,
``peridyn.parallel.halo``), so the owned rows come out as the serial K's rows, LPS dilatation
included.

Global inner products (``RankDofs.gram``) are per-rank products summed by one allreduce
(``Domain.allsum``): rounded in rank order, so a Krylov solver's iterates differ from a serial
run's by round-off; their answers agree to the solver tolerance.

The preconditioner (``rank_preconditioner``) is block Jacobi over the ranks (additive Schwarz
without overlap): on each rank the serial smoothed-aggregation V-cycle (``linalg.amg``) of the
sparse proxy restricted to its owned free dofs, couplings to other ranks' dofs dropped.
"""

from __future__ import annotations

import numpy as np
from scipy.sparse.linalg import LinearOperator

from peridyn.linalg.amg import (
    amg_preconditioner,
    orthonormal,
    proxy_aggregates,
    proxy_stiffness,
    rigid_fields,
)
from peridyn.linalg.block_operator import block_linear_force
from peridyn.linalg.dofs import free_dofs
from peridyn.parallel.domain import Domain
from peridyn.physics.materials.base import Model


class RankDofs:
    """The free dofs a rank owns, and the global reductions over every rank's.

    Parameters
    ----------
    model : Model
        The rank's part (owned points, then ghosts).
    domain : Domain
    fixed : (n_local, 3) bool or None
        Dofs held at zero (the part's ``Loading.constrained``).

    Attributes
    ----------
    dofs : (n_free,) int64
        Local dof indices (3 i + a) of the owned free dofs, ascending.
    global_dofs : (n_free,) int64
        Their global dof indices (3 g + a, g the global point index).
    mass : (n_free,) float64, kg
        Lumped mass rho V_i of each dof.
    """

    def __init__(self, model: Model, domain: Domain, fixed: np.ndarray | None = None):
        n = domain.n_owned
        local = free_dofs(model, fixed)
        self.dofs = local[local < 3 * n]
        points, axes = np.divmod(self.dofs, 3)
        self.global_dofs = 3 * domain.global_ids[points] + axes
        self.mass = (model.density * model.body.volumes)[points]
        self.model = model
        self.domain = domain
        #: total number of free dofs over the ranks
        self.n_total = domain.count(len(self.dofs))

    def gram(self, a: np.ndarray, b: np.ndarray) -> np.ndarray:
        """A^T B over every rank's rows, (ka, kb) float64, of the local blocks ``a`` (n_free, ka)
        and ``b`` (n_free, kb) (collective)."""
        return self.domain.allsum(np.ascontiguousarray(a.T @ b))

    def column_norms(self, a: np.ndarray) -> np.ndarray:
        """(k,) Euclidean norms of the global columns of the local block ``a`` (collective)."""
        return np.sqrt(self.domain.allsum(np.einsum("ij,ij->j", a, a)))

    def _owned_fields(self) -> np.ndarray:
        """The six rigid motions (``linalg.amg.rigid_fields``: translations, then rotations about
        the whole body's centroid scaled by its largest distance) on every dof of the owned
        points, (3 n_owned, 6) (collective)."""
        n = self.domain.n_owned
        x = self.model.body.points[:n]
        centroid = self.domain.allsum(x.sum(axis=0)) / self.domain.n_global
        scale = float(self.domain.max(np.abs(x - centroid).max(initial=0.0)))
        return rigid_fields(x, centroid, scale)

    def rigid_body_modes(self) -> np.ndarray:
        """The rigid motions the constraints allow (as ``linalg.amg.rigid_body_modes``), on the
        owned free dofs: (n_free, r) columns orthonormal over every rank (collective).

        The combinations of the fields that vanish on every held dof (fixed, and the z dofs of
        a 2D body) span the null space of the held rows' Gram matrix (6 x 6, reduced over the
        ranks); the kept combinations are then orthonormalised through their Gram matrix."""
        fields = self._owned_fields()
        held = np.ones(len(fields), dtype=bool)
        held[self.dofs] = False
        g = self.domain.allsum(fields[held].T @ fields[held])
        s, v = np.linalg.eigh(0.5 * (g + g.T))
        allowed = v[:, s <= 1e-12 * max(float(s.max()), 1e-300)] if g.any() else np.eye(6)
        basis = fields[self.dofs] @ allowed
        return basis @ self.orthonormaliser(self.gram(basis, basis))

    @staticmethod
    def orthonormaliser(g: np.ndarray, drop: float = 1e-10) -> np.ndarray:
        """(k, r) matrix C with (V C)^T (V C) = I for a block V whose Gram matrix is ``g``; the
        directions of singular value below ``drop`` times the largest are dropped (SVQB,
        Stathopoulos and Wu 2002)."""
        if g.shape[0] == 0:
            return np.zeros((0, 0))
        s, q = np.linalg.eigh(0.5 * (g + g.T))
        keep = s > drop**2 * max(float(s.max()), 1e-300)
        return q[:, keep] / np.sqrt(s[keep])

    def gather_fields(self, block: np.ndarray) -> np.ndarray | None:
        """The columns of ``block`` (n_free, k) as fields of the whole body, (k, n_global, 3) with
        zeros on the held dofs, on rank 0 (None elsewhere; collective)."""
        n = self.domain.n_owned
        k = block.shape[1]
        local = np.zeros((3 * n, k))
        local[self.dofs] = block
        whole = self.domain.gather(np.ascontiguousarray(local.reshape(n, 3, k)))
        return None if whole is None else np.ascontiguousarray(whole.transpose(2, 0, 1))


class RankStiffness:
    """The owned free rows of K (N/m) applied to blocks of the rank's dofs (see the module
    docstring): ``K @ v`` for v (n_free,) or (n_free, k) (collective: one halo exchange)."""

    def __init__(self, dofs: RankDofs):
        self.rank_dofs = dofs
        model = dofs.model
        self._model = model
        self._n_local = model.body.n_points
        self._volumes = model.body.volumes[dofs.dofs // 3]
        self._work = np.empty(0)  # flat extension buffer, grown to the widest block
        #: blocks applied so far (columns)
        self.columns = 0

    def __matmul__(self, v: np.ndarray) -> np.ndarray:
        v = np.asarray(v, dtype=np.float64)
        block = v.reshape(len(v), -1)
        k = block.shape[1]
        full = np.zeros((3 * self._n_local, k))
        full[self.rank_dofs.dofs] = block
        full = full.reshape(self._n_local, 3, k)
        self.rank_dofs.domain.exchange(full)
        return self.field_rows(full).reshape(v.shape)

    def field_rows(self, full: np.ndarray) -> np.ndarray:
        """The owned free rows (n_free, k), N, of K applied to ``full`` (n_local, 3, k), m: k
        displacement fields given on every local point, ghost rows filled (e.g. prescribed
        displacements, held dofs included)."""
        k = full.shape[2]
        wanted = self._model.bonds.n_bonds * k
        if len(self._work) < wanted:
            self._work = np.empty(wanted)
        extension = self._work[:wanted].reshape(self._model.bonds.n_bonds, k)
        f = block_linear_force(self._model, full, extension).reshape(3 * self._n_local, k)
        self.columns += k
        return -self._volumes[:, None] * f[self.rank_dofs.dofs]


def rank_preconditioner(dofs: RankDofs) -> LinearOperator:
    """Block Jacobi over the ranks: this rank's V-cycle of the proxy (``linalg.amg``) on its owned
    free dofs plus 1e-6 of the median diagonal-to-mass ratio times the mass (as in serial, the
    median of this rank's dofs), with the local rigid motions as near-null space."""
    model = dofs.model
    proxy = proxy_stiffness(model, dofs.dofs)
    shift = 1e-6 * float(np.median(proxy.diagonal() / dofs.mass))
    n = dofs.domain.n_owned
    near_null = orthonormal(rigid_fields(model.body.points[:n])[dofs.dofs])
    return amg_preconditioner(proxy, dofs.mass, near_null, shift, proxy_aggregates(model, dofs.dofs))
