"""Issue 22 item 1: candidate float64 force kernels against the single-loop ones, A/B interleaved.

Reference ("before"): the float64 kernels as they were before the two-loop chunks, one
loop per family (``tests/kernels/single_loop_kernels.py``). Candidates: today's kernels
(``peridyn.kernels``, chunked, reading the stored bond vectors) and variants of the single
loop written the same way (family slices, unsigned neighbour index, select on ``intact``,
``bond_differences``). The fused LPS forms (the dilatation and pair-force passes in one, row
block by row block: today's ``kernels.lps.lps_force_fused`` and the candidates
:func:`lps_force_fused_no_ring`, :func:`lps_force_block_prange`) are measured against the two
passes ``lps_dilatation`` + ``lps_pair_force`` instead. For each: the reference's time over
the candidate's (best of ``--rounds`` interleaved calls on the same inputs, any per-call
layout conversion included; wall clock and process CPU time, the latter less sensitive to
other jobs on a shared machine), the median of the rounds' ratios (steadier than the best
when the load moves during a run), and the largest force difference relative to the
largest force (0 = the same bits). Results in HISTORY.md ("Force kernels: chunks, candidates, roofs
and LAMMPS PERI", "Stored bond vectors, the fused LPS force, ...").

    PYTHONPATH=src python benchmarks/kernel_candidates.py --side 49 --rounds 15
    PYTHONPATH=src python benchmarks/kernel_candidates.py --case cases/lamb_plate.yaml --rounds 40

``--case`` runs the fused LPS candidates only, on the model of an LPS float64 case.
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from pathlib import Path

import numba
import numpy as np

from peridyn.discretization.bonds import fused_plan, fused_ring_columns
from peridyn.discretization.pairs import index_bandwidth
from peridyn.jobs.bench import DEFAULT_POINTS_PER_SIDE, SPACING, benchmark_grid
from peridyn.kernels import FASTMATH, bond_differences
from peridyn.kernels.lps import (
    lps_dilatation,
    lps_dilatation_rows,
    lps_dilatation_sum,
    lps_force_fused,
    lps_pair_force,
    lps_pair_force_row,
)
from peridyn.kernels.pmb import pmb_force
from peridyn.physics.materials import make_model
from peridyn.physics.materials.lps import LPSModel

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


# --- LPS dilatation and pair force fused (issue 22 item 1) -----------------------------------
# Today's ``LPSModel.force`` (float64) runs ``kernels.lps.lps_force_fused``: per-thread parts, and
# each bond's Y and |Y| kept from the dilatation for the force in a ring. The candidates here
# are the other forms measured: the same parts without the ring, and one parallel loop a block.


@numba.njit(parallel={"fusion": False}, fastmath=FASTMATH, cache=True)
def lps_force_fused_no_ring(
    xi, u, offsets, nbr, length, w, dev, intact, theta_coef, p_coef, parts, inner, blocks, need, theta, p, f
):
    """``kernels.lps.lps_force_fused`` without its ring: the force of the inner rows gathers
    ``u`` and takes |Y| again, so only the per-bond data is reused (read a second time while
    still in the cache, if the window of about index bandwidth + block rows fits). The same
    bits."""
    n = u.shape[0]
    uf = u.reshape(3 * n)
    xif = xi.reshape(3 * xi.shape[0])
    args = (offsets, nbr, length, w, intact, theta_coef, p_coef, theta, p)
    for t in numba.prange(parts.shape[0]):
        lps_dilatation_rows(parts[t, 0], inner[t, 0], xif, uf, *args)
        lps_dilatation_rows(inner[t, 1], parts[t, 1], xif, uf, *args)
    for t in numba.prange(parts.shape[0]):
        done = inner[t, 0]
        for k in range(parts[t, 2], parts[t, 3]):
            target = min(need[k], inner[t, 1])
            if target > done:
                lps_dilatation_rows(done, target, xif, uf, *args)
                done = target
            for i in range(blocks[k], blocks[k + 1]):
                lps_pair_force_row(i, xif, uf, offsets, nbr, length, w, dev, intact, p, f)
    return f


@numba.njit(parallel=True, fastmath=FASTMATH, cache=True)
def lps_force_block_prange(
    xi, u, offsets, nbr, length, w, dev, intact, theta_coef, p_coef, blocks, need, theta, p, f
):
    """``kernels.lps.lps_force_fused`` the other way round: the blocks one after the other
    (``blocks``, ``need`` of a one-part ``fused_plan``), each block's dilatation rows and then its
    force rows a parallel loop over all threads (two parallel regions a block). The same bits."""
    n = u.shape[0]
    uf = u.reshape(3 * n)
    xif = xi.reshape(3 * xi.shape[0])
    done = 0
    for k in range(blocks.shape[0] - 1):
        target = need[k]
        if target > done:
            for i in numba.prange(done, target):
                th = theta_coef[i] * lps_dilatation_sum(i, xif, uf, offsets, nbr, length, w, intact)
                theta[i] = th
                p[i] = th * p_coef[i]
            done = target
        for i in numba.prange(blocks[k], blocks[k + 1]):
            lps_pair_force_row(i, xif, uf, offsets, nbr, length, w, dev, intact, p, f)
    return f


def lps_fused_candidates(lps, u, out, block_rows=(64, 256, 1024), prange_rows=(2048, 8192)):
    """{name: (today's two passes, fused candidate)} on the LPS float64 model ``lps`` at ``u``
    (n, 3), m; forces into ``out`` ("a", "b": (n, 3) arrays). ``block_rows``: the block sizes of
    ``kernels.lps.lps_force_fused`` (today's, with its ring) and :func:`lps_force_fused_no_ring`;
    ``prange_rows``: those of :func:`lps_force_block_prange` (two parallel regions a block)."""
    b, xi, n = lps.bonds, lps.bond_vectors, lps.body.n_points
    families = (xi, u, b.offsets, b.neighbours, lps.length, lps.w)
    common = (*families, lps.dev, b.intact, lps._theta_coef, lps._p_coef)
    theta, p = np.empty(n), np.empty(n)

    def two_pass():
        th = lps_dilatation(*families, b.intact, lps._theta_coef, lps._theta)
        p = np.multiply(th, lps._p_coef, out=lps._p)
        return lps_pair_force(*families, lps.dev, b.intact, p, out["a"])

    cands = {}
    for rows in block_rows:
        plan = fused_plan(b.offsets, b.neighbours, numba.get_num_threads(), rows)
        ring = np.empty((len(plan.parts), 4, fused_ring_columns(b.offsets, plan)))
        cands[f"lps: fused, blocks of {rows} rows, no ring"] = (
            two_pass,
            lambda plan=plan: lps_force_fused_no_ring(*common, *plan, theta, p, out["b"]),
        )
        cands[f"lps: fused, {rows} rows, Y and |Y| kept"] = (
            two_pass,
            lambda plan=plan, ring=ring: lps_force_fused(*common, *plan, ring, theta, p, out["b"]),
        )
    for rows in prange_rows:
        _, _, blocks, need = fused_plan(b.offsets, b.neighbours, 1, rows)
        cands[f"lps: fused, prange in blocks of {rows} rows"] = (
            two_pass,
            lambda blocks=blocks, need=need: lps_force_block_prange(
                *common, blocks, need, theta, p, out["b"]
            ),
        )
    return cands


def candidates(side: int, block_rows=(64, 256, 1024), seed: int = 0):
    """(n_bonds, index bandwidth, {name: (reference call, candidate's call)}) on the ``side``^3
    bench grid; each call returns the force (n, 3)."""
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

    return (
        b.n_bonds,
        index_bandwidth(b.offsets, b.neighbours),
        {
            "pmb: chunks of 16, stored xi (today)": (pmb_before, pmb_chunked),
            "pmb: SoA x, u (six (n,) arrays)": (pmb_before, soa),
            "pmb: x, u interleaved (n, 6)": (pmb_before, interleaved),
            "pmb: float32 1/|xi|, no intact (16 B/bond)": (pmb_before, lean),
            "lps: chunks of 16, stored xi (today)": (lps_before, lps_chunked),
            "lps: |Y| stored by the dilatation pass": (lps_before, lps_keep_r),
            **lps_fused_candidates(lps, u, out, block_rows),
        },
    )


def case_candidates(path: str, block_rows=(64, 256, 1024), seed: int = 0):
    """:func:`candidates` for the fused LPS candidates on the model of the LPS float64 case
    ``path``, at a random displacement of 1e-4 of its shortest bond."""
    from peridyn.io.case import load_case
    from peridyn.setup.build import build

    setup = build(load_case(path), base_dir=Path(path).parent)
    lps, b = setup.model, setup.bonds
    if not isinstance(lps, LPSModel) or lps.dtype != np.float64:
        raise SystemExit(f"{path}: the fused candidates need an LPS float64 model")
    u = 1e-4 * b.length.min() * np.random.default_rng(seed).standard_normal(lps.x.shape)
    out = {key: np.empty_like(lps.x) for key in ("a", "b")}
    return b.n_bonds, index_bandwidth(b.offsets, b.neighbours), lps_fused_candidates(lps, u, out, block_rows)


def compare(name: str, before, cand, n_bonds: int, rounds: int) -> str:
    """One line: the calls ``before`` and ``cand`` (each returns a force) timed ``rounds`` times,
    interleaved; their best rates (M bond/s of ``n_bonds``), the ratio before / candidate of the
    best wall and CPU times and the median of the rounds' ratios (above 1: the candidate is
    faster), and the largest force difference relative to the largest force (0: the same bits)."""
    fa, fb = before().copy(), cand().copy()
    rel = float(np.max(np.abs(fb - fa)) / np.max(np.abs(fa)))
    wall, cpu = np.empty((2, rounds)), np.empty((2, rounds))
    for r in range(rounds):
        for k, call in enumerate((before, cand)):
            t0, c0 = time.perf_counter(), time.process_time()
            call()
            wall[k, r] = time.perf_counter() - t0
            cpu[k, r] = time.process_time() - c0
    best_wall, best_cpu = wall.min(axis=1), cpu.min(axis=1)
    return (
        f"{name:<44} before {n_bonds / best_wall[0] / 1e6:5.0f} M/s, "
        f"candidate {n_bonds / best_wall[1] / 1e6:5.0f} M/s; "
        f"ratio wall {best_wall[0] / best_wall[1]:.3f}, CPU {best_cpu[0] / best_cpu[1]:.3f} "
        f"(median of the rounds' ratios {np.median(wall[0] / wall[1]):.3f}, "
        f"{np.median(cpu[0] / cpu[1]):.3f}); max |df| / max |f| {rel:.1e}"
    )


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--side", type=int, default=DEFAULT_POINTS_PER_SIDE)
    parser.add_argument("--rounds", type=int, default=15)
    parser.add_argument("--only", default=None, help="substring of the candidates to run")
    parser.add_argument("--case", default=None, help="an LPS float64 case: the fused candidates on its model")
    parser.add_argument("--block-rows", default="64,256,1024", help="row block sizes of the fused candidates")
    args = parser.parse_args(argv)
    rows = tuple(int(v) for v in args.block_rows.split(","))
    if args.case:
        n_bonds, bandwidth, cands = case_candidates(args.case, rows)
        where = args.case
    else:
        n_bonds, bandwidth, cands = candidates(args.side, rows)
        where = f"{args.side}^3 grid"
    print(
        f"{where}, {n_bonds} bonds, index bandwidth {bandwidth}, {numba.get_num_threads()} threads, "
        f"load {os.getloadavg()[0]:.2f}"
    )
    for name, (before, cand) in cands.items():
        if args.only and args.only not in name:
            continue
        print(compare(name, before, cand, n_bonds, args.rounds))
    print(f"load {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()
