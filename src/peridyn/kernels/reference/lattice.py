"""References of ``peridyn.kernels.lattice``: the lattice expanded into an explicit list of
bonds, then each quantity from its definition (float64)."""

import numpy as np


def lattice_bonds(vol, broken, shape, offs):
    """(owner, neighbour, offset index, intact) (n_bonds,) of every bond of every grid point to a
    grid point with material (``vol > 0``): the bond list the lattice stands for."""
    nx, ny, nz = (int(s) for s in shape)
    g = np.arange(nx * ny * nz)
    ix, iy, iz = g % nx, (g // nx) % ny, g // (nx * ny)
    owners, nbrs, ks, intact = [], [], [], []
    for k, (ox, oy, oz) in enumerate(np.asarray(offs)):
        jx, jy, jz = ix + ox, iy + oy, iz + oz
        inside = (jx >= 0) & (jx < nx) & (jy >= 0) & (jy < ny) & (jz >= 0) & (jz < nz)
        q = np.where(inside, (jz * ny + jy) * nx + jx, 0)
        keep = inside & (np.asarray(vol)[q] > 0)
        p = g[keep]
        owners.append(p)
        nbrs.append(q[keep])
        ks.append(np.full(len(p), k))
        bit = (np.asarray(broken)[k // 64, p] >> np.uint64(k % 64)) & np.uint64(1)
        intact.append(bit == 0)
    return tuple(np.concatenate(a) for a in (owners, nbrs, ks, intact))


def _deformed(u, xi, p, q, k):
    """(n_bonds, 3) Y = xi_k + u_q - u_p and |Y|, float64."""
    u = np.asarray(u, dtype=np.float64)
    y = np.asarray(xi, dtype=np.float64)[k] + (u[:, q] - u[:, p]).T
    return y, np.linalg.norm(y, axis=1)


def _extension(xi, length, k, r, cf):
    """(n_bonds,) e = |Y| - |xi|: with the stored ``length`` (float64 kernels), or with |xi| of
    the stored vector (``cf``: the cancellation-free kernels, for which e = 0 at u = 0 exactly)."""
    if cf:
        return r - np.linalg.norm(np.asarray(xi, dtype=np.float64)[k], axis=1)
    return r - np.asarray(length, dtype=np.float64)[k]


def _to_points(n, p, values):
    """(n,) or (3, n): per-bond values summed on their owners."""
    if values.ndim == 1:
        return np.bincount(p, values, minlength=n)
    return np.stack([np.bincount(p, values[:, a], minlength=n) for a in range(3)])


def lattice_pmb_force(u, vol, broken, shape, offs, xi, length, coef, cf=False):
    """(3, n_grid) N/m^3: f_i = sum c V_j s Y / |Y|, s = e / |xi|, over intact bonds."""
    p, q, k, ok = lattice_bonds(vol, broken, shape, offs)
    y, r = _deformed(u, xi, p, q, k)
    L = np.asarray(length, dtype=np.float64)[k]
    e = _extension(xi, length, k, r, cf)
    t = np.where(ok, np.asarray(coef, np.float64)[k] * np.asarray(vol, np.float64)[q] * e / L / r, 0.0)
    return _to_points(np.asarray(vol).size, p, t[:, None] * y)


def lattice_lps_dilatation(u, vol, broken, shape, offs, xi, length, weight, theta_coef, cf=False):
    """(n_grid,): theta_i = theta_coef_i sum w V_j |xi| e over intact bonds."""
    p, q, k, ok = lattice_bonds(vol, broken, shape, offs)
    _, r = _deformed(u, xi, p, q, k)
    L = np.asarray(length, dtype=np.float64)[k]
    w = np.asarray(weight, np.float64)[k] * np.asarray(vol, np.float64)[q]
    e = _extension(xi, length, k, r, cf)
    return np.asarray(theta_coef, np.float64) * _to_points(
        np.asarray(vol).size, p, np.where(ok, w * L * e, 0.0)
    )


def lattice_lps_force(u, vol, broken, shape, offs, xi, length, weight, alpha, pressure, cf=False):
    """(3, n_grid) N/m^3: sum [w |xi| (P_i + P_j) + w (alpha_i + alpha_j) e] Y / |Y| over intact bonds."""
    p, q, k, ok = lattice_bonds(vol, broken, shape, offs)
    y, r = _deformed(u, xi, p, q, k)
    L = np.asarray(length, dtype=np.float64)[k]
    w = np.asarray(weight, np.float64)[k] * np.asarray(vol, np.float64)[q]
    a, P = np.asarray(alpha, np.float64), np.asarray(pressure, np.float64)
    e = _extension(xi, length, k, r, cf)
    t = np.where(ok, (w * L * (P[p] + P[q]) + w * (a[p] + a[q]) * e) / r, 0.0)
    return _to_points(np.asarray(vol).size, p, t[:, None] * y)


def lattice_bond_sum(vol, broken, shape, offs, coef, every):
    """(n_grid,): sum coef_k V_j over the bonds to material (intact ones unless ``every``)."""
    p, q, k, ok = lattice_bonds(vol, broken, shape, offs)
    values = np.asarray(coef, np.float64)[k] * np.asarray(vol, np.float64)[q]
    return _to_points(np.asarray(vol).size, p, np.where(ok | every, values, 0.0))


def lattice_pair_sum(vol, broken, shape, offs, coef, a, b):
    """(n_grid,): sum coef_k V_j (a_i + b_j) over intact bonds to material."""
    p, q, k, ok = lattice_bonds(vol, broken, shape, offs)
    values = np.asarray(coef, np.float64)[k] * np.asarray(vol, np.float64)[q] * (a[p] + b[q])
    return _to_points(np.asarray(vol).size, p, np.where(ok, values, 0.0))


def lattice_energy_sum(u, vol, broken, shape, offs, xi, length, coef, theta, dim):
    """(n_grid,): sum coef_k V_j (e - theta_i |xi| / d)^2 / |xi| over intact bonds to material."""
    p, q, k, ok = lattice_bonds(vol, broken, shape, offs)
    _, r = _deformed(u, xi, p, q, k)
    L = np.asarray(length, dtype=np.float64)[k]
    ed = r - L - np.asarray(theta, np.float64)[p] * L / dim
    values = np.asarray(coef, np.float64)[k] * np.asarray(vol, np.float64)[q] * ed * ed / L
    return _to_points(np.asarray(vol).size, p, np.where(ok, values, 0.0))


def lattice_stretch_test(u, vol, broken, shape, offs, xi, limit, breakable):
    """(broken bits after the test, count, room (n_rows,)): every intact breakable bond between
    points with material with |Y| > limit_k broken; room: the smallest limit_k - |Y| of the
    bonds left so per row of the grid (inf without one)."""
    p, q, k, ok = lattice_bonds(vol, broken, shape, offs)
    _, r = _deformed(u, xi, p, q, k)
    tested = ok & (np.asarray(vol)[p] > 0) & breakable[p] & breakable[q]
    fail = tested & (r > np.asarray(limit)[k])
    rows = int(shape[1] * shape[2])
    room = np.full(rows, np.inf)
    np.minimum.at(room, p[tested & ~fail] // int(shape[0]), (np.asarray(limit)[k] - r)[tested & ~fail])
    out = np.array(broken, copy=True)
    for pp, kk in zip(p[fail], k[fail], strict=True):
        out[kk // 64, pp] |= np.uint64(1) << np.uint64(kk % 64)
    return out, int(fail.sum()), room


def lattice_scatter(u, grid_index, n_grid):
    """(3, n_grid): the body points' ``u`` (n_points, 3) at their grid points, 0 elsewhere."""
    out = np.zeros((3, n_grid), dtype=np.asarray(u).dtype)
    out[:, grid_index] = np.asarray(u).T
    return out
