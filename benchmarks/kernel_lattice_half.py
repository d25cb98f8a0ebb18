"""Each bond pair once on the lattice: a half stencil against the full one, A/B interleaved.

The lattice force kernels (``peridyn.kernels.lattice``) compute every directed bond: each pair
twice, once from each end, each point's sums its own. The candidates here compute each pair once:

- the half stencil: the offsets (ox, oy, oz) with (oy, oz, ox) lexicographically positive; a pair
  (i, i + o) is computed at i, its force added to i and subtracted from j (with the other end's
  volume: f_i += c V_j t Y, f_j -= c V_i t Y), into a grid force array (3, n_grid) written to the
  body's points at the end; its broken bit is i's (a broken bond has both bits set);
- deterministic on any number of threads: the grid is cut into slabs of ``width`` = max |oy| rows
  of y (every z), so a pair computed in slab s ends in slab s or s + 1; the even slabs run in
  parallel, then the odd ones, each slab by one thread in a fixed order, so every point adds its
  pairs in the same order whatever the thread count (and whatever the x range of the grid: MPI
  ranks cut the grid across x);
- LPS: the dilatation the same way (theta_i += w V_j |xi| e, theta_j += w V_i |xi| e), then
  theta and P per point, then the pair force with P_i + P_j and alpha_i + alpha_j.

Rows (float64, ``--threads`` each in one interleaved pass): the full-stencil kernel / the
half-stencil one (best wall times and the median of the rounds' ratios, above 1: the half is
faster), the largest difference of the two forces relative to the largest force, and whether
the half stencil gives the same bits on every thread count. Results in HISTORY.md ("Each pair
once on the lattice: a half stencil against the full one").

    PYTHONPATH=src python benchmarks/kernel_lattice_half.py --body cube --threads 1 2
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


def half_stencil(offsets: np.ndarray) -> np.ndarray:
    """Rows of the stencil ``offsets`` (n_off, 3) whose (oy, oz, ox) is lexicographically positive
    (one of each pair of opposite offsets), in stencil order."""
    ox, oy, oz = offsets.T
    return np.flatnonzero((oy > 0) | ((oy == 0) & ((oz > 0) | ((oz == 0) & (ox > 0)))))


@numba.njit(fastmath=FASTMATH, cache=True, inline="always")
def _slab(colour, h, width, ny):
    """(first y, end y) of task ``h`` of phase ``colour`` (slab 2 h + colour; empty past the grid)."""
    s = 2 * h + colour
    return min(ny, s * width), min(ny, (s + 1) * width)


@numba.njit(fastmath=FASTMATH, cache=True)
def _zero_planes(a, y0, y1, shape):
    """a[:, g] = 0 (a (k, n_grid)) for the grid points of the y planes y0 .. y1 - 1."""
    nx, ny, nz = shape[0], shape[1], shape[2]
    for iz in range(nz):
        for g in range((iz * ny + y0) * nx, (iz * ny + y1) * nx):
            for d in range(a.shape[0]):
                a[d, g] = 0.0


@numba.njit(fastmath=FASTMATH, cache=True)
def _write_planes(grid_f, y0, y1, shape, point_of, f):
    """The forces ``grid_f`` (3, n_grid) of the y planes y0 .. y1 - 1 to ``f`` at ``point_of``."""
    nx, ny, nz = shape[0], shape[1], shape[2]
    for iz in range(nz):
        for iy in range(y0, y1):
            base = (iz * ny + iy) * nx
            _write_row(grid_f[:, base : base + nx], point_of, base, f)


@numba.njit(fastmath=FASTMATH, cache=True)
def _scale_planes(theta, y0, y1, shape, coef):
    """theta *= coef ((n_grid,)) on the y planes y0 .. y1 - 1."""
    nx, ny, nz = shape[0], shape[1], shape[2]
    for iz in range(nz):
        for g in range((iz * ny + y0) * nx, (iz * ny + y1) * nx):
            theta[g] *= coef[g]


@numba.njit(fastmath=FASTMATH, cache=True, inline="always")
def _phase_tasks(colour, n_slabs):
    """Tasks of phase ``colour``: the even slabs, then the odd ones (at least one: it finishes slab 0)."""
    return (n_slabs + 1) // 2 if colour == 0 else max(1, n_slabs // 2)


@numba.njit(fastmath=FASTMATH, cache=True, inline="always")
def _before(colour, h, width, ny):
    """Phase 0's task zeroes its slab and the next (only it adds to the next in phase 0): (y0, y1)."""
    y0, y1 = _slab(0, h, width, ny)
    return (y0, min(ny, y1 + width)) if colour == 0 else (0, 0)


@numba.njit(fastmath=FASTMATH, cache=True, inline="always")
def _after(colour, h, width, ny):
    """Phase 1's task finishes its slab and the next (no later pair adds to them; task 0 also
    slab 0, which no phase-1 pair reaches): (y0, y1)."""
    if colour == 0:
        return 0, 0
    y0, y1 = _slab(1, h, width, ny)
    return (0 if h == 0 else y0), min(ny, y1 + width)


@numba.njit(parallel=True, fastmath=FASTMATH, cache=True)
def half_pmb_force(
    u, vol, broken, shape, offs, ks, xi, length, inv_len, coef, cf, width, grid_f, point_of, f
):
    """PMB force (as ``lattice_pmb_force``) over the half stencil ``ks`` (rows of ``offs``), each
    pair once; ``grid_f`` (3, n_grid) scratch."""
    nx, ny, nz = shape[0], shape[1], shape[2]
    zero = u.dtype.type(0.0)
    one = u.dtype.type(1.0)
    n_slabs = (ny + width - 1) // width
    for colour in range(2):
        for h in numba.prange(_phase_tasks(colour, n_slabs)):
            z0, z1 = _before(colour, h, width, ny)
            _zero_planes(grid_f, z0, z1, shape)
            y0s, y1s = _slab(colour, h, width, ny)
            buf = stack_array(LATTICE_BUFFER, u.dtype)
            for iy in range(y0s, y1s):
                for iz in range(nz):
                    r = iz * ny + iy
                    base = r * nx
                    for kk in range(ks.shape[0]):
                        k = ks[kk]
                        lo, hi, shift = _neighbour_row(r, ny, nz, nx, offs[k, 0], offs[k, 1], offs[k, 2])
                        bit = np.uint64(1) << np.uint64(k & 63)
                        bits = broken[k >> 6]
                        x0, x1, x2, L, il, c = xi[k, 0], xi[k, 1], xi[k, 2], length[k], inv_len[k], coef[k]
                        for c0 in range(lo, hi, CHUNK):
                            m = min(CHUNK, hi - c0)
                            p0 = base + c0
                            q0 = p0 + shift
                            vq = vol[q0 : q0 + m]
                            vp = vol[p0 : p0 + m]
                            _bond_terms(cf, u, p0, q0, m, x0, x1, x2, L, bits[p0 : p0 + m], bit, vq, buf)
                            for q in range(m):
                                rr = buf[4 * CHUNK + q]
                                t = buf[5 * CHUNK + q] * il / rr if cf else il - one / rr
                                buf[q] = c * t if buf[q] > zero else zero
                            g0 = grid_f[0, p0 : p0 + m]
                            g1 = grid_f[1, p0 : p0 + m]
                            g2 = grid_f[2, p0 : p0 + m]
                            for q in range(m):
                                s = buf[q] * vq[q]
                                g0[q] += s * buf[CHUNK + q]
                                g1[q] += s * buf[2 * CHUNK + q]
                                g2[q] += s * buf[3 * CHUNK + q]
                            h0 = grid_f[0, q0 : q0 + m]
                            h1 = grid_f[1, q0 : q0 + m]
                            h2 = grid_f[2, q0 : q0 + m]
                            for q in range(m):
                                s = buf[q] * vp[q]
                                h0[q] -= s * buf[CHUNK + q]
                                h1[q] -= s * buf[2 * CHUNK + q]
                                h2[q] -= s * buf[3 * CHUNK + q]
            w0, w1 = _after(colour, h, width, ny)
            _write_planes(grid_f, w0, w1, shape, point_of, f)
    return f


@numba.njit(parallel=True, fastmath=FASTMATH, cache=True)
def half_lps_dilatation(u, vol, broken, shape, offs, ks, xi, length, weight, cf, width, theta_coef, theta):
    """LPS dilatation (as ``lattice_lps_dilatation``) over the half stencil, each pair once."""
    nx, ny, nz = shape[0], shape[1], shape[2]
    zero = theta.dtype.type(0.0)
    n_slabs = (ny + width - 1) // width
    t2 = theta.reshape((1, theta.shape[0]))
    for colour in range(2):
        for h in numba.prange(_phase_tasks(colour, n_slabs)):
            z0, z1 = _before(colour, h, width, ny)
            _zero_planes(t2, z0, z1, shape)
            y0s, y1s = _slab(colour, h, width, ny)
            buf = stack_array(LATTICE_BUFFER, theta.dtype)
            for iy in range(y0s, y1s):
                for iz in range(nz):
                    r = iz * ny + iy
                    base = r * nx
                    for kk in range(ks.shape[0]):
                        k = ks[kk]
                        lo, hi, shift = _neighbour_row(r, ny, nz, nx, offs[k, 0], offs[k, 1], offs[k, 2])
                        bit = np.uint64(1) << np.uint64(k & 63)
                        bits = broken[k >> 6]
                        x0, x1, x2, L, wk = xi[k, 0], xi[k, 1], xi[k, 2], length[k], weight[k]
                        for c0 in range(lo, hi, CHUNK):
                            m = min(CHUNK, hi - c0)
                            p0 = base + c0
                            q0 = p0 + shift
                            vq = vol[q0 : q0 + m]
                            vp = vol[p0 : p0 + m]
                            _bond_terms(cf, u, p0, q0, m, x0, x1, x2, L, bits[p0 : p0 + m], bit, vq, buf)
                            for q in range(m):
                                buf[q] = (wk * L) * buf[5 * CHUNK + q] if buf[q] > zero else zero
                            g = theta[p0 : p0 + m]
                            for q in range(m):
                                g[q] += vq[q] * buf[q]
                            g = theta[q0 : q0 + m]
                            for q in range(m):
                                g[q] += vp[q] * buf[q]
            w0, w1 = _after(colour, h, width, ny)
            _scale_planes(theta, w0, w1, shape, theta_coef)
    return theta


@numba.njit(parallel=True, fastmath=FASTMATH, cache=True)
def half_lps_force(
    u, vol, broken, shape, offs, ks, xi, length, weight, cf, width, alpha, p, grid_f, point_of, f
):
    """LPS pair force (as ``lattice_lps_force``) over the half stencil, each pair once."""
    nx, ny, nz = shape[0], shape[1], shape[2]
    zero = u.dtype.type(0.0)
    n_slabs = (ny + width - 1) // width
    for colour in range(2):
        for h in numba.prange(_phase_tasks(colour, n_slabs)):
            z0, z1 = _before(colour, h, width, ny)
            _zero_planes(grid_f, z0, z1, shape)
            y0s, y1s = _slab(colour, h, width, ny)
            buf = stack_array(LATTICE_BUFFER, u.dtype)
            for iy in range(y0s, y1s):
                for iz in range(nz):
                    r = iz * ny + iy
                    base = r * nx
                    for kk in range(ks.shape[0]):
                        k = ks[kk]
                        lo, hi, shift = _neighbour_row(r, ny, nz, nx, offs[k, 0], offs[k, 1], offs[k, 2])
                        bit = np.uint64(1) << np.uint64(k & 63)
                        bits = broken[k >> 6]
                        x0, x1, x2, L, wk = xi[k, 0], xi[k, 1], xi[k, 2], length[k], weight[k]
                        for c0 in range(lo, hi, CHUNK):
                            m = min(CHUNK, hi - c0)
                            i0 = base + c0
                            j0 = i0 + shift
                            vq = vol[j0 : j0 + m]
                            vp = vol[i0 : i0 + m]
                            _bond_terms(cf, u, i0, j0, m, x0, x1, x2, L, bits[i0 : i0 + m], bit, vq, buf)
                            pi = p[i0 : i0 + m]
                            pj = p[j0 : j0 + m]
                            ai = alpha[i0 : i0 + m]
                            aj = alpha[j0 : j0 + m]
                            for q in range(m):
                                e = buf[5 * CHUNK + q]
                                t = (wk * L * (pi[q] + pj[q]) + wk * (ai[q] + aj[q]) * e) / buf[4 * CHUNK + q]
                                buf[q] = t if buf[q] > zero else zero
                            g0 = grid_f[0, i0 : i0 + m]
                            g1 = grid_f[1, i0 : i0 + m]
                            g2 = grid_f[2, i0 : i0 + m]
                            for q in range(m):
                                s = buf[q] * vq[q]
                                g0[q] += s * buf[CHUNK + q]
                                g1[q] += s * buf[2 * CHUNK + q]
                                g2[q] += s * buf[3 * CHUNK + q]
                            h0 = grid_f[0, j0 : j0 + m]
                            h1 = grid_f[1, j0 : j0 + m]
                            h2 = grid_f[2, j0 : j0 + m]
                            for q in range(m):
                                s = buf[q] * vp[q]
                                h0[q] -= s * buf[CHUNK + q]
                                h1[q] -= s * buf[2 * CHUNK + q]
                                h2[q] -= s * buf[3 * CHUNK + q]
            w0, w1 = _after(colour, h, width, ny)
            _write_planes(grid_f, w0, w1, shape, point_of, f)
    return f


def calls(model, u):
    """(full, half) zero-argument force calls of the lattice ``model`` at ``u`` (n_points, 3),
    kernels only: the grid displacement is scattered once here."""
    lat, s = model.lattice, model.lattice.stencil
    ug = model._scatter(u).copy()
    ks = half_stencil(s.offsets)
    width = max(1, int(np.abs(s.offsets[:, 1]).max()))
    grid_f = np.empty((3, lat.n_grid), dtype=model.dtype)
    out = {key: np.empty_like(model.x) for key in ("full", "half")}
    head = (ug, model._vol, lat.broken, lat.shape, s.offsets)
    if model.name == "pmb":
        table = (model._xi, model._length, model._inv_len, model._coef, model._cf)

        def full():
            return lattice_pmb_force(*head, *table, model._point_of, out["full"])

        def half():
            return half_pmb_force(*head, ks, *table, width, grid_f, model._point_of, out["half"])

        return full, half
    table = (model._xi, model._length, model._weight, model._cf)
    theta = {key: np.empty(lat.n_grid, dtype=model.dtype) for key in ("full", "half")}

    def full():
        p = lattice_lps_dilatation(*head, *table, model._theta_coef, theta["full"])
        np.multiply(p, model._p_coef, out=p)
        return lattice_lps_force(*head, *table, model._alpha, p, model._point_of, out["full"])

    def half():
        p = half_lps_dilatation(*head, ks, *table, width, model._theta_coef, theta["half"])
        np.multiply(p, model._p_coef, out=p)
        return half_lps_force(*head, ks, *table, width, model._alpha, p, grid_f, model._point_of, out["half"])

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
