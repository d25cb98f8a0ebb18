"""Kernels of bodies stored as a lattice: a regular grid, one stencil of offsets, no bond list.

Layout (``peridyn.discretization.lattice``):

- the grid has ``shape = (nx, ny, nz)`` (int64 array); grid point (ix, iy, iz) is row
  ``r = iz ny + iy`` and column ``ix``, flat index ``g = r nx + ix``: rows run along x and
  are contiguous;
- ``u``: (3, n_grid) structure of arrays, m, float64 or float32; the force kernels sum each
  row's forces in a (3, nx) array of their own and write them to ``f`` (n_out, 3), N/m^3, at the
  rows ``point_of`` (n_grid,) int gives (-1: not written), e.g. the body's point order;
- ``vol``: (n_grid,) m^3 of the kernel dtype, 0 for a grid point without material (a hole);
- the stencil: ``offs`` (n_off, 3) int64 integer offsets (ox, oy, oz) and per-offset tables
  of the kernel dtype: ``xi`` (n_off, 3) m, ``length`` |xi| m, ``inv_len`` 1/|xi|, and the
  per-offset coefficients of each law;
- ``broken``: (n_words, n_grid) uint64, bit ``k % 64`` of word ``k // 64`` set when the bond of
  grid point g along offset k is broken (pre-crack or damage).

A bond (g, k) counts when its far end lies in the grid, holds material (``vol > 0``) and its
bit is clear. Every kernel runs the rows in parallel; in a row, the offsets one after the
other and, for each, the row's points in a unit-stride loop over x (the neighbour row is the
row shifted by a constant: no index array is read). Each point's sums therefore add its
bonds in stencil order, from zero, as a bond-list kernel adds its family in neighbour order.

Two forms of the extension (as in ``peridyn.kernels``): float64 ``|Y| - |xi|`` with the
per-offset ``length`` (``cf`` False), float32 the cancellation-free
``du . (Y + xi) / (|Y| + |xi|)`` (``cf`` True). ``Y = xi + (u_j - u_i)`` is formed by
``deformed_component`` so that the two ends of a bond see exactly opposite vectors.
"""

import numba
import numpy as np

from peridyn.kernels import CHUNK, FASTMATH, deformed_component, stack_array


@numba.njit(fastmath=FASTMATH, cache=True, inline="always")
def _neighbour_row(r, ny, nz, nx, ox, oy, oz):
    """(first column, end column, flat offset of the neighbour) of row ``r`` along (ox, oy, oz);
    an empty range when the neighbour row lies outside the grid."""
    iz = r // ny
    iy = r - iz * ny
    jy = iy + oy
    jz = iz + oz
    if jy < 0 or jy >= ny or jz < 0 or jz >= nz:
        return 0, 0, 0
    lo = max(0, -ox)
    hi = min(nx, nx - ox)
    return lo, hi, (jz * ny + jy) * nx + ox - r * nx


@numba.njit(fastmath=FASTMATH, cache=True, inline="always")
def _bond_terms(cf, u, p0, q0, m, x0, x1, x2, L, bits, bit, vq, buf):
    """The first loop of a chunk (``peridyn.kernels``): for the ``m`` bonds of the points
    ``p0 .. p0 + m - 1`` along one offset (neighbours ``q0 ..``), Y into ``buf[CHUNK + q]``,
    ``buf[2 CHUNK + q]``, ``buf[3 CHUNK + q]``, |Y| into ``buf[4 CHUNK + q]``, the extension e
    into ``buf[5 CHUNK + q]`` and whether the bond counts (intact, to material) as 1 or 0 into
    ``buf[q]``. No sum: it vectorises. ``bits``: the chunk's broken words of the offset, ``vq``
    the neighbours' volumes."""
    zero = buf.dtype.type(0.0)
    one = buf.dtype.type(1.0)
    a0 = u[0, p0 : p0 + m]
    a1 = u[1, p0 : p0 + m]
    a2 = u[2, p0 : p0 + m]
    b0 = u[0, q0 : q0 + m]
    b1 = u[1, q0 : q0 + m]
    b2 = u[2, q0 : q0 + m]
    for q in range(m):
        y0 = deformed_component(x0, b0[q], a0[q])
        y1 = deformed_component(x1, b1[q], a1[q])
        y2 = deformed_component(x2, b2[q], a2[q])
        r = np.sqrt(y0 * y0 + y1 * y1 + y2 * y2)
        if cf:  # du . (Y + xi) / (|Y| + |xi|), du from u itself (Y - xi keeps only Y's rounding)
            d0 = b0[q] - a0[q]
            d1 = b1[q] - a1[q]
            d2 = b2[q] - a2[q]
            e = (d0 * (y0 + x0) + d1 * (y1 + x1) + d2 * (y2 + x2)) / (r + L)
        else:
            e = r - L
        ok = ((bits[q] & bit) == 0) & (vq[q] > zero)
        buf[q] = one if ok else zero
        buf[CHUNK + q] = y0
        buf[2 * CHUNK + q] = y1
        buf[3 * CHUNK + q] = y2
        buf[4 * CHUNK + q] = r
        buf[5 * CHUNK + q] = e


@numba.njit(fastmath=FASTMATH, cache=True, inline="always")
def _write_row(row, point_of, base, f):
    """The (3, nx) forces ``row`` of the grid points ``base ..`` into ``f`` at their rows
    ``point_of`` (those with one, >= 0)."""
    for ix in range(row.shape[1]):
        i = point_of[base + ix]
        if i >= 0:
            f[i, 0] = row[0, ix]
            f[i, 1] = row[1, ix]
            f[i, 2] = row[2, ix]


#: Values per bond of a chunk in the lattice kernels' stack buffer (see ``_bond_terms``).
LATTICE_BUFFER = 6 * CHUNK


@numba.njit(parallel=True, fastmath=FASTMATH, cache=True)
def lattice_pmb_force(u, vol, broken, shape, offs, xi, length, inv_len, coef, cf, point_of, f):
    """PMB force density ``f`` (OUT, (n_out, 3), N/m^3, rows ``point_of``) of the grid points:
    f_i = sum_k coef_k V_j (1/|xi| - 1/|Y|) Y over the counted bonds (``coef`` = c0 omega beta,
    N/m^6; ``cf``: the cancellation-free form ``e / (|xi| |Y|)`` instead). Each row's offsets in
    chunks of ``CHUNK`` columns, two loops a chunk (``peridyn.kernels``)."""
    nx, ny, nz = shape[0], shape[1], shape[2]
    zero = u.dtype.type(0.0)
    one = u.dtype.type(1.0)
    for r in numba.prange(ny * nz):
        base = r * nx
        buf = stack_array(LATTICE_BUFFER, u.dtype)
        row = np.zeros((3, nx), dtype=u.dtype)
        f0 = row[0]
        f1 = row[1]
        f2 = row[2]
        for k in range(offs.shape[0]):
            lo, hi, shift = _neighbour_row(r, ny, nz, nx, offs[k, 0], offs[k, 1], offs[k, 2])
            bit = np.uint64(1) << np.uint64(k & 63)
            bits = broken[k >> 6]
            x0, x1, x2, L, il, c = xi[k, 0], xi[k, 1], xi[k, 2], length[k], inv_len[k], coef[k]
            for c0 in range(lo, hi, CHUNK):
                m = min(CHUNK, hi - c0)
                p0 = base + c0
                vq = vol[p0 + shift : p0 + shift + m]
                _bond_terms(cf, u, p0, p0 + shift, m, x0, x1, x2, L, bits[p0 : p0 + m], bit, vq, buf)
                for q in range(m):
                    rr = buf[4 * CHUNK + q]
                    t = buf[5 * CHUNK + q] * il / rr if cf else il - one / rr
                    buf[q] = c * vq[q] * t if buf[q] > zero else zero
                g0 = f0[c0 : c0 + m]
                g1 = f1[c0 : c0 + m]
                g2 = f2[c0 : c0 + m]
                for q in range(m):
                    s = buf[q]
                    g0[q] += s * buf[CHUNK + q]
                    g1[q] += s * buf[2 * CHUNK + q]
                    g2[q] += s * buf[3 * CHUNK + q]
        _write_row(row, point_of, base, f)
    return f


@numba.njit(parallel=True, fastmath=FASTMATH, cache=True)
def lattice_lps_dilatation(u, vol, broken, shape, offs, xi, length, weight, cf, theta_coef, theta):
    """LPS dilatation ``theta`` (OUT, (n_grid,)): theta_i = theta_coef_i sum_k w V_j |xi| e over
    the counted bonds (``weight`` = omega beta per offset)."""
    nx, ny, nz = shape[0], shape[1], shape[2]
    zero = theta.dtype.type(0.0)
    for r in numba.prange(ny * nz):
        base = r * nx
        buf = stack_array(LATTICE_BUFFER, theta.dtype)
        th = theta[base : base + nx]
        for ix in range(nx):
            th[ix] = zero
        for k in range(offs.shape[0]):
            lo, hi, shift = _neighbour_row(r, ny, nz, nx, offs[k, 0], offs[k, 1], offs[k, 2])
            bit = np.uint64(1) << np.uint64(k & 63)
            bits = broken[k >> 6]
            x0, x1, x2, L, wk = xi[k, 0], xi[k, 1], xi[k, 2], length[k], weight[k]
            for c0 in range(lo, hi, CHUNK):
                m = min(CHUNK, hi - c0)
                p0 = base + c0
                vq = vol[p0 + shift : p0 + shift + m]
                _bond_terms(cf, u, p0, p0 + shift, m, x0, x1, x2, L, bits[p0 : p0 + m], bit, vq, buf)
                g = th[c0 : c0 + m]
                for q in range(m):
                    g[q] += (wk * vq[q]) * L * buf[5 * CHUNK + q] if buf[q] > zero else zero
        tc = theta_coef[base : base + nx]
        for ix in range(nx):
            th[ix] *= tc[ix]
    return theta


@numba.njit(parallel=True, fastmath=FASTMATH, cache=True)
def lattice_lps_force(u, vol, broken, shape, offs, xi, length, weight, cf, alpha, p, point_of, f):
    """LPS force density ``f`` (OUT, (n_out, 3), N/m^3, rows ``point_of``) from the per-point ``p`` = P_i and
    deviatoric coefficients ``alpha`` (n_grid,):
    f_i = sum_k [w |xi| (P_i + P_j) + w (alpha_i + alpha_j) e] Y / |Y|, w = omega beta V_j."""
    nx, ny, nz = shape[0], shape[1], shape[2]
    zero = u.dtype.type(0.0)
    for r in numba.prange(ny * nz):
        base = r * nx
        buf = stack_array(LATTICE_BUFFER, u.dtype)
        row = np.zeros((3, nx), dtype=u.dtype)
        f0 = row[0]
        f1 = row[1]
        f2 = row[2]
        for k in range(offs.shape[0]):
            lo, hi, shift = _neighbour_row(r, ny, nz, nx, offs[k, 0], offs[k, 1], offs[k, 2])
            bit = np.uint64(1) << np.uint64(k & 63)
            bits = broken[k >> 6]
            x0, x1, x2, L, wk = xi[k, 0], xi[k, 1], xi[k, 2], length[k], weight[k]
            for c0 in range(lo, hi, CHUNK):
                m = min(CHUNK, hi - c0)
                i0 = base + c0
                j0 = i0 + shift
                vq = vol[j0 : j0 + m]
                _bond_terms(cf, u, i0, j0, m, x0, x1, x2, L, bits[i0 : i0 + m], bit, vq, buf)
                pi = p[i0 : i0 + m]
                pj = p[j0 : j0 + m]
                ai = alpha[i0 : i0 + m]
                aj = alpha[j0 : j0 + m]
                for q in range(m):
                    w = wk * vq[q]
                    e = buf[5 * CHUNK + q]
                    t = (w * L * (pi[q] + pj[q]) + w * (ai[q] + aj[q]) * e) / buf[4 * CHUNK + q]
                    buf[q] = t if buf[q] > zero else zero
                g0 = f0[c0 : c0 + m]
                g1 = f1[c0 : c0 + m]
                g2 = f2[c0 : c0 + m]
                for q in range(m):
                    s = buf[q]
                    g0[q] += s * buf[CHUNK + q]
                    g1[q] += s * buf[2 * CHUNK + q]
                    g2[q] += s * buf[3 * CHUNK + q]
        _write_row(row, point_of, base, f)
    return f


@numba.njit(parallel=True, cache=True)
def lattice_bond_sum(vol, broken, shape, offs, coef, every, out):
    """``out`` (OUT, (n_grid,) float64): sum_k coef_k V_j over each point's bonds whose far end
    holds material, intact ones only unless ``every`` (weighted volumes, stiffness bounds, the
    totals of the damage index)."""
    nx, ny, nz = shape[0], shape[1], shape[2]
    for r in numba.prange(ny * nz):
        base = r * nx
        for ix in range(nx):
            out[base + ix] = 0.0
        for k in range(offs.shape[0]):
            lo, hi, shift = _neighbour_row(r, ny, nz, nx, offs[k, 0], offs[k, 1], offs[k, 2])
            word = k >> 6
            bit = np.uint64(1) << np.uint64(k & 63)
            c = coef[k]
            for ix in range(lo, hi):
                p = base + ix
                q = p + shift
                ok = (every or (broken[word, p] & bit) == 0) and vol[q] > 0.0
                out[p] += c * vol[q] if ok else 0.0
    return out


@numba.njit(parallel=True, cache=True)
def lattice_damage_index(vol, broken, shape, offs, coef, point_of, phi):
    """Damage index ``phi`` (OUT, (n_out,) float64, at the rows ``point_of``): 1 - the intact
    share of sum_k coef_k V_j over each point's bonds to material (0 without one), the two sums
    as ``lattice_bond_sum`` adds them."""
    nx, ny, nz = shape[0], shape[1], shape[2]
    for r in numba.prange(ny * nz):
        base = r * nx
        sums = np.zeros((2, nx))  # every bond, the intact ones
        for k in range(offs.shape[0]):
            lo, hi, shift = _neighbour_row(r, ny, nz, nx, offs[k, 0], offs[k, 1], offs[k, 2])
            word = k >> 6
            bit = np.uint64(1) << np.uint64(k & 63)
            c = coef[k]
            for ix in range(lo, hi):
                p = base + ix
                q = p + shift
                held = vol[q] > 0.0
                sums[0, ix] += c * vol[q] if held else 0.0
                sums[1, ix] += c * vol[q] if held and (broken[word, p] & bit) == 0 else 0.0
        for ix in range(nx):
            i = point_of[base + ix]
            if i >= 0:
                phi[i] = 1.0 - sums[1, ix] / sums[0, ix] if sums[0, ix] > 0 else 0.0
    return phi


@numba.njit(parallel=True, cache=True)
def lattice_owned_bonds(vol, broken, shape, offs, grid_index, n_owned):
    """(bonds, broken bits) of the body points ``0 .. n_owned - 1`` (grid points ``grid_index``,
    (n_points,) int64): their directed bonds to grid points that hold material (``vol > 0``),
    broken or not, and the bits set in their broken words. No array of the body's size."""
    nx, ny = shape[0], shape[1]
    bonds = 0
    cut = 0
    for i in numba.prange(n_owned):
        g = grid_index[i]
        r = g // nx
        ix = g - r * nx
        iz = r // ny
        iy = r - iz * ny
        for k in range(offs.shape[0]):
            jx = ix + offs[k, 0]
            jy = iy + offs[k, 1]
            jz = iz + offs[k, 2]
            inside = 0 <= jx < nx and 0 <= jy < ny and 0 <= jz < shape[2]
            bonds += 1 if inside and vol[(jz * ny + jy) * nx + jx] > 0.0 else 0
        for w in range(broken.shape[0]):
            word = broken[w, g]
            while word != 0:  # one set bit a turn
                word &= word - np.uint64(1)
                cut += 1
    return bonds, cut


@numba.njit(parallel=True, cache=True)
def lattice_pair_sum(vol, broken, shape, offs, coef, a, b, out):
    """``out`` (OUT, (n_grid,) float64): sum_k coef_k V_j (a_i + b_j) over each point's intact
    bonds to material (``a``, ``b`` (n_grid,) float64): the LPS stiffness bound's pair terms."""
    nx, ny, nz = shape[0], shape[1], shape[2]
    for r in numba.prange(ny * nz):
        base = r * nx
        for ix in range(nx):
            out[base + ix] = 0.0
        for k in range(offs.shape[0]):
            lo, hi, shift = _neighbour_row(r, ny, nz, nx, offs[k, 0], offs[k, 1], offs[k, 2])
            word = k >> 6
            bit = np.uint64(1) << np.uint64(k & 63)
            c = coef[k]
            for ix in range(lo, hi):
                p = base + ix
                q = p + shift
                ok = (broken[word, p] & bit) == 0 and vol[q] > 0.0
                out[p] += c * vol[q] * (a[p] + b[q]) if ok else 0.0
    return out


@numba.njit(parallel=True, cache=True)
def lattice_energy_sum(u, vol, broken, shape, offs, xi, length, coef, theta, dim, out):
    """``out`` (OUT, (n_grid,) float64): sum_k coef_k V_j (e - theta_i |xi| / d)^2 / |xi| over the
    intact bonds to material, e = |Y| - |xi| (float64). PMB energy density: coef = c0 omega beta / 4
    and theta = 0; LPS deviatoric squares sum w (e - theta |xi| / d)^2: coef = omega beta |xi|."""
    nx, ny, nz = shape[0], shape[1], shape[2]
    for r in numba.prange(ny * nz):
        base = r * nx
        for ix in range(nx):
            out[base + ix] = 0.0
        for k in range(offs.shape[0]):
            lo, hi, shift = _neighbour_row(r, ny, nz, nx, offs[k, 0], offs[k, 1], offs[k, 2])
            word = k >> 6
            bit = np.uint64(1) << np.uint64(k & 63)
            x0, x1, x2, L, c = xi[k, 0], xi[k, 1], xi[k, 2], length[k], coef[k]
            for ix in range(lo, hi):
                p = base + ix
                q = p + shift
                if (broken[word, p] & bit) != 0 or not vol[q] > 0.0:
                    continue
                y0 = deformed_component(x0, u[0, q], u[0, p])
                y1 = deformed_component(x1, u[1, q], u[1, p])
                y2 = deformed_component(x2, u[2, q], u[2, p])
                ed = np.sqrt(y0 * y0 + y1 * y1 + y2 * y2) - L - theta[p] * L / dim
                out[p] += c * vol[q] * ed * ed / L
    return out


@numba.njit(parallel=True, cache=True)
def lattice_stretch_test(u, vol, broken, shape, offs, xi, limit, breakable, count, room):
    """Break every intact bond between points with material whose deformed length |Y| exceeds
    ``limit`` (m, per offset: |xi| (1 + s_c)) and whose two ends are ``breakable`` ((n_grid,)
    bool): sets its bit in ``broken`` (IN/OUT). Both ends of a bond see the same |Y| (exactly
    opposite vectors), so each point sets its own bits only and a bond breaks from both ends in
    the same call. ``count`` (OUT, (n_rows,) int64): bits set per row; ``room`` (OUT, (n_rows,)
    float64, m): per row, the smallest ``limit - |Y|`` of the breakable bonds left intact (inf
    without one). Returns the number of bits set."""
    nx, ny, nz = shape[0], shape[1], shape[2]
    for r in numba.prange(ny * nz):
        base = r * nx
        count[r] = 0
        least = np.inf
        for k in range(offs.shape[0]):
            lo, hi, shift = _neighbour_row(r, ny, nz, nx, offs[k, 0], offs[k, 1], offs[k, 2])
            word = k >> 6
            bit = np.uint64(1) << np.uint64(k & 63)
            x0, x1, x2 = xi[k, 0], xi[k, 1], xi[k, 2]
            for ix in range(lo, hi):
                p = base + ix
                q = p + shift
                if (broken[word, p] & bit) != 0 or not (
                    vol[p] > 0.0 and vol[q] > 0.0 and breakable[p] and breakable[q]
                ):
                    continue
                y0 = deformed_component(x0, u[0, q], u[0, p])
                y1 = deformed_component(x1, u[1, q], u[1, p])
                y2 = deformed_component(x2, u[2, q], u[2, p])
                rest = limit[k] - np.sqrt(y0 * y0 + y1 * y1 + y2 * y2)
                if rest < 0.0:
                    broken[word, p] |= bit
                    count[r] += 1
                else:
                    least = min(least, rest)
        room[r] = least
    return count.sum()


@numba.njit(cache=True)
def lattice_scatter(u, grid_index, ug):
    """``ug[:, grid_index[i]]`` (OUT, (3, n_grid)) = ``u[i]`` ((n_points, 3)) for every body point."""
    for i in range(grid_index.shape[0]):
        g = grid_index[i]
        ug[0, g] = u[i, 0]
        ug[1, g] = u[i, 1]
        ug[2, g] = u[i, 2]
    return ug


@numba.njit(cache=True)
def largest_move_squared(u, ref):
    """max_i |u_i - ref_i|^2 (m^2) of two (n_points, 3) displacements, with no temporary."""
    largest = 0.0
    for i in range(u.shape[0]):
        d0 = u[i, 0] - ref[i, 0]
        d1 = u[i, 1] - ref[i, 1]
        d2 = u[i, 2] - ref[i, 2]
        largest = max(largest, d0 * d0 + d1 * d1 + d2 * d2)
    return largest
