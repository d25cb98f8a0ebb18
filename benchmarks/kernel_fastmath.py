"""The force kernels' fast-math flags, A/B in one process: today's ``peridyn.kernels.FASTMATH``
(no signed zeros only) against the earlier set that also let LLVM fuse multiply-adds and use
reciprocals (``{"contract", "nsz", "arcp"}``).

Each top-level force kernel that the PMB and LPS models call is compiled a second time from its
Python source with the earlier flags (helpers inlined into it take its flags; the exact helpers
keep theirs), and each model's ``force`` is timed with either set of kernels swapped into its
module, the two interleaved round by round on the bench grid; best of ``--rounds``, and the
largest force difference relative to the largest force (the earlier flags round differently).

    PYTHONPATH=src python benchmarks/kernel_fastmath.py --rounds 10

Results in benchmarks/RESULTS.md ("Force kernels").
"""

from __future__ import annotations

import argparse
import time

import numba
import numpy as np

import peridyn.physics.materials.lps as lps_module
import peridyn.physics.materials.pmb as pmb_module
from peridyn.jobs.bench import ROWS, benchmark_grid
from peridyn.kernels import FASTMATH
from peridyn.physics.materials import make_model

EARLIER = {"contract", "nsz", "arcp"}
KERNELS = {
    pmb_module: ("pmb_force", "pmb_force_cf", "pmb_pair_force"),
    lps_module: (
        "lps_dilatation",
        "lps_dilatation_cf",
        "lps_force_fused",
        "lps_pair_force",
        "lps_pair_force_cf",
    ),
}
E, NU, DENSITY = 200e9, 0.25, 7850.0


def recompiled(dispatcher, flags):
    """``dispatcher``'s Python function compiled again with the fast-math ``flags``."""
    options = {**dispatcher.targetoptions, "fastmath": flags}
    for key in ("cache", "nopython"):
        options.pop(key, None)
    return numba.njit(**options)(dispatcher.py_func)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--side", type=int, default=40, help="grid points per side (default 40)")
    parser.add_argument("--rounds", type=int, default=10)
    args = parser.parse_args()
    sets = {
        "today": {m: {n: getattr(m, n) for n in names} for m, names in KERNELS.items()},
        "earlier": {
            m: {n: recompiled(getattr(m, n), EARLIER) for n in names} for m, names in KERNELS.items()
        },
    }
    body, bonds = benchmark_grid(args.side)
    rng = np.random.default_rng(0)
    u = 1e-6 * rng.standard_normal((body.n_points, 3))
    print(f"{body.n_points} points, {bonds.n_bonds} directed bonds; today's flags {sorted(FASTMATH)}")
    print("| model | dtype | earlier / today time | max |df| / max |f| |")
    print("|---|---|---:|---:|")
    for name, dtype in ROWS:
        if name == "pmb-baseline":
            continue
        nu = NU if name == "lps" else None
        model = make_model(name, body, bonds, E=E, nu=nu, density=DENSITY, dtype=dtype)
        uu = u.astype(dtype)
        best, force = {}, {}
        for key, kernels in sets.items():  # warm up (compiles)
            for module, table in kernels.items():
                for n, k in table.items():
                    setattr(module, n, k)
            force[key] = np.array(model.force(uu), dtype=np.float64)
            best[key] = np.inf
        for _ in range(args.rounds):
            for key, kernels in sets.items():
                for module, table in kernels.items():
                    for n, k in table.items():
                        setattr(module, n, k)
                t0 = time.perf_counter()
                model.force(uu)
                best[key] = min(best[key], time.perf_counter() - t0)
        for module, table in sets["today"].items():
            for n, k in table.items():
                setattr(module, n, k)
        diff = np.max(np.abs(force["earlier"] - force["today"])) / np.max(np.abs(force["today"]))
        print(f"| {name} | {dtype} | {best['earlier'] / best['today']:.3f} | {diff:.1e} |")


if __name__ == "__main__":
    main()
