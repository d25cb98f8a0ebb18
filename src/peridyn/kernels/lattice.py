"""Kernels of bodies stored as a lattice: a regular grid, one stencil of offsets, no bond list.

Layout (``peridyn.discretization.lattice``):

- the grid has ``shape = (nx, ny, nz)`` (int64 array); grid point (ix, iy, iz) is row
  ``r = iz ny + iy`` and column ``ix``, flat index ``g = r nx + ix``: rows run along x and
  are contiguous;
- ``u``: (3, n_grid) structure of arrays, m, float64 or float32; the force kernels sum the
  forces in ``grid_f`` (3, n_grid) and write each finished plane's to ``f`` (n_out, 3), N/m^3,
  at the rows ``point_of`` (n_grid,) int gives (-1: not written), e.g. the body's point order;
- ``vol``: (n_grid,) m^3 of the kernel dtype, 0 for a grid point without material (a hole);
- the stencil: ``offs`` (n_off, 3) int64 integer offsets (ox, oy, oz) and per-offset tables
  of the kernel dtype: ``xi`` (n_off, 3) m, ``length`` |xi| m, ``inv_len`` 1/|xi|, and the
  per-offset coefficients of each law;
- ``broken``: (n_words, n_grid) uint64, bit ``k % 64`` of word ``k // 64`` set when the bond of
  grid point g along offset k is broken (pre-crack or damage).

A bond (g, k) counts when its far end lies in the grid, holds material (``vol > 0``) and its
bit is clear. Every kernel runs rows of the grid (or slabs of rows) in parallel; in a row, the
offsets one after the other and, for each, the row's points in a unit-stride loop over x (the
neighbour row is the row shifted by a constant: no index array is read).

The force and dilatation kernels compute each pair of points once (``pair_offsets``: the
offsets whose (oy, oz, ox) is lexicographically positive, one of each two opposite ones): the
pair's term goes to its point, with the neighbour's volume, and to its neighbour, with the
point's volume (a force with the opposite sign), in a grid-sized sum; its broken bit is the
point's (a broken bond has both bits set). The grid is cut into slabs of ``width`` y planes
(every z), ``width`` the largest |oy|, so that the pairs of slab s end in slab s or s + 1: the
even slabs run in parallel, then the odd ones, each slab by one thread, its rows, offsets and
columns in one order (in a chunk, the neighbours' terms before the points': ``_add_pair_forces``).
Every point therefore adds its pairs in an order set by the grid's y and z planes and the stencil
alone, whatever the number of threads and whatever the grid's extent across x (an MPI rank's
slab of x planes with its ghosts adds its owned points' pairs as a serial run does). The other
kernels run each point's bonds from its own end, in stencil order.

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
def _bond_terms(cf, u, p0, q0, m, x0, x1, x2, L, bits, bit, vp, vq, buf):
    """The first loop of a chunk (``peridyn.kernels``): for the ``m`` pairs of the points
    ``p0 .. p0 + m - 1`` along one offset (neighbours ``q0 ..``), Y into ``buf[CHUNK + q]``,
    ``buf[2 CHUNK + q]``, ``buf[3 CHUNK + q]``, |Y| into ``buf[4 CHUNK + q]``, the extension e
    into ``buf[5 CHUNK + q]`` and whether the bond counts (intact, both ends with material) as 1
    or 0 into ``buf[q]``. No sum: it vectorises. ``bits``: the chunk's broken words of the
    offset, ``vp`` and ``vq`` the points' and the neighbours' volumes."""
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
        ok = ((bits[q] & bit) == 0) & (vq[q] > zero) & (vp[q] > zero)
        buf[q] = one if ok else zero
        buf[CHUNK + q] = y0
        buf[2 * CHUNK + q] = y1
        buf[3 * CHUNK + q] = y2
        buf[4 * CHUNK + q] = r
        buf[5 * CHUNK + q] = e


@numba.njit(fastmath=FASTMATH, cache=True, inline="always")
def _add_pair_forces(grid_f, p0, q0, m, vp, vq, buf):
    """The second loop of a chunk: each pair's force ``buf[q]`` V Y (``buf[q]`` the pair's scalar
    without the volume) subtracted from its neighbour (times the point's volume ``vp``), then
    added to its point (times the neighbour's volume ``vq``), in ``grid_f`` (3, n_grid). The
    neighbours first: along an offset within its row, a point's term as a neighbour then comes
    before its term as a point whether the pair's other end lies in its chunk or in the one
    before, so the sums do not depend on where the chunks start (a rank's grid starts elsewhere)."""
    h0 = grid_f[0, q0 : q0 + m]
    h1 = grid_f[1, q0 : q0 + m]
    h2 = grid_f[2, q0 : q0 + m]
    for q in range(m):
        s = buf[q] * vp[q]
        h0[q] -= s * buf[CHUNK + q]
        h1[q] -= s * buf[2 * CHUNK + q]
        h2[q] -= s * buf[3 * CHUNK + q]
    g0 = grid_f[0, p0 : p0 + m]
    g1 = grid_f[1, p0 : p0 + m]
    g2 = grid_f[2, p0 : p0 + m]
    for q in range(m):
        s = buf[q] * vq[q]
        g0[q] += s * buf[CHUNK + q]
        g1[q] += s * buf[2 * CHUNK + q]
        g2[q] += s * buf[3 * CHUNK + q]


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


def pair_offsets(offsets: np.ndarray) -> tuple[np.ndarray, int]:
    """(rows, width): the rows of the stencil ``offsets`` (n_off, 3) int whose (oy, oz, ox) is
    lexicographically positive (one of each two opposite offsets, in stencil order; int64), and
    the width in y planes of the pair kernels' slabs, the largest |oy| (at least 1)."""
    ox, oy, oz = np.asarray(offsets).T
    rows = np.flatnonzero((oy > 0) | ((oy == 0) & ((oz > 0) | ((oz == 0) & (ox > 0)))))
    return rows.astype(np.int64), max(1, int(np.abs(oy).max(initial=0)))


@numba.njit(fastmath=FASTMATH, cache=True, inline="always")
def _slab(colour, h, width, ny):
    """(first y, end y) of slab ``2 h + colour`` (empty past the grid)."""
    s = 2 * h + colour
    return min(ny, s * width), min(ny, (s + 1) * width)


@numba.njit(fastmath=FASTMATH, cache=True, inline="always")
def _phase_tasks(colour, n_slabs):
    """Slabs of phase ``colour``: the even ones, then the odd ones (at least one task: the one
    that finishes slab 0)."""
    return (n_slabs + 1) // 2 if colour == 0 else max(1, n_slabs // 2)


@numba.njit(fastmath=FASTMATH, cache=True, inline="always")
def _to_clear(colour, h, width, ny):
    """(y0, y1): the planes a phase-0 task clears before its pairs: its slab and the next (only
    its pairs reach the next one in phase 0); none in phase 1."""
    if colour == 1:
        return 0, 0
    y0, y1 = _slab(0, h, width, ny)
    return y0, min(ny, y1 + width)


@numba.njit(fastmath=FASTMATH, cache=True, inline="always")
def _finished(colour, h, width, ny):
    """(y0, y1): the planes final after a phase-1 task's pairs: its slab and the next (no later
    pair reaches them), and for task 0 slab 0 too (no phase-1 pair reaches it); none in phase 0."""
    if colour == 0:
        return 0, 0
    y0, y1 = _slab(1, h, width, ny)
    return (0 if h == 0 else y0), min(ny, y1 + width)


@numba.njit(fastmath=FASTMATH, cache=True)
def _clear_planes(a, y0, y1, shape):
    """``a`` (k, n_grid) = 0 on the grid points of the y planes ``y0 .. y1 - 1``."""
    nx, ny, nz = shape[0], shape[1], shape[2]
    zero = a.dtype.type(0.0)
    for iz in range(nz):
        for g in range((iz * ny + y0) * nx, (iz * ny + y1) * nx):
            for d in range(a.shape[0]):
                a[d, g] = zero


@numba.njit(fastmath=FASTMATH, cache=True)
def _write_planes(grid_f, y0, y1, shape, point_of, f):
    """The forces ``grid_f`` (3, n_grid) of the y planes ``y0 .. y1 - 1`` into ``f`` at ``point_of``."""
    nx, ny, nz = shape[0], shape[1], shape[2]
    for iz in range(nz):
        for iy in range(y0, y1):
            base = (iz * ny + iy) * nx
            _write_row(grid_f[:, base : base + nx], point_of, base, f)


@numba.njit(fastmath=FASTMATH, cache=True)
def _scale_planes(theta, y0, y1, shape, coef):
    """``theta *= coef`` ((n_grid,) each) on the y planes ``y0 .. y1 - 1``."""
    nx, ny, nz = shape[0], shape[1], shape[2]
    for iz in range(nz):
        for g in range((iz * ny + y0) * nx, (iz * ny + y1) * nx):
            theta[g] *= coef[g]


@numba.njit(parallel=True, fastmath=FASTMATH, cache=True)
def lattice_pmb_force(
    u, vol, broken, shape, offs, pairs, width, xi, length, inv_len, coef, cf, grid_f, point_of, f
):
    """PMB force density ``f`` (OUT, (n_out, 3), N/m^3, rows ``point_of``) of the grid points:
    f_i = sum_k coef_k V_j (1/|xi| - 1/|Y|) Y over the counted bonds (``coef`` = c0 omega beta,
    N/m^6; ``cf``: the cancellation-free form ``e / (|xi| |Y|)`` instead). Each pair once (the
    module docstring; ``pairs``, ``width``: ``pair_offsets``), summed in ``grid_f`` (scratch,
    (3, n_grid)); chunks of ``CHUNK`` columns, two loops a chunk (``peridyn.kernels``)."""
    nx, ny, nz = shape[0], shape[1], shape[2]
    zero = u.dtype.type(0.0)
    one = u.dtype.type(1.0)
    n_slabs = (ny + width - 1) // width
    for colour in range(2):
        for h in numba.prange(_phase_tasks(colour, n_slabs)):
            z0, z1 = _to_clear(colour, h, width, ny)
            _clear_planes(grid_f, z0, z1, shape)
            buf = stack_array(LATTICE_BUFFER, u.dtype)
            y0, y1 = _slab(colour, h, width, ny)
            for iy in range(y0, y1):
                for iz in range(nz):
                    r = iz * ny + iy
                    base = r * nx
                    for k in pairs:
                        lo, hi, shift = _neighbour_row(r, ny, nz, nx, offs[k, 0], offs[k, 1], offs[k, 2])
                        bit = np.uint64(1) << np.uint64(k & 63)
                        bits = broken[k >> 6]
                        x0, x1, x2, L, il, c = xi[k, 0], xi[k, 1], xi[k, 2], length[k], inv_len[k], coef[k]
                        for c0 in range(lo, hi, CHUNK):
                            m = min(CHUNK, hi - c0)
                            p0 = base + c0
                            q0 = p0 + shift
                            vp = vol[p0 : p0 + m]
                            vq = vol[q0 : q0 + m]
                            _bond_terms(cf, u, p0, q0, m, x0, x1, x2, L, bits[p0 : p0 + m], bit, vp, vq, buf)
                            for q in range(m):
                                rr = buf[4 * CHUNK + q]
                                t = buf[5 * CHUNK + q] * il / rr if cf else il - one / rr
                                buf[q] = c * t if buf[q] > zero else zero
                            _add_pair_forces(grid_f, p0, q0, m, vp, vq, buf)
            w0, w1 = _finished(colour, h, width, ny)
            _write_planes(grid_f, w0, w1, shape, point_of, f)
    return f


@numba.njit(parallel=True, fastmath=FASTMATH, cache=True)
def lattice_lps_dilatation(
    u, vol, broken, shape, offs, pairs, width, xi, length, weight, cf, theta_coef, theta
):
    """LPS dilatation ``theta`` (OUT, (n_grid,); 0 where ``vol`` is 0): theta_i = theta_coef_i
    sum_k w V_j |xi| e over the counted bonds (``weight`` = omega beta per offset), each pair
    once (theta_i += w V_j |xi| e, theta_j += w V_i |xi| e; ``pairs``, ``width``: ``pair_offsets``)."""
    nx, ny, nz = shape[0], shape[1], shape[2]
    zero = theta.dtype.type(0.0)
    n_slabs = (ny + width - 1) // width
    sums = theta.reshape((1, theta.shape[0]))
    for colour in range(2):
        for h in numba.prange(_phase_tasks(colour, n_slabs)):
            z0, z1 = _to_clear(colour, h, width, ny)
            _clear_planes(sums, z0, z1, shape)
            buf = stack_array(LATTICE_BUFFER, theta.dtype)
            y0, y1 = _slab(colour, h, width, ny)
            for iy in range(y0, y1):
                for iz in range(nz):
                    r = iz * ny + iy
                    base = r * nx
                    for k in pairs:
                        lo, hi, shift = _neighbour_row(r, ny, nz, nx, offs[k, 0], offs[k, 1], offs[k, 2])
                        bit = np.uint64(1) << np.uint64(k & 63)
                        bits = broken[k >> 6]
                        x0, x1, x2, L, wk = xi[k, 0], xi[k, 1], xi[k, 2], length[k], weight[k]
                        for c0 in range(lo, hi, CHUNK):
                            m = min(CHUNK, hi - c0)
                            p0 = base + c0
                            q0 = p0 + shift
                            vp = vol[p0 : p0 + m]
                            vq = vol[q0 : q0 + m]
                            _bond_terms(cf, u, p0, q0, m, x0, x1, x2, L, bits[p0 : p0 + m], bit, vp, vq, buf)
                            for q in range(m):
                                buf[q] = (wk * L) * buf[5 * CHUNK + q] if buf[q] > zero else zero
                            g = theta[q0 : q0 + m]  # the neighbours first (``_add_pair_forces``)
                            for q in range(m):
                                g[q] += vp[q] * buf[q]
                            g = theta[p0 : p0 + m]
                            for q in range(m):
                                g[q] += vq[q] * buf[q]
            w0, w1 = _finished(colour, h, width, ny)
            _scale_planes(theta, w0, w1, shape, theta_coef)
    return theta


@numba.njit(parallel=True, fastmath=FASTMATH, cache=True)
def lattice_lps_force(
    u, vol, broken, shape, offs, pairs, width, xi, length, weight, cf, alpha, p, grid_f, point_of, f
):
    """LPS force density ``f`` (OUT, (n_out, 3), N/m^3, rows ``point_of``) from the per-point ``p`` = P_i and
    deviatoric coefficients ``alpha`` (n_grid,):
    f_i = sum_k [w |xi| (P_i + P_j) + w (alpha_i + alpha_j) e] Y / |Y|, w = omega beta V_j; each
    pair once (``pairs``, ``width``: ``pair_offsets``), summed in ``grid_f`` (scratch, (3, n_grid))."""
    nx, ny, nz = shape[0], shape[1], shape[2]
    zero = u.dtype.type(0.0)
    n_slabs = (ny + width - 1) // width
    for colour in range(2):
        for h in numba.prange(_phase_tasks(colour, n_slabs)):
            z0, z1 = _to_clear(colour, h, width, ny)
            _clear_planes(grid_f, z0, z1, shape)
            buf = stack_array(LATTICE_BUFFER, u.dtype)
            y0, y1 = _slab(colour, h, width, ny)
            for iy in range(y0, y1):
                for iz in range(nz):
                    r = iz * ny + iy
                    base = r * nx
                    for k in pairs:
                        lo, hi, shift = _neighbour_row(r, ny, nz, nx, offs[k, 0], offs[k, 1], offs[k, 2])
                        bit = np.uint64(1) << np.uint64(k & 63)
                        bits = broken[k >> 6]
                        x0, x1, x2, L, wk = xi[k, 0], xi[k, 1], xi[k, 2], length[k], weight[k]
                        for c0 in range(lo, hi, CHUNK):
                            m = min(CHUNK, hi - c0)
                            i0 = base + c0
                            j0 = i0 + shift
                            vp = vol[i0 : i0 + m]
                            vq = vol[j0 : j0 + m]
                            _bond_terms(cf, u, i0, j0, m, x0, x1, x2, L, bits[i0 : i0 + m], bit, vp, vq, buf)
                            pi = p[i0 : i0 + m]
                            pj = p[j0 : j0 + m]
                            ai = alpha[i0 : i0 + m]
                            aj = alpha[j0 : j0 + m]
                            for q in range(m):
                                e = buf[5 * CHUNK + q]
                                t = (wk * L * (pi[q] + pj[q]) + wk * (ai[q] + aj[q]) * e) / buf[4 * CHUNK + q]
                                buf[q] = t if buf[q] > zero else zero
                            _add_pair_forces(grid_f, i0, j0, m, vp, vq, buf)
            w0, w1 = _finished(colour, h, width, ny)
            _write_planes(grid_f, w0, w1, shape, point_of, f)
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
