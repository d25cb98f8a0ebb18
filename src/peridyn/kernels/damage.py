"""Bond-breaking kernels: the stretch test and its skin, and the damage index."""

import numba
import numpy as np

from peridyn.kernels import FASTMATH, bond_differences, exact_helper

#: A bond's margin is taken as ``limit * MARGIN_SCALE - |Y|``: the 1e-9 relative slack covers
#: the roundings of |Y|, of the squared-length test and of the displacement norms (a few
#: 1e-16 relative), so that a margin never promises more room than the exact test allows.
MARGIN_SCALE = 1.0 - 1e-9


@exact_helper("{t}({t}, {t}, {t})")
def squared_length(y0, y1, y2):
    """``y0^2 + y1^2 + y2^2`` in this order, compiled without fast-math (``exact_helper``).

    Inlined into the fast-math kernels with its roundings kept as written (no fused
    multiply-add), so a bond's squared length is the same number in every kernel and in
    every call, and its two directed copies (``Y_ji = -Y_ij`` exactly, see
    :func:`~peridyn.kernels.bond_differences`) always get the same verdict.
    """
    return y0 * y0 + y1 * y1 + y2 * y2


#: Margins are counted in whole quanta (``quantum``, m) up to this many (< 2^31): an int32
#: minimum vectorises where a floating-point one does not. Larger margins are capped.
MAX_QUANTA = 2_000_000_000


@numba.njit(parallel=True, fastmath=FASTMATH, cache=True)
def stretch_test_families(x, u, offsets, nbr, limit, intact, points, tested, moved, quantum, margin):
    """Stretch test of the families of ``points``: break, and measure the room left.

    For each point i of ``points`` (int64; ``tested`` (n_points,) bool marks them), every
    intact bond (i, j) whose deformed length |Y| = |xi + u_j - u_i| exceeds ``limit`` (m,
    per bond; ``inf`` for a bond that may not break) is broken (``intact`` IN/OUT), and so
    is its reverse copy (j, i) when j is not tested itself (a tested j breaks it in its
    own family, so every directed bond is written by one thread only).

    ``margin[i]`` (OUT, m) gets the room left to i's family, taken back to the reference
    displacement that ``moved`` (n_points,), the distance each point moved since it, m,
    is measured from: the smallest ``limit * MARGIN_SCALE - |Y| - moved[j]`` over the
    bonds left intact, rounded down to whole ``quantum`` (at most ``MAX_QUANTA``, at
    least 0), minus ``moved[i]``. Returns the number of directed bonds broken.
    """
    count = np.zeros(points.shape[0], dtype=np.int64)
    for p in numba.prange(points.shape[0]):
        count[p] = _test_family(points[p], x, u, offsets, nbr, limit, intact, tested, moved, quantum, margin)
    return count.sum()


@numba.njit(fastmath=FASTMATH, cache=True)
def _test_family(i, x, u, offsets, nbr, limit, intact, tested, moved, quantum, margin):
    """:func:`stretch_test_families` for point ``i``; returns the number of bonds broken.

    A first loop, written to vectorise (see ``peridyn.kernels``), counts the failing intact
    bonds and the margin; the few families with a failure get a second, scalar loop.
    """
    n = x.shape[0]
    xf = x.reshape(3 * n)
    uf = u.reshape(3 * n)
    xi0, xi1, xi2 = xf[3 * i], xf[3 * i + 1], xf[3 * i + 2]
    ui0, ui1, ui2 = uf[3 * i], uf[3 * i + 1], uf[3 * i + 2]
    lo = offsets[i]
    hi = offsets[i + 1]
    fam = nbr[lo:hi]
    lim = limit[lo:hi]
    alive = intact[lo:hi]
    per_quantum = 1.0 / quantum
    none = np.int32(MAX_QUANTA)
    failed = np.int32(0)
    room = none
    for q in range(hi - lo):
        jj = np.uint64(np.uint32(fam[q]))
        j = 3 * jj
        _, _, y0 = bond_differences(xf[j], xi0, uf[j], ui0)
        _, _, y1 = bond_differences(xf[j + 1], xi1, uf[j + 1], ui1)
        _, _, y2 = bond_differences(xf[j + 2], xi2, uf[j + 2], ui2)
        r2 = squared_length(y0, y1, y2)
        hit = np.int32(1) if r2 > lim[q] * lim[q] else np.int32(0)
        failed += hit if alive[q] else np.int32(0)
        left = (lim[q] * MARGIN_SCALE - np.sqrt(r2) - moved[jj]) * per_quantum
        quanta = np.int32(min(max(left, 0.0), float(MAX_QUANTA)))
        room = min(room, quanta if alive[q] else none)
    broken = 0
    if failed:
        room = none
        for q in range(hi - lo):
            if not alive[q]:
                continue
            j = fam[q]
            _, _, y0 = bond_differences(xf[3 * j], xi0, uf[3 * j], ui0)
            _, _, y1 = bond_differences(xf[3 * j + 1], xi1, uf[3 * j + 1], ui1)
            _, _, y2 = bond_differences(xf[3 * j + 2], xi2, uf[3 * j + 2], ui2)
            r2 = squared_length(y0, y1, y2)
            if r2 > lim[q] * lim[q]:
                alive[q] = False
                broken += 1
                if not tested[j]:
                    broken += _break_reverse(i, j, offsets, nbr, intact)
            else:
                left = (lim[q] * MARGIN_SCALE - np.sqrt(r2) - moved[j]) * per_quantum
                room = min(room, np.int32(min(max(left, 0.0), float(MAX_QUANTA))))
    margin[i] = room * quantum - moved[i]
    return broken


@numba.njit(cache=True)
def _break_reverse(i, j, offsets, nbr, intact):
    """Break the bond (j, i) of j's family if intact; returns 1 if it did, else 0."""
    for r in range(offsets[j], offsets[j + 1]):
        if nbr[r] == i and intact[r]:
            intact[r] = False
            return 1
    return 0


@numba.njit(parallel=True, fastmath=FASTMATH, cache=True)
def flag_moved_points(u, u_ref, margin, moved, tested):
    """Which families the skin must test at ``u`` (see ``peridyn.physics.damage``).

    ``moved`` (OUT, (n_points,), m): ``|u_k - u_ref_k|``; ``tested`` (OUT, (n_points,) bool):
    ``margin[k] <= 2 moved[k]``. Returns the number of points tested, or -1 if some
    ``moved`` is not finite.
    """
    n = u.shape[0]
    count = 0
    bad = 0
    for k in numba.prange(n):
        d0 = u[k, 0] - u_ref[k, 0]
        d1 = u[k, 1] - u_ref[k, 1]
        d2 = u[k, 2] - u_ref[k, 2]
        d = np.sqrt(d0 * d0 + d1 * d1 + d2 * d2)
        moved[k] = d
        flag = margin[k] <= 2.0 * d
        tested[k] = flag
        count += 1 if flag else 0
        bad += 0 if np.isfinite(d) else 1
    return -1 if bad else count


@numba.njit(parallel=True, cache=True)
def damage_index(offsets, weight, intact, phi):
    """``phi`` (OUT): 1 - (intact weight) / (total weight) of each family."""
    n = offsets.shape[0] - 1
    for i in numba.prange(n):
        total = 0.0
        alive = 0.0
        for b in range(offsets[i], offsets[i + 1]):
            total += weight[b]
            if intact[b]:
                alive += weight[b]
        phi[i] = 1.0 - alive / total if total > 0 else 0.0
    return phi
