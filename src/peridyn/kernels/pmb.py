"""Bond-based prototype microelastic brittle (PMB) kernels.

Force density on point i (N/m^3):

    f_i = sum_j k_ij (1/|xi| - 1/|Y|) Y,     Y = xi + u_j - u_i,

which is c s Y/|Y| V_j with stretch s = |Y|/|xi| - 1, folded so that each
bond costs one square root and one division. ``k_ij = c omega beta V_j g``
(micromodulus, influence, volume factor, neighbour volume, surface factor).

``pmb_force`` (float64) and ``pmb_force_cf`` (float32) compute the same force; see
``peridyn.kernels`` for the two forms and what makes them fast. ``pmb_pair_force`` is the
float64 force from a half list (each bond pair once: about half the bytes streamed a bond),
in the row-block order of ``peridyn.discretization.pairs`` that ``pmb_force`` follows too.
``pmb_force_baseline`` is the straightforward loop kept as the reference row of ``peridyn bench``.
"""

import numba
import numpy as np

from peridyn.kernels import (
    CHUNK,
    CHUNK_BUFFER,
    FASTMATH,
    bond_differences,
    deformed_component,
    stack_array,
)


@numba.njit(fastmath=FASTMATH, cache=True, inline="always")
def _stretch_terms(uf, ui0, ui1, ui2, fam, xib, il, ok, buf):
    """The first loop of a chunk (``peridyn.kernels``): for each of its bonds q (``fam``, ``xib``,
    ``il``, ``ok``: the chunk's slices of the neighbours, flat bond vectors, ``1/|xi|`` and
    ``intact``), ``t = 1/|xi| - 1/|Y|`` (0 if broken) into ``buf[q]`` and ``Y`` into
    ``buf[CHUNK + q]``, ``buf[2 CHUNK + q]``, ``buf[3 CHUNK + q]``. No sum: it vectorises.
    Inlined in numba's IR into the calling kernel."""
    zero = buf.dtype.type(0.0)
    one = buf.dtype.type(1.0)
    for q in range(fam.shape[0]):
        j = 3 * np.uint64(np.uint32(fam[q]))
        y0 = deformed_component(xib[3 * q], uf[j], ui0)
        y1 = deformed_component(xib[3 * q + 1], uf[j + 1], ui1)
        y2 = deformed_component(xib[3 * q + 2], uf[j + 2], ui2)
        t = il[q] - one / np.sqrt(y0 * y0 + y1 * y1 + y2 * y2)
        buf[q] = t if ok[q] else zero
        buf[CHUNK + q] = y0
        buf[2 * CHUNK + q] = y1
        buf[3 * CHUNK + q] = y2


@numba.njit(fastmath=FASTMATH, cache=True, inline="always")
def _chain(xif, uf, ui0, ui1, ui2, nbr, inv_len, k, intact, lo, hi, buf):
    """Sums ``(f0, f1, f2)`` of the PMB terms ``k t Y`` of the bonds ``lo .. hi - 1`` of one
    family, added one after the other from zero (the two-loop chunks of ``peridyn.kernels``);
    ``buf``: the kernel's ``stack_array(CHUNK_BUFFER)``. Inlined in numba's IR into
    :func:`pmb_force`."""
    zero = buf.dtype.type(0.0)
    f0 = zero
    f1 = zero
    f2 = zero
    for c in range(lo, hi, CHUNK):
        m = min(CHUNK, hi - c)
        fam, xib, il, ok = nbr[c : c + m], xif[3 * c : 3 * (c + m)], inv_len[c : c + m], intact[c : c + m]
        _stretch_terms(uf, ui0, ui1, ui2, fam, xib, il, ok, buf)
        kb = k[c : c + m]
        for q in range(m):
            s = kb[q] * buf[q]
            f0 += s * buf[CHUNK + q]
            f1 += s * buf[2 * CHUNK + q]
            f2 += s * buf[3 * CHUNK + q]
    return f0, f1, f2


@numba.njit(parallel=True, fastmath=FASTMATH, cache=True)
def pmb_force(xi, u, offsets, nbr, inv_len, k, intact, f, first=0, stop=-1, split=None):
    """Internal force density ``f`` (OUT: the rows ``first .. stop - 1``, see ``peridyn.kernels``)
    of the PMB model ("length form").

    ``s = k (1/|xi| - 1/|Y|)`` with the stored ``inv_len = 1/|xi|`` and bond vectors ``xi``
    (n_bonds, 3), m (``bond_search.initial_bond_vectors``): one square root and one division
    per bond, and only ``u_j`` gathered. Used for float64 (see the package docstring).

    ``split`` (n_points,) int64: row i's family is summed in two chains, each in the written
    order from zero, ``h`` over its bonds ``offsets[i] .. split[i] - 1`` and ``g`` over the
    rest, and ``f_i = h + g``: the block order of ``peridyn.discretization.pairs``, which the
    half-list kernel :func:`pmb_pair_force` follows to the bit. None: ``f_i = 0 + g`` over the
    whole family.
    """
    n = u.shape[0]
    zero = f.dtype.type(0.0)
    uf = u.reshape(3 * n)
    xif = xi.reshape(3 * xi.shape[0])
    end = n if stop < 0 else stop
    for i in numba.prange(first, end):
        ui0, ui1, ui2 = uf[3 * i], uf[3 * i + 1], uf[3 * i + 2]
        buf = stack_array(CHUNK_BUFFER, f.dtype)
        lo = offsets[i]
        mid = lo
        if split is not None:
            mid = split[i]
        h0, h1, h2 = zero, zero, zero
        if mid > lo:
            h0, h1, h2 = _chain(xif, uf, ui0, ui1, ui2, nbr, inv_len, k, intact, lo, mid, buf)
        g0, g1, g2 = _chain(xif, uf, ui0, ui1, ui2, nbr, inv_len, k, intact, mid, offsets[i + 1], buf)
        f[i, 0] = h0 + g0
        f[i, 1] = h1 + g1
        f[i, 2] = h2 + g2
    return f


@numba.njit(parallel=True, fastmath=FASTMATH, cache=True)
def pmb_pair_force(xi, u, offsets, nbr, inv_len, k, k_rev, intact, intact_at, blocks, phase, f, h):
    """One phase of the half-list PMB force (float64): each bond pair (i, j), j > i, computed
    once at row i, its reverse term added to row j. ``peridyn.physics.materials.pmb`` calls it
    with ``phase`` 0 then 1; after both, ``f`` (OUT, (n_points, 3)) holds the force of
    :func:`pmb_force` with ``split = pairs.block_split(...)``, bit for bit.

    The arrays of ``peridyn.discretization.pairs.HalfList``: ``offsets`` (n_points + 1,),
    ``nbr`` (n_pairs,) int32 (j > i, ascending), ``xi`` (n_pairs, 3) m, ``inv_len``, ``k``,
    ``k_rev`` (n_pairs,) (the stiffness of i -> j and of j -> i); ``intact`` (n_bonds,) bool is
    the full list's (a bond breaks in both directions together), ``intact_at`` (n_points,)
    int64 the full-list index of row i's first pair. ``blocks`` (n_blocks + 1,): row bounds,
    each block at least the index bandwidth; ``h`` (n_points, 3): scratch.

    The blocks ``phase``, ``phase + 2``, ... run in parallel, each on one thread, rows in
    order (a block's pairs reach into its own rows and the next block's only, so two blocks
    of a phase share no row). A pair's term for row j goes to ``f`` if j is in the pair's
    block (the ``g`` chain of row j, which row j then continues with its own pairs) and to
    ``h`` if j is in the next block (row j's ``h`` chain). Each term is rounded as in
    :func:`pmb_force`: ``Y_ji = -Y_ij`` exactly, the same ``|Y|`` and ``1/|xi|``, and the fused
    ``acc - r Y_ji`` rounds as ``acc + r Y_ij``. A row adds ``h + g`` once both are complete:
    its own block does for the odd blocks (phase 1) and block 0 (``h = 0``); the block before
    does for the other even blocks, at the end of phase 1 (``h + g`` and ``g + h`` are the
    same bits).
    """
    n = u.shape[0]
    zero = f.dtype.type(0.0)
    uf = u.reshape(3 * n)
    xif = xi.reshape(3 * xi.shape[0])
    ff = f.reshape(3 * n)
    hf = h.reshape(3 * n)
    n_blocks = blocks.shape[0] - 1
    for p in numba.prange((n_blocks - phase + 1) // 2):
        block = 2 * p + phase
        start = blocks[block]
        end = blocks[block + 1]
        after = blocks[min(block + 2, n_blocks)]
        ff[3 * start : 3 * end] = zero
        hf[3 * end : 3 * after] = zero
        with_h = phase == 1
        buf = stack_array(CHUNK_BUFFER, f.dtype)
        for i in range(start, end):
            ui0, ui1, ui2 = uf[3 * i], uf[3 * i + 1], uf[3 * i + 2]
            hi = offsets[i + 1]
            f0 = ff[3 * i]
            f1 = ff[3 * i + 1]
            f2 = ff[3 * i + 2]
            for c in range(offsets[i], hi, CHUNK):
                m = min(CHUNK, hi - c)
                fam = nbr[c : c + m]
                at = intact_at[i] + c - offsets[i]
                xib, il, ok = xif[3 * c : 3 * (c + m)], inv_len[c : c + m], intact[at : at + m]
                _stretch_terms(uf, ui0, ui1, ui2, fam, xib, il, ok, buf)
                kb = k[c : c + m]
                kr = k_rev[c : c + m]
                for q in range(m):
                    t = buf[q]
                    s = kb[q] * t
                    r = kr[q] * t
                    y0 = buf[CHUNK + q]
                    y1 = buf[2 * CHUNK + q]
                    y2 = buf[3 * CHUNK + q]
                    f0 += s * y0
                    f1 += s * y1
                    f2 += s * y2
                    jr = np.uint64(np.uint32(fam[q]))
                    acc = ff if jr < end else hf
                    j = 3 * jr
                    acc[j] -= r * y0
                    acc[j + 1] -= r * y1
                    acc[j + 2] -= r * y2
            if with_h:
                f0 = hf[3 * i] + f0
                f1 = hf[3 * i + 1] + f1
                f2 = hf[3 * i + 2] + f2
            elif block == 0:
                f0 = zero + f0
                f1 = zero + f1
                f2 = zero + f2
            ff[3 * i] = f0
            ff[3 * i + 1] = f1
            ff[3 * i + 2] = f2
        if with_h:
            for a in range(3 * end, 3 * after):
                ff[a] = hf[a] + ff[a]
    return f


@numba.njit(parallel=True, fastmath=FASTMATH, cache=True)
def pmb_force_cf(x, u, offsets, nbr, k, intact, f, first=0, stop=-1):
    """PMB force density ``f`` (OUT), cancellation-free form (used for float32).

    Same force as :func:`pmb_force`, written
    ``s = k (|Y|^2 - |xi|^2) / (|Y| |xi| (|Y| + |xi|))`` with
    ``|Y|^2 - |xi|^2 = du . (Y + xi)`` and ``|xi|`` recomputed from ``x``: no per-bond
    length is read and the stretch keeps full relative precision however small it is.
    """
    n = x.shape[0]
    zero = f.dtype.type(0.0)
    xf = x.reshape(3 * n)
    uf = u.reshape(3 * n)
    end = n if stop < 0 else stop
    for i in numba.prange(first, end):
        xi0, xi1, xi2 = xf[3 * i], xf[3 * i + 1], xf[3 * i + 2]
        ui0, ui1, ui2 = uf[3 * i], uf[3 * i + 1], uf[3 * i + 2]
        buf = stack_array(CHUNK_BUFFER, f.dtype)
        hi = offsets[i + 1]
        f0 = zero
        f1 = zero
        f2 = zero
        for c in range(offsets[i], hi, CHUNK):
            m = min(CHUNK, hi - c)
            fam = nbr[c : c + m]
            kb = k[c : c + m]
            ok = intact[c : c + m]
            for q in range(m):
                j = 3 * np.uint64(np.uint32(fam[q]))
                d0, e0, y0 = bond_differences(xf[j], xi0, uf[j], ui0)
                d1, e1, y1 = bond_differences(xf[j + 1], xi1, uf[j + 1], ui1)
                d2, e2, y2 = bond_differences(xf[j + 2], xi2, uf[j + 2], ui2)
                r = np.sqrt(y0 * y0 + y1 * y1 + y2 * y2)
                length = np.sqrt(d0 * d0 + d1 * d1 + d2 * d2)
                ext2 = e0 * (y0 + d0) + e1 * (y1 + d1) + e2 * (y2 + d2)
                s = kb[q] * ext2 / (r * length * (r + length))
                buf[q] = s if ok[q] else zero
                buf[CHUNK + q] = y0
                buf[2 * CHUNK + q] = y1
                buf[3 * CHUNK + q] = y2
            for q in range(m):
                s = buf[q]
                f0 += s * buf[CHUNK + q]
                f1 += s * buf[2 * CHUNK + q]
                f2 += s * buf[3 * CHUNK + q]
        f[i, 0] = f0
        f[i, 1] = f1
        f[i, 2] = f2
    return f


@numba.njit(parallel=True, cache=True)
def pmb_energy(x, u, offsets, nbr, length, k, intact, w):
    """Strain energy density ``w`` (OUT, J/m^3): W_i = sum_j k_ij s^2 |xi| / 4."""
    n = x.shape[0]
    for i in numba.prange(n):
        acc = 0.0
        for b in range(offsets[i], offsets[i + 1]):
            if not intact[b]:
                continue
            j = nbr[b]
            r2 = 0.0
            for a in range(3):
                d = (x[j, a] - x[i, a]) + (u[j, a] - u[i, a])
                r2 += d * d
            s = np.sqrt(r2) / length[b] - 1.0
            acc += k[b] * s * s * length[b]
        w[i] = 0.25 * acc
    return w


@numba.njit(parallel=True, cache=True)
def pmb_force_baseline(x, u, offsets, nbr, length, c, intact, f):
    """The straightforward PMB loop kept as the benchmark baseline (not used by solvers).

    Reads a stored reference length per bond, computes the stretch with a divide,
    and the unit vector with another divide.
    """
    n = x.shape[0]
    for i in numba.prange(n):
        for a in range(3):
            f[i, a] = 0.0
        for b in range(offsets[i], offsets[i + 1]):
            if not intact[b]:
                continue
            j = nbr[b]
            y0 = x[j, 0] + u[j, 0] - x[i, 0] - u[i, 0]
            y1 = x[j, 1] + u[j, 1] - x[i, 1] - u[i, 1]
            y2 = x[j, 2] + u[j, 2] - x[i, 2] - u[i, 2]
            r = np.sqrt(y0 * y0 + y1 * y1 + y2 * y2)
            s = (r - length[b]) / length[b]
            t = c[b] * s / r
            f[i, 0] += t * y0
            f[i, 1] += t * y1
            f[i, 2] += t * y2
    return f
