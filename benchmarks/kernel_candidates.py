"""Issue 22 item 1: candidate float64 force kernels against the single-loop ones, A/B interleaved.

Reference ("before"): the float64 kernels as they were before the two-loop chunks, one
loop per family (``tests/kernels/single_loop_kernels.py``). Candidates: today's kernels
(``peridyn.kernels``, chunked, reading the stored bond vectors) and variants of the single
loop written the same way (family slices, unsigned neighbour index, select on ``intact``,
``bond_differences``). For each: the reference's time over the candidate's (best of
``--rounds`` interleaved calls on the same inputs, any per-call layout conversion included;
wall clock and process CPU time, the latter less sensitive to other jobs on a shared
machine), and the largest force difference relative to the largest force (0 = the same
bits). Results in RESULTS.md.

    PYTHONPATH=src python benchmarks/kernel_candidates.py --side 49 --rounds 15
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from pathlib import Path

import numba
import numpy as np

from peridyn.jobs.bench import DEFAULT_POINTS_PER_SIDE, SPACING, benchmark_grid
from peridyn.kernels import FASTMATH, bond_differences
from peridyn.kernels.lps import lps_dilatation, lps_pair_force
from peridyn.kernels.pmb import pmb_force
from peridyn.physics.materials import make_model

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests" / "kernels"))
import single_loop_kernels as single  # noqa: E402

E, NU, DENSITY = 200e9, 0.25, 7850.0


@numba.njit(parallel=True, fastmath=FASTMATH, cache=True)
def pmb_force_soa(x0, x1, x2, u0, u1, u2, offsets, nbr, inv_len, k, intact, f):
    """PMB with structure-of-arrays coordinates and displacements (six (n,) arrays)."""
    n = x0.shape[0]
    zero = f.dtype.type(0.0)
    one = f.dtype.type(1.0)
    for i in numba.prange(n):
        xi0, xi1, xi2 = x0[i], x1[i], x2[i]
        ui0, ui1, ui2 = u0[i], u1[i], u2[i]
        lo = offsets[i]
        hi = offsets[i + 1]
        fam = nbr[lo:hi]
        il = inv_len[lo:hi]
        kb = k[lo:hi]
        ok = intact[lo:hi]
        f0 = zero
        f1 = zero
        f2 = zero
        for q in range(hi - lo):
            j = np.uint64(np.uint32(fam[q]))
            _, _, y0 = bond_differences(x0[j], xi0, u0[j], ui0)
            _, _, y1 = bond_differences(x1[j], xi1, u1[j], ui1)
            _, _, y2 = bond_differences(x2[j], xi2, u2[j], ui2)
            s = kb[q] * (il[q] - one / np.sqrt(y0 * y0 + y1 * y1 + y2 * y2))
            s = s if ok[q] else zero
            f0 += s * y0
            f1 += s * y1
            f2 += s * y2
        f[i, 0] = f0
        f[i, 1] = f1
        f[i, 2] = f2
    return f


@numba.njit(parallel=True, fastmath=FASTMATH, cache=True)
def pmb_force_xu(xu, offsets, nbr, inv_len, k, intact, f):
    """PMB with x and u of a point side by side: ``xu`` (n, 6) = [x, u] (one cache line per neighbour)."""
    n = xu.shape[0]
    zero = f.dtype.type(0.0)
    one = f.dtype.type(1.0)
    g = xu.reshape(6 * n)
    for i in numba.prange(n):
        xi0, xi1, xi2 = g[6 * i], g[6 * i + 1], g[6 * i + 2]
        ui0, ui1, ui2 = g[6 * i + 3], g[6 * i + 4], g[6 * i + 5]
        lo = offsets[i]
        hi = offsets[i + 1]
        fam = nbr[lo:hi]
        il = inv_len[lo:hi]
        kb = k[lo:hi]
        ok = intact[lo:hi]
        f0 = zero
        f1 = zero
        f2 = zero
        for q in range(hi - lo):
            j = 6 * np.uint64(np.uint32(fam[q]))
            _, _, y0 = bond_differences(g[j], xi0, g[j + 3], ui0)
            _, _, y1 = bond_differences(g[j + 1], xi1, g[j + 4], ui1)
            _, _, y2 = bond_differences(g[j + 2], xi2, g[j + 5], ui2)
            s = kb[q] * (il[q] - one / np.sqrt(y0 * y0 + y1 * y1 + y2 * y2))
            s = s if ok[q] else zero
            f0 += s * y0
            f1 += s * y1
            f2 += s * y2
        f[i, 0] = f0
        f[i, 1] = f1
        f[i, 2] = f2
    return f


@numba.njit(parallel=True, fastmath=FASTMATH, cache=True)
def pmb_force_lean(x, u, offsets, nbr, inv_len32, k, f):
    """PMB with leaner per-bond data: 1/|xi| stored in float32 (float64 arithmetic) and no
    ``intact`` array (a broken bond would carry k = 0): 4 + 4 + 8 = 16 bytes per bond, not 21."""
    n = x.shape[0]
    one = f.dtype.type(1.0)
    zero = f.dtype.type(0.0)
    xf = x.reshape(3 * n)
    uf = u.reshape(3 * n)
    for i in numba.prange(n):
        xi0, xi1, xi2 = xf[3 * i], xf[3 * i + 1], xf[3 * i + 2]
        ui0, ui1, ui2 = uf[3 * i], uf[3 * i + 1], uf[3 * i + 2]
        lo = offsets[i]
        hi = offsets[i + 1]
        fam = nbr[lo:hi]
        il = inv_len32[lo:hi]
        kb = k[lo:hi]
        f0 = zero
        f1 = zero
        f2 = zero
        for q in range(hi - lo):
            j = 3 * np.uint64(np.uint32(fam[q]))
            _, _, y0 = bond_differences(xf[j], xi0, uf[j], ui0)
            _, _, y1 = bond_differences(xf[j + 1], xi1, uf[j + 1], ui1)
            _, _, y2 = bond_differences(xf[j + 2], xi2, uf[j + 2], ui2)
            s = kb[q] * (np.float64(il[q]) - one / np.sqrt(y0 * y0 + y1 * y1 + y2 * y2))
            f0 += s * y0
            f1 += s * y1
            f2 += s * y2
        f[i, 0] = f0
        f[i, 1] = f1
        f[i, 2] = f2
    return f


@numba.njit(parallel=True, fastmath=FASTMATH, cache=True)
def lps_dilatation_keep_r(x, u, offsets, nbr, length, w, intact, theta_coef, theta, r_out):
    """``lps_dilatation`` that also stores each bond's |Y| (``r_out``, (n_bonds,)) for the force pass."""
    n = x.shape[0]
    zero = theta.dtype.type(0.0)
    xf = x.reshape(3 * n)
    uf = u.reshape(3 * n)
    for i in numba.prange(n):
        xi0, xi1, xi2 = xf[3 * i], xf[3 * i + 1], xf[3 * i + 2]
        ui0, ui1, ui2 = uf[3 * i], uf[3 * i + 1], uf[3 * i + 2]
        lo = offsets[i]
        hi = offsets[i + 1]
        fam = nbr[lo:hi]
        lb = length[lo:hi]
        wb = w[lo:hi]
        ok = intact[lo:hi]
        rb = r_out[lo:hi]
        acc = zero
        for q in range(hi - lo):
            j = 3 * np.uint64(np.uint32(fam[q]))
            _, _, y0 = bond_differences(xf[j], xi0, uf[j], ui0)
            _, _, y1 = bond_differences(xf[j + 1], xi1, uf[j + 1], ui1)
            _, _, y2 = bond_differences(xf[j + 2], xi2, uf[j + 2], ui2)
            r = np.sqrt(y0 * y0 + y1 * y1 + y2 * y2)
            rb[q] = r
            t = wb[q] * lb[q] * (r - lb[q])
            acc += t if ok[q] else zero
        theta[i] = theta_coef[i] * acc
    return theta


@numba.njit(parallel=True, fastmath=FASTMATH, cache=True)
def lps_pair_force_given_r(x, u, offsets, nbr, length, w, dev, intact, p, r_in, f):
    """``lps_pair_force`` reading |Y| from the dilatation pass (``r_in``) instead of a square root."""
    n = x.shape[0]
    zero = f.dtype.type(0.0)
    xf = x.reshape(3 * n)
    uf = u.reshape(3 * n)
    for i in numba.prange(n):
        xi0, xi1, xi2 = xf[3 * i], xf[3 * i + 1], xf[3 * i + 2]
        ui0, ui1, ui2 = uf[3 * i], uf[3 * i + 1], uf[3 * i + 2]
        lo = offsets[i]
        hi = offsets[i + 1]
        fam = nbr[lo:hi]
        lb = length[lo:hi]
        wb = w[lo:hi]
        kb = dev[lo:hi]
        ok = intact[lo:hi]
        rb = r_in[lo:hi]
        pi = p[i]
        f0 = zero
        f1 = zero
        f2 = zero
        for q in range(hi - lo):
            jp = np.uint32(fam[q])
            j = 3 * np.uint64(jp)
            _, _, y0 = bond_differences(xf[j], xi0, uf[j], ui0)
            _, _, y1 = bond_differences(xf[j + 1], xi1, uf[j + 1], ui1)
            _, _, y2 = bond_differences(xf[j + 2], xi2, uf[j + 2], ui2)
            r = rb[q]
            L = lb[q]
            t = (wb[q] * L * (pi + p[jp]) + kb[q] * (r - L)) / r
            t = t if ok[q] else zero
            f0 += t * y0
            f1 += t * y1
            f2 += t * y2
        f[i, 0] = f0
        f[i, 1] = f1
        f[i, 2] = f2
    return f


def candidates(side: int, seed: int = 0):
    """{name: (today's call, candidate's call)}; each call returns the force (n, 3)."""
    body, bonds = benchmark_grid(side)
    u = 1e-4 * SPACING * np.random.default_rng(seed).standard_normal(body.points.shape)
    pmb = make_model("pmb", body, bonds, E=E, nu=NU, density=DENSITY)
    lps = make_model("lps", body, bonds, E=E, nu=NU, density=DENSITY)
    b, x, n = bonds, pmb.x, body.n_points
    out = {key: np.empty_like(x) for key in ("a", "b")}
    xs = [np.ascontiguousarray(x[:, a]) for a in range(3)]
    us = [np.empty(n) for _ in range(3)]
    xu = np.empty((n, 6))
    xu[:, :3] = x
    il32 = pmb.inv_length.astype(np.float32)
    k_broken = np.where(b.intact, pmb.bond_stiffness, 0.0)
    r = np.empty(b.n_bonds)

    pmb_args = (x, u, b.offsets, b.neighbours, pmb.inv_length, pmb.bond_stiffness, b.intact)
    xi = pmb.bond_vectors

    def pmb_before():
        return single.pmb_force(*pmb_args, out["a"])

    def pmb_chunked():
        return pmb_force(xi, *pmb_args[1:], out["b"])

    def soa():
        for a in range(3):
            us[a][:] = u[:, a]
        args = (b.offsets, b.neighbours, pmb.inv_length, pmb.bond_stiffness, b.intact, out["b"])
        return pmb_force_soa(*xs, *us, *args)

    def interleaved():
        xu[:, 3:] = u
        return pmb_force_xu(
            xu, b.offsets, b.neighbours, pmb.inv_length, pmb.bond_stiffness, b.intact, out["b"]
        )

    def lean():
        return pmb_force_lean(x, u, b.offsets, b.neighbours, il32, k_broken, out["b"])

    def lps_pair(dilatation, pair_force, f, where=x):
        theta = dilatation(
            where, u, b.offsets, b.neighbours, lps.length, lps.w, b.intact, lps._theta_coef, lps._theta
        )
        p = np.multiply(theta, lps._p_coef, out=lps._p)
        return pair_force(where, u, b.offsets, b.neighbours, lps.length, lps.w, lps.dev, b.intact, p, f)

    def lps_before():
        return lps_pair(single.lps_dilatation, single.lps_pair_force, out["a"])

    def lps_chunked():
        return lps_pair(lps_dilatation, lps_pair_force, out["b"], xi)

    def lps_keep_r():
        theta = lps_dilatation_keep_r(
            x, u, b.offsets, b.neighbours, lps.length, lps.w, b.intact, lps._theta_coef, lps._theta, r
        )
        p = np.multiply(theta, lps._p_coef, out=lps._p)
        return lps_pair_force_given_r(
            x, u, b.offsets, b.neighbours, lps.length, lps.w, lps.dev, b.intact, p, r, out["b"]
        )

    return b.n_bonds, {
        "pmb: chunks of 16, stored xi (today)": (pmb_before, pmb_chunked),
        "pmb: SoA x, u (six (n,) arrays)": (pmb_before, soa),
        "pmb: x, u interleaved (n, 6)": (pmb_before, interleaved),
        "pmb: float32 1/|xi|, no intact (16 B/bond)": (pmb_before, lean),
        "lps: chunks of 16, stored xi (today)": (lps_before, lps_chunked),
        "lps: |Y| stored by the dilatation pass": (lps_before, lps_keep_r),
    }


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--side", type=int, default=DEFAULT_POINTS_PER_SIDE)
    parser.add_argument("--rounds", type=int, default=15)
    parser.add_argument("--only", default=None, help="substring of the candidates to run")
    args = parser.parse_args(argv)
    n_bonds, cands = candidates(args.side)
    print(
        f"{args.side}^3 grid, {n_bonds} bonds, {numba.get_num_threads()} threads, "
        f"load {os.getloadavg()[0]:.2f}"
    )
    for name, (before, cand) in cands.items():
        if args.only and args.only not in name:
            continue
        fa, fb = before().copy(), cand().copy()
        rel = float(np.max(np.abs(fb - fa)) / np.max(np.abs(fa)))
        wall = [np.inf, np.inf]
        cpu = [np.inf, np.inf]
        for _ in range(args.rounds):
            for k, call in enumerate((before, cand)):
                t0, c0 = time.perf_counter(), time.process_time()
                call()
                wall[k] = min(wall[k], time.perf_counter() - t0)
                cpu[k] = min(cpu[k], time.process_time() - c0)
        print(
            f"{name:<44} before {n_bonds / wall[0] / 1e6:5.0f} M/s, "
            f"candidate {n_bonds / wall[1] / 1e6:5.0f} M/s; "
            f"ratio wall {wall[0] / wall[1]:.3f}, CPU {cpu[0] / cpu[1]:.3f}; max |df| / max |f| {rel:.1e}"
        )
    print(f"load {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()
