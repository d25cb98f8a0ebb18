"""Energy surface correction of the LPS deviatoric part (``surface_correction: energy``).

Near a free surface a point's family is cut, and the LPS deviatoric energy no longer
matches the continuum for every deviatoric deformation: on a cubic grid with horizon
sqrt(2) h a point on a face is 43 % too stiff in the shear parallel to the face and
29 % too soft in the two shears across it, so one factor per point (``shear-factor``)
cannot fix both. Here each point i gets its own deviatoric bond factors g_ij in

    W_i = kappa theta_i^2 / 2 + (alpha_i / 2) [ sum_j g_ij w_ij e_ij^2 - m~_i theta_i^2 / d^2 ],
    m~_i = sum_j g_ij w_ij |xi|^2,

which is plain LPS for g = 1 and keeps, for any g, no deviatoric energy under an
isotropic expansion (e = theta |xi| / d) and the dilatation theta of plain LPS.

The factors are the smallest change of the point's weights (in the norm
sum_j w |xi|^2 (g - 1)^2) for which its deviatoric energy of each test deformation k
equals the continuum value W_k = mu eps_k : eps_k: the energy method of Madenci and
Oterkus (2014, sec. 4.2) with per-direction factors, here per bond from Lagrange
multipliers as in the position-aware linear solid (Mitchell, Silling and Littlewood
2015). The tests are the traceless strains: pure shears of the coordinate planes and
isochoric extensions along the axes (3 + 3 in 3D, 1 + 2 in 2D). W_k is linear in g:
W_k = (alpha_i / 2) sum_j g_ij w |xi|^2 r_jk with r_jk = (n.eps_k.n)^2 - theta_ik^2 / d^2
(the linear model, e = |xi| n.eps.n), so the Lagrange conditions give, per point,

    g_ij = 1 + sum_k lambda_ik r_jk,
    sum_l A_kl lambda_il = W_k - (alpha_i / 2) sum_j w |xi|^2 r_jk,
    A_kl = (alpha_i / 2) sum_j w |xi|^2 r_jk r_jl,

solved with a pseudo-inverse (tests that a cut family cannot tell apart share the
correction). Interior points of a cubic grid with horizon sqrt(2) h (18 neighbours,
already exact) get g = 1 to round-off; on other lattices (2 h, 3 h) the interior factors
also remove the lattice's anisotropy (the same factors at every interior point; Bloch
long waves then classical to 1e-6).
"""

from __future__ import annotations

import numpy as np


def deviatoric_tests(dim: int) -> np.ndarray:
    """The traceless test strains (k, 3, 3): pure shears eps_ab = eps_ba = 1 of the coordinate
    planes, then isochoric extensions along each axis (eps_aa = 1, the others -1 / (d - 1))."""
    tests = []
    planes = [(0, 1), (0, 2), (1, 2)] if dim == 3 else [(0, 1)]
    for a, b in planes:
        eps = np.zeros((3, 3))
        eps[a, b] = eps[b, a] = 1.0
        tests.append(eps)
    for a in range(dim):
        eps = np.zeros((3, 3))
        eps[np.arange(dim), np.arange(dim)] = -1.0 / (dim - 1)
        eps[a, a] = 1.0
        tests.append(eps)
    return np.array(tests)


def energy_factors(owners, n_vec, length, w, alpha, shear, dim, n_points) -> np.ndarray:
    """Per directed bond i->j, the factor g_ij of point i's deviatoric weight (n_bonds,).

    ``owners`` (n_bonds,) the point i of each bond; ``n_vec`` (n_bonds, 3) unit bond
    vectors; ``length`` (n_bonds,) m; ``w`` (n_bonds,) omega beta V_j, m^3, zero on broken
    bonds; ``alpha`` (n_points,) the deviatoric coefficient 15 mu / m_i (8 mu / m_i in 2D);
    ``shear`` mu, Pa: a number, or (n_points,) each point's own (a body of several blocks).
    """
    tests = deviatoric_tests(dim)
    n_tests = len(tests)
    m = np.bincount(owners, w * length**2, minlength=n_points)
    r = np.empty((len(owners), n_tests))
    norms = np.empty(n_tests)
    for k, eps in enumerate(tests):
        stretch = np.einsum("ba,ac,bc->b", n_vec, eps, n_vec)
        theta = dim * np.bincount(owners, w * length**2 * stretch, minlength=n_points) / m
        r[:, k] = stretch**2 - (theta[owners] / dim) ** 2
        norms[k] = np.sum(eps * eps)
    continuum = np.asarray(shear)[..., None] * norms  # W_k = mu eps_k : eps_k, (n_tests,) or (n, n_tests)
    weight = 0.5 * alpha[owners] * w * length**2
    gram = np.empty((n_points, n_tests, n_tests))
    for k in range(n_tests):
        for q in range(k, n_tests):
            gram[:, k, q] = gram[:, q, k] = np.bincount(
                owners, weight * r[:, k] * r[:, q], minlength=n_points
            )
    plain = np.stack(
        [np.bincount(owners, weight * r[:, k], minlength=n_points) for k in range(n_tests)], axis=1
    )
    lam = np.einsum("pkq,pq->pk", np.linalg.pinv(gram, rcond=1e-10, hermitian=True), continuum - plain)
    return 1.0 + np.einsum("bk,bk->b", lam[owners], r)
