"""Per-point deformation and stress: the nonlocal deformation gradient, the Green-Lagrange
strain and the peridynamic partial stress of a body at a displacement.

Deformation gradient (Silling, Epton, Weckner, Xu, Askari 2007, sec. 18; Peridigm's
``Deformation_Gradient``): over the intact bonds of point i, with the weight
w_ij = omega(|xi|) beta_ij V_j (influence function, partial-volume factor, neighbour volume, m^3),

    K_i = sum_j w_ij xi_ij (x) xi_ij,    F_i = (sum_j w_ij Y_ij (x) xi_ij) K_i^-1,

xi the reference and Y = xi + u_j - u_i the deformed bond. For u = H x every Y_ij equals
(I + H) xi_ij, so F_i = I + H exactly at every point, surfaces included. A broken bond is left
out of both sums: F then describes the deformation of what is still bonded to the point.
In 2D (``body.dim == 2``) the sums are the 2 x 2 in-plane blocks.

A point whose shape tensor is singular (fewer than ``dim`` independent intact bonds, e.g. a
detached point) has no deformation gradient: there F and the strain are 0 and ``valid`` is
False. "Singular" is condition number above :data:`MAX_CONDITION` (F's rounding is about
the condition number times 1e-16).

Strain: the Green-Lagrange strain E = (F^T F - I) / 2, stored rather than the small strain
(F + F^T) / 2 - I because it is objective: a rigidly rotating fragment (fracture runs) has
E = 0, while its small strain would be of the order of the rotation angle squared, or
larger. The two agree to O(|F - I|^2) at small strains.

Stress: ``Model.partial_stress`` (see there): sigma_i = sum_j T_ij (x) xi_ij V_j, Pa, a
first Piola-Kirchhoff (nominal) stress, not symmetric under finite rotations.
"""

from __future__ import annotations

import numpy as np

from peridyn.discretization.body import Body
from peridyn.discretization.bonds import Bonds
from peridyn.kernels.stress import shape_tensors

#: Largest condition number of a shape tensor K_i with which F_i is computed.
MAX_CONDITION = 1e8


def deformation_gradient(body: Body, bonds: Bonds, u: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Nonlocal deformation gradient of every point (module docstring).

    Parameters
    ----------
    body, bonds : Body, Bonds
        ``bonds.intact`` says which bonds count.
    u : (n_points, 3) array, m

    Returns
    -------
    F : (n_points, dim, dim) float64, dimensionless
        0 where ``valid`` is False.
    valid : (n_points,) bool
        The point's shape tensor has condition number at most :data:`MAX_CONDITION`.
    """
    n, dim = body.n_points, body.dim
    weight = bonds.influence * bonds.volume_factor * body.volumes[bonds.neighbours]
    K, N = shape_tensors(
        body.points,
        np.ascontiguousarray(u, dtype=np.float64),
        bonds.offsets,
        bonds.neighbours,
        weight,
        bonds.intact,
        np.empty((n, 3, 3)),
        np.empty((n, 3, 3)),
    )
    K, N = K[:, :dim, :dim], N[:, :dim, :dim]
    eig = np.linalg.eigvalsh(K)  # ascending, K symmetric positive semi-definite
    valid = eig[:, -1] > 0.0
    valid[valid] = eig[valid, 0] * MAX_CONDITION >= eig[valid, -1]
    F = np.zeros((n, dim, dim))
    # F K = N with K symmetric: K F^T = N^T
    F[valid] = np.linalg.solve(K[valid], N[valid].transpose(0, 2, 1)).transpose(0, 2, 1)
    return F, valid


def green_lagrange_strain(F: np.ndarray, valid: np.ndarray) -> np.ndarray:
    """E = (F^T F - I) / 2 (n_points, dim, dim), dimensionless; 0 where ``valid`` is False."""
    dim = F.shape[-1]
    E = 0.5 * (np.einsum("nka,nkb->nab", F, F) - np.eye(dim))
    E[~valid] = 0.0
    return E


def strain_field(body: Body, bonds: Bonds, u: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Green-Lagrange strain (n_points, dim, dim) and its ``valid`` mask (n_points,) at ``u`` (m)."""
    F, valid = deformation_gradient(body, bonds, u)
    return green_lagrange_strain(F, valid), valid
