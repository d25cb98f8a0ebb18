"""Each bond pair once on the lattice: the pair kernels against the full stencil, A/B interleaved.

Before (kept here): the lattice force kernels as they were before each pair once, every directed
bond computed from its own end, each grid row's points summing their own bonds (rows in
parallel). Candidate: the kernels of ``peridyn.kernels.lattice`` (its module docstring): one of
each two opposite offsets (``pair_offsets``), each pair's term added to both ends in a grid-sized
sum, slabs of y planes run even then odd so that the bits do not depend on the thread count.
LPS: the dilatation and the pair force, each before / candidate, P = p_coef theta between them.

Rows (float64 by default, each thread count of ``--threads`` one interleaved pass, the kernels
alone: the grid displacement scattered once): best rates (M directed bonds/s), before /
candidate of the best wall times and the median of the rounds' ratios (above 1: the pair kernels
are faster), the largest force difference relative to the largest force, and whether the
candidate gives the same bits as on the first thread count. Results in HISTORY.md ("Each pair
once on the lattice: ...").

    PYTHONPATH=src python benchmarks/kernel_lattice_half.py --body cube --side 49 --threads 1 2
    PYTHONPATH=src python benchmarks/kernel_lattice_half.py --body case --threads 1 2
"""

from __future__ import annotations

import argparse
import os
import time

import numba
import numpy as np
from lattice_rates import case_models, cube_models

from peridyn.jobs.bench import DEFAULT_POINTS_PER_SIDE
from peridyn.kernels import CHUNK, FASTMATH, stack_array
from peridyn.kernels.lattice import (
    LATTICE_BUFFER,
    _bond_terms,
    _neighbour_row,
    _write_row,
    lattice_lps_dilatation,
    lattice_lps_force,
    lattice_pmb_force,
)


@numba.njit(parallel=True, fastmath=FASTMATH, cache=True)
def full_pmb_force(u, vol, broken, shape, offs, xi, length, inv_len, coef, cf, point_of, f):
    """The previous PMB kernel (every directed bond, each point its own sums): force density
    ``f`` (OUT, (n_out, 3), N/m^3, rows ``point_of``) of the grid points:
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
                _bond_terms(
                    cf, u, p0, p0 + shift, m, x0, x1, x2, L, bits[p0 : p0 + m], bit, vol[p0 : p0 + m], vq, buf
                )
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
def full_lps_dilatation(u, vol, broken, shape, offs, xi, length, weight, cf, theta_coef, theta):
    """The previous LPS dilatation kernel (every directed bond): ``theta`` (OUT, (n_grid,)):
    theta_i = theta_coef_i sum_k w V_j |xi| e over
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
                _bond_terms(
                    cf, u, p0, p0 + shift, m, x0, x1, x2, L, bits[p0 : p0 + m], bit, vol[p0 : p0 + m], vq, buf
                )
                g = th[c0 : c0 + m]
                for q in range(m):
                    g[q] += (wk * vq[q]) * L * buf[5 * CHUNK + q] if buf[q] > zero else zero
        tc = theta_coef[base : base + nx]
        for ix in range(nx):
            th[ix] *= tc[ix]
    return theta


@numba.njit(parallel=True, fastmath=FASTMATH, cache=True)
def full_lps_force(u, vol, broken, shape, offs, xi, length, weight, cf, alpha, p, point_of, f):
    """The previous LPS force kernel (every directed bond): force density ``f`` (OUT, (n_out, 3),
    N/m^3, rows ``point_of``) from the per-point ``p`` = P_i and
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
                _bond_terms(
                    cf, u, i0, j0, m, x0, x1, x2, L, bits[i0 : i0 + m], bit, vol[i0 : i0 + m], vq, buf
                )
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


def calls(model, u):
    """(before, candidate) zero-argument force calls of the lattice ``model`` at ``u``
    (n_points, 3), kernels only: the grid displacement is scattered once here."""
    lat, s = model.lattice, model.lattice.stencil
    ug = model._scatter(u).copy()
    grid_f = np.empty((3, lat.n_grid), dtype=model.dtype)
    out = {key: np.empty_like(model.x) for key in ("full", "half")}
    head = (ug, model._vol, lat.broken, lat.shape, s.offsets)
    if model.name == "pmb":
        table = (model._xi, model._length, model._inv_len, model._coef, model._cf)

        def full():
            return full_pmb_force(*head, *table, model._point_of, out["full"])

        def half():
            return lattice_pmb_force(*head, *model._pairs, *table, grid_f, model._point_of, out["half"])

        return full, half
    table = (model._xi, model._length, model._weight, model._cf)
    theta = {key: np.empty(lat.n_grid, dtype=model.dtype) for key in ("full", "half")}

    def full():
        p = full_lps_dilatation(*head, *table, model._theta_coef, theta["full"])
        np.multiply(p, model._p_coef, out=p)
        return full_lps_force(*head, *table, model._alpha, p, model._point_of, out["full"])

    def half():
        p = lattice_lps_dilatation(*head, *model._pairs, *table, model._theta_coef, theta["half"])
        np.multiply(p, model._p_coef, out=p)
        args = (*table, model._alpha, p, grid_f, model._point_of, out["half"])
        return lattice_lps_force(*head, *model._pairs, *args)

    return full, half


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--body", choices=("cube", "case"), default="cube")
    parser.add_argument("--side", type=int, default=DEFAULT_POINTS_PER_SIDE, help="cube: points a side")
    parser.add_argument("--case", default="cases/lamb_plate.yaml", help="case: the case file")
    parser.add_argument("--rounds", type=int, default=10)
    parser.add_argument("--threads", type=int, nargs="+", default=[1, 2])
    parser.add_argument("--dtype", default="float64")
    args = parser.parse_args(argv)
    models, n_bonds = cube_models(args.side) if args.body == "cube" else case_models(args.case)
    lattice_models = {k[0]: m for k, m in models.items() if k[1] == args.dtype and k[2] == "lattice"}
    del models
    x = lattice_models["pmb"].x
    u = (
        1e-4
        * lattice_models["pmb"].lattice.stencil.length.min()
        * np.random.default_rng(0).standard_normal(x.shape)
    )
    u = u.astype(args.dtype)
    pairs = {name: calls(model, u) for name, model in lattice_models.items()}
    what = f"{args.side}^3 cube" if args.body == "cube" else args.case
    first = {}
    for threads in args.threads:
        numba.set_num_threads(threads)
        print(f"{what}: {x.shape[0]} points, {n_bonds} directed bonds, {args.dtype}, {threads} threads, "
              f"load {os.getloadavg()[0]:.2f}")  # fmt: skip
        for name, (full, half) in pairs.items():
            ff, fh = full().copy(), half().copy()
            same = np.array_equal(first.setdefault(name, fh), fh)
            rel = np.max(np.abs(fh - ff)) / np.max(np.abs(ff))
            times = np.empty((2, args.rounds))
            for r in range(args.rounds):
                for k, call in enumerate((full, half)):
                    t0 = time.perf_counter()
                    call()
                    times[k, r] = time.perf_counter() - t0
            best = times.min(axis=1)
            rates = n_bonds / best / 1e6
            print(
                f"  {name}: full {rates[0]:6.1f} M/s, half {rates[1]:6.1f} M/s; full / half "
                f"{best[0] / best[1]:.2f}x (median of the rounds {np.median(times[0] / times[1]):.2f}x); "
                f"max |df| / max |f| {rel:.1e}; same bits as on {args.threads[0]} threads: {same}",
                flush=True,
            )
    print(f"load {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()
