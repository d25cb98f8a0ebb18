"""The stiffness applied to a block of vectors at once, matrix-free (for iterative eigensolvers).

``kernels.linear`` applies K to one displacement field; an eigensolver such as LOBPCG
applies it to a dozen at every iteration. Here each bond is visited once per block: its
unit vector and coefficients are read once and used for all ``k`` vectors, which sit
contiguously in memory (``u`` of shape (n_points, 3, k)). Same formulas as
``kernels.linear`` (``K u = -V f_lin(u)``), with the coefficients of ``model.linearisation()``
(``peridyn.physics.materials.linearisation``): t = axial (P_i + P_j) + extension e, axial =
weight |xi|, and no axial part for a material without dilatation. Nothing is assembled: the
memory is the bonds' plus a few (n_bonds, k) arrays, whatever the horizon.
"""

from __future__ import annotations

import numpy as np
from scipy.sparse.linalg import LinearOperator

from peridyn.kernels.block import block_bond_force, block_extension, block_family_sum
from peridyn.physics.materials.base import Model


def block_linear_force(model: Model, u: np.ndarray, extension: np.ndarray | None = None) -> np.ndarray:
    """Linearised force density (n_points, 3, k), N/m^3, of the k fields ``u`` (n_points, 3, k).

    ``extension``: optional (n_bonds, k) float64 work array, reused between calls (a fresh
    one of a few hundred MB per call costs its page faults every time)."""
    b = model.bonds
    x = model.body.points
    u = np.ascontiguousarray(u, dtype=np.float64)
    if extension is None or extension.shape != (b.n_bonds, u.shape[2]):
        extension = np.empty((b.n_bonds, u.shape[2]))
    e = block_extension(x, u, b.offsets, b.neighbours, b.length, b.intact, extension)
    f = np.empty_like(u)
    lin = model.linearisation()
    if lin.has_dilatation:
        axial = lin.weight * b.length
        theta = block_family_sum(b.offsets, axial, e, np.empty((len(x), u.shape[2])))
        p = theta * (lin.theta_coef * lin.p_coef)[:, None]
    else:
        axial = np.zeros(b.n_bonds)
        p = np.zeros((len(x), u.shape[2]))
    return block_bond_force(x, e, b.offsets, b.neighbours, b.length, axial, lin.extension, b.intact, p, f)


def block_stiffness_operator(model: Model, dofs: np.ndarray) -> LinearOperator:
    """K[dofs][:, dofs] (N/m) as an operator whose ``matmat`` visits the bonds once per block."""
    n = model.body.n_points
    vol = model.body.volumes
    size = len(dofs)
    work = [np.empty(0)]  # flat extension buffer, kept between calls, grown to the widest block

    def matmat(v):
        v = np.asarray(v, dtype=np.float64)
        block = v.reshape(size, -1)
        full = np.zeros((3 * n, block.shape[1]))
        full[dofs] = block
        wanted = model.bonds.n_bonds * block.shape[1]
        if len(work[0]) < wanted:
            work[0] = np.empty(wanted)
        extension = work[0][:wanted].reshape(model.bonds.n_bonds, -1)
        f = block_linear_force(model, full.reshape(n, 3, -1), extension)
        out = (-vol[:, None, None] * f).reshape(3 * n, -1)[dofs]
        return out.reshape(v.shape)

    return LinearOperator((size, size), matvec=matmat, matmat=matmat, rmatvec=matmat, dtype=np.float64)
