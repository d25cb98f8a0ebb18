"""Issue 22 item 1: the float64 force kernels reading stored bond vectors, against the same
chunked kernels gathering the neighbours' positions (as they were up to 3c37f49), A/B interleaved.

"before": ``*_gather_x`` below (chunks of 16, two loops, ``x_j`` and ``u_j`` gathered: six
gathers a bond); "today": ``peridyn.kernels`` (the same loops reading ``xi = x_j - x_i`` from a
stored (n_bonds, 3) array: three gathers a bond, 24 B more streamed). Also measured, and not
taken: PMB with the chunk's sums in 16 lanes (a vector accumulator per component, summed by a
fixed tree at the end of the family): faster on its own, but it changes the order of each
point's sum, hence the last bits. Each pair is timed by ``kernel_candidates.compare``
(interleaved calls on the same inputs: the before / candidate ratio of the best wall and CPU
times and the median of the rounds' ratios, and the largest force difference). Results in
HISTORY.md, "Stored bond vectors, the fused LPS force, ..." (2026-11-28).

    PYTHONPATH=src python benchmarks/kernel_bond_vectors.py --side 49 --rounds 10
"""

from __future__ import annotations

import argparse
import os

import numba
import numpy as np
from kernel_candidates import compare

from peridyn.jobs.bench import DEFAULT_POINTS_PER_SIDE, SPACING, benchmark_grid
from peridyn.kernels import CHUNK, CHUNK_BUFFER, FASTMATH, bond_differences, deformed_component, stack_array
from peridyn.kernels.lps import lps_dilatation, lps_pair_force
from peridyn.kernels.pmb import pmb_force
from peridyn.physics.materials import make_model

E, NU, DENSITY = 200e9, 0.25, 7850.0

#: Lanes of the lane-sum candidate (one vector accumulator per force component).
LANES = 16
LANES3 = 3 * 16


@numba.njit(parallel=True, fastmath=FASTMATH, cache=True)
def pmb_force_gather_x(x, u, offsets, nbr, inv_len, k, intact, f):
    """``pmb_force`` as it was before the stored bond vectors: ``x_j`` gathered in the loop."""
    n = x.shape[0]
    zero = f.dtype.type(0.0)
    one = f.dtype.type(1.0)
    xf = x.reshape(3 * n)
    uf = u.reshape(3 * n)
    for i in numba.prange(n):
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
            il = inv_len[c : c + m]
            kb = k[c : c + m]
            ok = intact[c : c + m]
            for q in range(m):
                j = 3 * np.uint64(np.uint32(fam[q]))
                _, _, y0 = bond_differences(xf[j], xi0, uf[j], ui0)
                _, _, y1 = bond_differences(xf[j + 1], xi1, uf[j + 1], ui1)
                _, _, y2 = bond_differences(xf[j + 2], xi2, uf[j + 2], ui2)
                s = kb[q] * (il[q] - one / np.sqrt(y0 * y0 + y1 * y1 + y2 * y2))
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


@numba.njit(parallel=True, fastmath=FASTMATH, cache=True)
def lps_dilatation_gather_x(x, u, offsets, nbr, length, w, intact, theta_coef, theta):
    """``lps_dilatation`` before the stored bond vectors: ``x_j`` gathered in the loop."""
    n = x.shape[0]
    zero = theta.dtype.type(0.0)
    xf = x.reshape(3 * n)
    uf = u.reshape(3 * n)
    for i in numba.prange(n):
        xi0, xi1, xi2 = xf[3 * i], xf[3 * i + 1], xf[3 * i + 2]
        ui0, ui1, ui2 = uf[3 * i], uf[3 * i + 1], uf[3 * i + 2]
        buf = stack_array(CHUNK_BUFFER, theta.dtype)
        hi = offsets[i + 1]
        acc = zero
        for c in range(offsets[i], hi, CHUNK):
            m = min(CHUNK, hi - c)
            fam = nbr[c : c + m]
            lb = length[c : c + m]
            wb = w[c : c + m]
            ok = intact[c : c + m]
            for q in range(m):
                j = 3 * np.uint64(np.uint32(fam[q]))
                _, _, y0 = bond_differences(xf[j], xi0, uf[j], ui0)
                _, _, y1 = bond_differences(xf[j + 1], xi1, uf[j + 1], ui1)
                _, _, y2 = bond_differences(xf[j + 2], xi2, uf[j + 2], ui2)
                r = np.sqrt(y0 * y0 + y1 * y1 + y2 * y2)
                t = wb[q] * lb[q] * (r - lb[q])
                buf[q] = t if ok[q] else zero
            for q in range(m):
                acc += buf[q]
        theta[i] = theta_coef[i] * acc
    return theta


@numba.njit(parallel=True, fastmath=FASTMATH, cache=True)
def lps_pair_force_gather_x(x, u, offsets, nbr, length, w, dev, intact, p, f):
    """``lps_pair_force`` before the stored bond vectors: ``x_j`` gathered in the loop."""
    n = x.shape[0]
    zero = f.dtype.type(0.0)
    xf = x.reshape(3 * n)
    uf = u.reshape(3 * n)
    for i in numba.prange(n):
        xi0, xi1, xi2 = xf[3 * i], xf[3 * i + 1], xf[3 * i + 2]
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
            lb = length[c : c + m]
            wb = w[c : c + m]
            kb = dev[c : c + m]
            ok = intact[c : c + m]
            for q in range(m):
                jp = np.uint32(fam[q])
                j = 3 * np.uint64(jp)
                _, _, y0 = bond_differences(xf[j], xi0, uf[j], ui0)
                _, _, y1 = bond_differences(xf[j + 1], xi1, uf[j + 1], ui1)
                _, _, y2 = bond_differences(xf[j + 2], xi2, uf[j + 2], ui2)
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
    return f


@numba.njit(parallel=True, fastmath=FASTMATH, cache=True)
def pmb_force_lanes(xi, u, offsets, nbr, inv_len, k, intact, f):
    """``pmb_force`` with each force component summed in ``LANES`` partial sums (bond q of a chunk
    into lane q), added by a fixed pairwise tree at the end: no chain of dependent additions,
    but another order of each point's sum (the last bits change)."""
    n = u.shape[0]
    zero = f.dtype.type(0.0)
    one = f.dtype.type(1.0)
    uf = u.reshape(3 * n)
    xif = xi.reshape(3 * xi.shape[0])
    for i in numba.prange(n):
        ui0, ui1, ui2 = uf[3 * i], uf[3 * i + 1], uf[3 * i + 2]
        acc = stack_array(LANES3, f.dtype)
        for q in range(LANES3):
            acc[q] = zero
        hi = offsets[i + 1]
        for c in range(offsets[i], hi, LANES):
            m = min(LANES, hi - c)
            fam = nbr[c : c + m]
            xib = xif[3 * c : 3 * (c + m)]
            il = inv_len[c : c + m]
            kb = k[c : c + m]
            ok = intact[c : c + m]
            for q in range(m):
                j = 3 * np.uint64(np.uint32(fam[q]))
                y0 = deformed_component(xib[3 * q], uf[j], ui0)
                y1 = deformed_component(xib[3 * q + 1], uf[j + 1], ui1)
                y2 = deformed_component(xib[3 * q + 2], uf[j + 2], ui2)
                s = kb[q] * (il[q] - one / np.sqrt(y0 * y0 + y1 * y1 + y2 * y2))
                s = s if ok[q] else zero
                acc[q] += s * y0
                acc[LANES + q] += s * y1
                acc[2 * LANES + q] += s * y2
        width = LANES // 2
        while width >= 1:
            for q in range(width):
                for a in range(3):
                    acc[a * LANES + q] += acc[a * LANES + q + width]
            width //= 2
        f[i, 0] = acc[0]
        f[i, 1] = acc[LANES]
        f[i, 2] = acc[2 * LANES]
    return f


def candidates(side: int, seed: int = 0):
    """{name: (the "before" call, the candidate's call)}; each call returns the force (n, 3)."""
    body, b = benchmark_grid(side)
    u = 1e-4 * SPACING * np.random.default_rng(seed).standard_normal(body.points.shape)
    pmb = make_model("pmb", body, b, E=E, nu=NU, density=DENSITY)
    lps = make_model("lps", body, b, E=E, nu=NU, density=DENSITY)
    x, xi = pmb.x, pmb.bond_vectors
    out = {key: np.empty_like(x) for key in ("a", "b")}
    per_bond = (pmb.inv_length, pmb.bond_stiffness, b.intact)

    def lps_force(dilatation, pair_force, where, f):
        theta = dilatation(
            where, u, b.offsets, b.neighbours, lps.length, lps.w, b.intact, lps._theta_coef, lps._theta
        )
        p = np.multiply(theta, lps._p_coef, out=lps._p)
        return pair_force(where, u, b.offsets, b.neighbours, lps.length, lps.w, lps.dev, b.intact, p, f)

    return b.n_bonds, {
        "pmb: x gathered / stored xi (today)": (
            lambda: pmb_force_gather_x(x, u, b.offsets, b.neighbours, *per_bond, out["a"]),
            lambda: pmb_force(xi, u, b.offsets, b.neighbours, *per_bond, out["b"]),
        ),
        "lps: x gathered / stored xi (today)": (
            lambda: lps_force(lps_dilatation_gather_x, lps_pair_force_gather_x, x, out["a"]),
            lambda: lps_force(lps_dilatation, lps_pair_force, xi, out["b"]),
        ),
        "pmb: stored xi (today) / + lane sums": (
            lambda: pmb_force(xi, u, b.offsets, b.neighbours, *per_bond, out["a"]),
            lambda: pmb_force_lanes(xi, u, b.offsets, b.neighbours, *per_bond, out["b"]),
        ),
    }


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--side", type=int, default=DEFAULT_POINTS_PER_SIDE)
    parser.add_argument("--rounds", type=int, default=10)
    args = parser.parse_args(argv)
    n_bonds, cands = candidates(args.side)
    print(
        f"{args.side}^3 grid, {n_bonds} bonds, {numba.get_num_threads()} threads, "
        f"load {os.getloadavg()[0]:.2f}"
    )
    for name, (before, cand) in cands.items():
        print(compare(name, before, cand, n_bonds, args.rounds))
    print(f"load {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()
