"""Linear peridynamic solid (LPS, Silling et al. 2007) kernels, in d = 2 or 3 dimensions.

Per point: weighted volume m_i = sum_j w_ij |xi|^2 with w_ij = omega beta V_j,
dilatation theta_i = (d / m_i) sum_j w_ij |xi| e_ij, extension e = |Y| - |xi|.
Scalar force state t_ij = |xi| omega P_i + alpha_i g_ij omega e_ij, with the per-point
P_i = theta_i p_coef_i (``peridyn.physics.materials.lps``: p_coef = d kappa / m - alpha / d without
surface correction) and g_ij the point's deviatoric factor (1 without correction).
The pair force on i is (t_ij + t_ji) Y/|Y| beta V_j, which the kernel writes as

    sum_j [ w_ij |xi| (P_i + P_j) + k_ij e_ij ] Y / |Y|,   k_ij = w_ij (alpha_i g_ij + alpha_j g_ji),

with the per-bond deviatoric stiffness ``dev`` = k_ij.

The force takes two passes over the bonds (the pair force needs the neighbours'
dilatations). ``lps_dilatation`` / ``lps_pair_force`` (float64, from the stored bond vectors
``xi``) and the ``*_cf``
versions (float32) compute the same quantities; see ``peridyn.kernels`` for the two
forms of the extension. ``lps_force_fused`` (float64) gives the same bits as the two float64
passes in one go, row block by row block (see there); the per-point work of all three is
the row functions ``lps_dilatation_sum`` and ``lps_pair_force_row``, and their ``*_kept`` forms.
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
def lps_dilatation_sum(i, xif, uf, offsets, nbr, length, w, intact):
    """sum_j w_ij |xi| e_ij over the family of point ``i`` (m^5), the row of :func:`lps_dilatation`.

    ``xif`` (3 n_bonds,) and ``uf`` (3 n,): the flat bond vectors and displacements, m.
    Inlined in numba's IR (``inline="always"``): compiled inside each calling kernel, with
    its flags and its vectorisation (as a separate function it did not vectorise).
    """
    zero = uf.dtype.type(0.0)
    ui0, ui1, ui2 = uf[3 * i], uf[3 * i + 1], uf[3 * i + 2]
    buf = stack_array(CHUNK_BUFFER, uf.dtype)
    hi = offsets[i + 1]
    acc = zero
    for c in range(offsets[i], hi, CHUNK):
        m = min(CHUNK, hi - c)
        fam = nbr[c : c + m]
        xib = xif[3 * c : 3 * (c + m)]
        lb = length[c : c + m]
        wb = w[c : c + m]
        ok = intact[c : c + m]
        for q in range(m):
            j = 3 * np.uint64(np.uint32(fam[q]))
            y0 = deformed_component(xib[3 * q], uf[j], ui0)
            y1 = deformed_component(xib[3 * q + 1], uf[j + 1], ui1)
            y2 = deformed_component(xib[3 * q + 2], uf[j + 2], ui2)
            r = np.sqrt(y0 * y0 + y1 * y1 + y2 * y2)
            t = wb[q] * lb[q] * (r - lb[q])
            buf[q] = t if ok[q] else zero
        for q in range(m):
            acc += buf[q]
    return acc


@numba.njit(fastmath=FASTMATH, cache=True, inline="always")
def lps_pair_force_row(i, xif, uf, offsets, nbr, length, w, dev, intact, p, f):
    """``f[i]`` (OUT, N/m^3) from the per-point ``p`` (n,), the row of :func:`lps_pair_force`
    (arguments as :func:`lps_dilatation_sum`)."""
    zero = f.dtype.type(0.0)
    ui0, ui1, ui2 = uf[3 * i], uf[3 * i + 1], uf[3 * i + 2]
    buf = stack_array(CHUNK_BUFFER, f.dtype)
    hi = offsets[i + 1]
    pi = p[i]
    f0 = zero
    f1 = zero
    f2 = zero
    for c in range(offsets[i], hi, CHUNK):
        m = min(CHUNK, hi - c)
        fam = nbr[c : c + m]
        xib = xif[3 * c : 3 * (c + m)]
        lb = length[c : c + m]
        wb = w[c : c + m]
        kb = dev[c : c + m]
        ok = intact[c : c + m]
        for q in range(m):
            jp = np.uint32(fam[q])
            j = 3 * np.uint64(jp)
            y0 = deformed_component(xib[3 * q], uf[j], ui0)
            y1 = deformed_component(xib[3 * q + 1], uf[j + 1], ui1)
            y2 = deformed_component(xib[3 * q + 2], uf[j + 2], ui2)
            r = np.sqrt(y0 * y0 + y1 * y1 + y2 * y2)
            L = lb[q]
            t = (wb[q] * L * (pi + p[jp]) + kb[q] * (r - L)) / r
            buf[q] = t if ok[q] else zero
            buf[CHUNK + q] = y0
            buf[2 * CHUNK + q] = y1
            buf[3 * CHUNK + q] = y2
        for q in range(m):
            t = buf[q]
            f0 += t * buf[CHUNK + q]
            f1 += t * buf[2 * CHUNK + q]
            f2 += t * buf[3 * CHUNK + q]
    f[i, 0] = f0
    f[i, 1] = f1
    f[i, 2] = f2


@numba.njit(parallel=True, fastmath=FASTMATH, cache=True)
def lps_dilatation(xi, u, offsets, nbr, length, w, intact, theta_coef, theta, first=0, stop=-1):
    """Dilatation ``theta`` (OUT): theta_i = theta_coef_i sum_j w_ij |xi| e_ij, coef = d / m_i.

    Length form, e = |Y| - |xi| with the stored ``length`` and bond vectors ``xi`` (n_bonds,
    3), m (float64; see ``peridyn.kernels``).
    """
    n = u.shape[0]
    uf = u.reshape(3 * n)
    xif = xi.reshape(3 * xi.shape[0])
    end = n if stop < 0 else stop
    for i in numba.prange(first, end):
        theta[i] = theta_coef[i] * lps_dilatation_sum(i, xif, uf, offsets, nbr, length, w, intact)
    return theta


@numba.njit(parallel=True, fastmath=FASTMATH, cache=True)
def lps_pair_force(xi, u, offsets, nbr, length, w, dev, intact, p, f, first=0, stop=-1):
    """Force density ``f`` (OUT) from the per-point ``p`` = P_i and per-bond ``dev`` (see module).

    Length form (float64), from the stored bond vectors ``xi`` (n_bonds, 3), m.
    """
    n = u.shape[0]
    uf = u.reshape(3 * n)
    xif = xi.reshape(3 * xi.shape[0])
    end = n if stop < 0 else stop
    for i in numba.prange(first, end):
        lps_pair_force_row(i, xif, uf, offsets, nbr, length, w, dev, intact, p, f)
    return f


@numba.njit(fastmath=FASTMATH, cache=True, inline="always")
def lps_dilatation_sum_kept(i, xif, uf, offsets, nbr, length, w, intact, ring, s):
    """:func:`lps_dilatation_sum` that also writes each bond's deformed vector Y (m) and |Y| to
    ``ring`` (4, columns): bond ``offsets[i] + k`` of the family at column ``s + k``."""
    zero = uf.dtype.type(0.0)
    ui0, ui1, ui2 = uf[3 * i], uf[3 * i + 1], uf[3 * i + 2]
    buf = stack_array(CHUNK_BUFFER, uf.dtype)
    lo = offsets[i]
    hi = offsets[i + 1]
    acc = zero
    for c in range(lo, hi, CHUNK):
        m = min(CHUNK, hi - c)
        fam = nbr[c : c + m]
        xib = xif[3 * c : 3 * (c + m)]
        lb = length[c : c + m]
        wb = w[c : c + m]
        ok = intact[c : c + m]
        k0 = s + (c - lo)
        ry0 = ring[0, k0 : k0 + m]
        ry1 = ring[1, k0 : k0 + m]
        ry2 = ring[2, k0 : k0 + m]
        rr = ring[3, k0 : k0 + m]
        for q in range(m):
            j = 3 * np.uint64(np.uint32(fam[q]))
            y0 = deformed_component(xib[3 * q], uf[j], ui0)
            y1 = deformed_component(xib[3 * q + 1], uf[j + 1], ui1)
            y2 = deformed_component(xib[3 * q + 2], uf[j + 2], ui2)
            r = np.sqrt(y0 * y0 + y1 * y1 + y2 * y2)
            ry0[q] = y0
            ry1[q] = y1
            ry2[q] = y2
            rr[q] = r
            t = wb[q] * lb[q] * (r - lb[q])
            buf[q] = t if ok[q] else zero
        for q in range(m):
            acc += buf[q]
    return acc


@numba.njit(fastmath=FASTMATH, cache=True, inline="always")
def lps_pair_force_row_kept(i, offsets, nbr, length, w, dev, intact, p, ring, s, f):
    """:func:`lps_pair_force_row` from the Y and |Y| that :func:`lps_dilatation_sum_kept` wrote
    at column ``s`` of ``ring``: no gather of ``u`` and no square root, the same values."""
    zero = f.dtype.type(0.0)
    buf = stack_array(CHUNK_BUFFER, f.dtype)
    lo = offsets[i]
    hi = offsets[i + 1]
    pi = p[i]
    f0 = zero
    f1 = zero
    f2 = zero
    for c in range(lo, hi, CHUNK):
        m = min(CHUNK, hi - c)
        fam = nbr[c : c + m]
        lb = length[c : c + m]
        wb = w[c : c + m]
        kb = dev[c : c + m]
        ok = intact[c : c + m]
        k0 = s + (c - lo)
        ry0 = ring[0, k0 : k0 + m]
        ry1 = ring[1, k0 : k0 + m]
        ry2 = ring[2, k0 : k0 + m]
        rr = ring[3, k0 : k0 + m]
        for q in range(m):
            r = rr[q]
            L = lb[q]
            t = (wb[q] * L * (pi + p[np.uint32(fam[q])]) + kb[q] * (r - L)) / r
            buf[q] = t if ok[q] else zero
        for q in range(m):
            t = buf[q]
            f0 += t * ry0[q]
            f1 += t * ry1[q]
            f2 += t * ry2[q]
    f[i, 0] = f0
    f[i, 1] = f1
    f[i, 2] = f2


@numba.njit(fastmath=FASTMATH, cache=True)
def lps_dilatation_rows(lo, hi, xif, uf, offsets, nbr, length, w, intact, theta_coef, p_coef, theta, p):
    """``theta`` and ``p`` = theta p_coef (OUT, (n,)) of the rows ``lo .. hi - 1``, in order."""
    for i in range(lo, hi):
        th = theta_coef[i] * lps_dilatation_sum(i, xif, uf, offsets, nbr, length, w, intact)
        theta[i] = th
        p[i] = th * p_coef[i]


@numba.njit(fastmath=FASTMATH, cache=True)
def ring_slot(pos, count, size):
    """Column of a family of ``count`` bonds in a ring of ``size`` columns whose next free one is
    ``pos``: ``pos``, or 0 when the family would not fit before the end (families are not split)."""
    return 0 if pos + count > size else pos


@numba.njit(parallel={"fusion": False}, fastmath=FASTMATH, cache=True)
def lps_force_fused(
    xi,
    u,
    offsets,
    nbr,
    length,
    w,
    dev,
    intact,
    theta_coef,
    p_coef,
    parts,
    inner,
    blocks,
    need,
    ring,
    theta,
    p,
    f,
):
    """LPS force ``f`` (OUT, (n, 3)), dilatation ``theta`` and ``p`` (OUT, (n,)) in one go: the same
    bits as :func:`lps_dilatation`, ``theta * p_coef`` and :func:`lps_pair_force` (float64).

    Plan (``peridyn.discretization.bonds.fused_plan``): one thread a part (a range of rows).
    First parallel loop: the dilatation of each part's outer rows (outside its inner rows
    ``inner[t]``: the rows of other parts may read them). Second: each part's force, block of
    rows by block; before a block, the dilatation of the inner rows up to ``need`` (all its
    rows read), each bond's Y and |Y| written to the part's ``ring`` ((n_parts, 4, columns))
    and read back by the force of the row (no second gather of ``u``, no second square
    root), while the row's per-bond data is still in the cache if the window (about index
    bandwidth + block rows) fits there. The outer rows' force recomputes Y and |Y|.
    """
    n = u.shape[0]
    uf = u.reshape(3 * n)
    xif = xi.reshape(3 * xi.shape[0])
    args = (offsets, nbr, length, w, intact, theta_coef, p_coef, theta, p)
    for t in numba.prange(parts.shape[0]):
        lps_dilatation_rows(parts[t, 0], inner[t, 0], xif, uf, *args)
        lps_dilatation_rows(inner[t, 1], parts[t, 1], xif, uf, *args)
    for t in numba.prange(parts.shape[0]):
        inner_lo, inner_hi = inner[t, 0], inner[t, 1]
        rg = ring[t]
        size = rg.shape[1]
        done = inner_lo
        put = 0
        take = 0
        for k in range(parts[t, 2], parts[t, 3]):
            while done < min(need[k], inner_hi):
                count = offsets[done + 1] - offsets[done]
                put = ring_slot(put, count, size)
                acc = lps_dilatation_sum_kept(done, xif, uf, offsets, nbr, length, w, intact, rg, put)
                th = theta_coef[done] * acc
                theta[done] = th
                p[done] = th * p_coef[done]
                put += count
                done += 1
            for i in range(blocks[k], blocks[k + 1]):
                if inner_lo <= i < inner_hi:
                    count = offsets[i + 1] - offsets[i]
                    take = ring_slot(take, count, size)
                    lps_pair_force_row_kept(i, offsets, nbr, length, w, dev, intact, p, rg, take, f)
                    take += count
                else:
                    lps_pair_force_row(i, xif, uf, offsets, nbr, length, w, dev, intact, p, f)
    return f


@numba.njit(parallel=True, fastmath=FASTMATH, cache=True)
def lps_dilatation_cf(x, u, offsets, nbr, w, intact, theta_coef, theta, first=0, stop=-1):
    """:func:`lps_dilatation` in the cancellation-free form (float32).

    ``|xi|`` is recomputed from ``x`` and e = du . (Y + xi) / (|Y| + |xi|); no per-bond
    length is read.
    """
    n = x.shape[0]
    zero = theta.dtype.type(0.0)
    xf = x.reshape(3 * n)
    uf = u.reshape(3 * n)
    end = n if stop < 0 else stop
    for i in numba.prange(first, end):
        xi0, xi1, xi2 = xf[3 * i], xf[3 * i + 1], xf[3 * i + 2]
        ui0, ui1, ui2 = uf[3 * i], uf[3 * i + 1], uf[3 * i + 2]
        buf = stack_array(CHUNK_BUFFER, theta.dtype)
        hi = offsets[i + 1]
        acc = zero
        for c in range(offsets[i], hi, CHUNK):
            m = min(CHUNK, hi - c)
            fam = nbr[c : c + m]
            wb = w[c : c + m]
            ok = intact[c : c + m]
            for q in range(m):
                j = 3 * np.uint64(np.uint32(fam[q]))
                d0, e0, y0 = bond_differences(xf[j], xi0, uf[j], ui0)
                d1, e1, y1 = bond_differences(xf[j + 1], xi1, uf[j + 1], ui1)
                d2, e2, y2 = bond_differences(xf[j + 2], xi2, uf[j + 2], ui2)
                r = np.sqrt(y0 * y0 + y1 * y1 + y2 * y2)
                L = np.sqrt(d0 * d0 + d1 * d1 + d2 * d2)
                ext2 = e0 * (y0 + d0) + e1 * (y1 + d1) + e2 * (y2 + d2)
                t = wb[q] * L * ext2 / (r + L)
                buf[q] = t if ok[q] else zero
            for q in range(m):
                acc += buf[q]
        theta[i] = theta_coef[i] * acc
    return theta


@numba.njit(parallel=True, fastmath=FASTMATH, cache=True)
def lps_pair_force_cf(x, u, offsets, nbr, w, dev, intact, p, f, first=0, stop=-1):
    """:func:`lps_pair_force` in the cancellation-free form (float32), one division per bond:

    t = [ w |xi| (|Y| + |xi|) (P_i + P_j) + dev du . (Y + xi) ] / (|Y| (|Y| + |xi|)).

    Still one loop per family, not in chunks (see ``peridyn.kernels``): in chunks its
    float32 results moved by up to 3e-8 of the largest force (the scalar loop's reciprocal
    square root estimate rounds unlike the vectorised one's); kept until that is decided.
    """
    n = x.shape[0]
    zero = f.dtype.type(0.0)
    xf = x.reshape(3 * n)
    uf = u.reshape(3 * n)
    end = n if stop < 0 else stop
    for i in numba.prange(first, end):
        xi0, xi1, xi2 = xf[3 * i], xf[3 * i + 1], xf[3 * i + 2]
        ui0, ui1, ui2 = uf[3 * i], uf[3 * i + 1], uf[3 * i + 2]
        lo = offsets[i]
        hi = offsets[i + 1]
        fam = nbr[lo:hi]
        wb = w[lo:hi]
        kb = dev[lo:hi]
        ok = intact[lo:hi]
        pi = p[i]
        f0 = zero
        f1 = zero
        f2 = zero
        for q in range(hi - lo):
            jp = np.uint32(fam[q])
            j = 3 * np.uint64(jp)
            d0, e0, y0 = bond_differences(xf[j], xi0, uf[j], ui0)
            d1, e1, y1 = bond_differences(xf[j + 1], xi1, uf[j + 1], ui1)
            d2, e2, y2 = bond_differences(xf[j + 2], xi2, uf[j + 2], ui2)
            r = np.sqrt(y0 * y0 + y1 * y1 + y2 * y2)
            L = np.sqrt(d0 * d0 + d1 * d1 + d2 * d2)
            ext2 = e0 * (y0 + d0) + e1 * (y1 + d1) + e2 * (y2 + d2)
            rl = r + L
            t = (wb[q] * L * rl * (pi + p[jp]) + kb[q] * ext2) / (r * rl)
            t = t if ok[q] else zero
            f0 += t * y0
            f1 += t * y1
            f2 += t * y2
        f[i, 0] = f0
        f[i, 1] = f1
        f[i, 2] = f2
    return f


@numba.njit(parallel=True, cache=True)
def lps_deviatoric_energy(x, u, offsets, nbr, length, w, intact, theta, dim, out):
    """``out`` (OUT): sum_j w_ij (e_ij - theta_i |xi| / d)^2 per point (m^5)."""
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
            ed = np.sqrt(r2) - length[b] - theta[i] * length[b] / dim
            acc += w[b] * ed * ed
        out[i] = acc
    return out


@numba.njit(parallel=True, cache=True)
def lps_stiffness_bound(offsets, nbr, intact, w, length, dev, bulk, theta_coef, s, out):
    """``out`` (OUT, (n_points,), N/m^5): the block-Gershgorin bound of the LPS stiffness
    (``LPSModel.stiffness_bound``), with ``s`` (OUT, (n_points,)) = ``theta_coef`` x the
    family sum of ``w |xi|`` over intact bonds. ``w`` (n_bonds,) influence x bond volume,
    ``dev`` the deviatoric bond coefficient, ``bulk`` and ``theta_coef`` (n_points,); all
    float64. Each sum is taken in its family's bond order, every product in the order of the
    NumPy form (``reference.lps.lps_stiffness_bound``): the same bits."""
    n = len(out)
    for i in numba.prange(n):
        total = 0.0
        for b in range(offsets[i], offsets[i + 1]):
            total += (w[b] if intact[b] else 0.0) * length[b]
        s[i] = theta_coef[i] * total
    for i in numba.prange(n):
        total = 0.0
        for b in range(offsets[i], offsets[i + 1]):
            j = nbr[b]
            wb = w[b] if intact[b] else 0.0
            pair = 2.0 * (np.float64(dev[b]) if intact[b] else 0.0)
            total += pair + 2.0 * bulk[j] * theta_coef[j] * wb * length[b] * s[j]
        out[i] = total + 2.0 * bulk[i] * (s[i] * s[i])
    return out
