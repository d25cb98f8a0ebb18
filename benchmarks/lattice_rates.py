"""Lattice against bond-list force rates, interleaved in one process, on the bench cube and a case.

For each material (PMB, LPS) and dtype (float64, float32): the model on bond lists
(``make_model``) and on lattice storage (``make_lattice_model``) of the same body, each
``model.force(u, out)`` as the explicit solver calls it (the lattice's scatter of u to the grid
included), timed in turn round after round; a row's time is its best round. Printed per row:
both rates (M directed bonds/s of the bond list), lattice / bond-list ratio of the best times and
the median of the rounds' ratios, and the largest force difference relative to the largest force.
The bodies:

- ``cube``: ``peridyn bench``'s cube (``jobs.bench.benchmark_grid``, ``--side`` points a side,
  no surface correction), the rows of ``peridyn bench --storage lattice``;
- ``case``: the body of a case file (default the Lamb plate, ``cases/lamb_plate.yaml``), its
  horizon, influence function and partial volumes; LPS with the case's surface correction, PMB
  without one (the only one PMB has on a lattice), the case's E and density (PMB's own Poisson
  ratio).

Each thread count of ``--threads`` (``numba.set_num_threads``) is one interleaved pass. Results in
HISTORY.md ("Lattice against bond-list force rates on the bench cube and the Lamb plate").

    PYTHONPATH=src python benchmarks/lattice_rates.py --body cube --threads 1 2
    PYTHONPATH=src python benchmarks/lattice_rates.py --body case --threads 1 2
"""

from __future__ import annotations

import argparse
import os
import time
from pathlib import Path

import numba
import numpy as np

from peridyn.discretization.lattice import build_lattice
from peridyn.io.case import load_case
from peridyn.jobs.bench import DEFAULT_POINTS_PER_SIDE, HORIZON_FACTOR, SPACING, benchmark_grid
from peridyn.physics.materials import make_model
from peridyn.physics.materials.lattice import make_lattice_model
from peridyn.setup.build import build_body, build_bonds, case_horizon

E, NU, DENSITY = 200e9, 0.25, 7850.0  # the bench cube's steel (as ``jobs.bench``)
ROWS = (("pmb", "float64"), ("lps", "float64"), ("pmb", "float32"), ("lps", "float32"))


def cube_models(side: int):
    """{(material, dtype, storage): model} on the bench cube, and its directed bonds."""
    body, bonds = benchmark_grid(side)
    lattice = build_lattice(body, HORIZON_FACTOR * SPACING, partial_volumes=False)
    models = {}
    for name, dtype in ROWS:
        params = dict(E=E, nu=NU, density=DENSITY, dtype=np.dtype(dtype))
        models[name, dtype, "bonds"] = make_model(name, body, bonds, **params)
        models[name, dtype, "lattice"] = make_lattice_model(name, body, lattice, **params)
    return models, bonds.n_bonds


def case_models(path: str):
    """{(material, dtype, storage): model} on the body of the case ``path``, and its directed bonds."""
    case = load_case(path, ["discretization.storage=bonds"])
    body = build_body(case, Path(path).parent)
    bonds = build_bonds(case, body)
    d, mat = case.discretization, case.material
    lattice = build_lattice(body, case_horizon(case, body), d.influence, d.partial_volumes)
    models = {}
    for name, dtype in ROWS:
        params = dict(E=mat.E, density=mat.density, dtype=np.dtype(dtype))
        if name == "lps":
            params.update(nu=mat.nu, surface_correction=mat.surface_correction)
        models[name, dtype, "bonds"] = make_model(name, body, bonds, **params)
        models[name, dtype, "lattice"] = make_lattice_model(name, body, lattice, **params)
    return models, bonds.n_bonds


def interleaved(models: dict, n_bonds: int, rounds: int, seed: int = 0) -> list[str]:
    """One line per (material, dtype): both storages' ``force`` timed in turn for ``rounds``
    rounds at one random displacement (1e-4 of the shortest reference bond)."""
    x = next(iter(models.values())).body.points
    shortest = min(m.lattice.stencil.length.min() for m in models.values() if hasattr(m, "lattice"))
    u64 = 1e-4 * shortest * np.random.default_rng(seed).standard_normal(x.shape)
    calls, forces = {}, {}
    for key, model in models.items():
        u = np.ascontiguousarray(u64, dtype=model.dtype)
        out = np.empty_like(model.x)
        calls[key] = lambda model=model, u=u, out=out: model.force(u, out)
        forces[key] = calls[key]().astype(np.float64)  # warm-up (compilation or cache load)
    times = {key: np.empty(rounds) for key in calls}
    for r in range(rounds):
        for key, call in calls.items():
            t0 = time.perf_counter()
            call()
            times[key][r] = time.perf_counter() - t0
    lines = []
    for name, dtype in ROWS:
        tb, tl = times[name, dtype, "bonds"], times[name, dtype, "lattice"]
        fb, fl = forces[name, dtype, "bonds"], forces[name, dtype, "lattice"]
        rel = np.max(np.abs(fl - fb)) / np.max(np.abs(fb))
        lines.append(
            f"{name} {dtype}: bonds {n_bonds / tb.min() / 1e6:6.1f} M/s, lattice "
            f"{n_bonds / tl.min() / 1e6:6.1f} M/s; lattice / bonds {tb.min() / tl.min():.2f}x "
            f"(median of the rounds {np.median(tb / tl):.2f}x); max |df| / max |f| {rel:.1e}"
        )
    return lines


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--body", choices=("cube", "case"), default="cube")
    parser.add_argument("--side", type=int, default=DEFAULT_POINTS_PER_SIDE, help="cube: points a side")
    parser.add_argument("--case", default="cases/lamb_plate.yaml", help="case: the case file")
    parser.add_argument("--rounds", type=int, default=10)
    parser.add_argument("--threads", type=int, nargs="+", default=[numba.get_num_threads()])
    args = parser.parse_args(argv)
    models, n_bonds = cube_models(args.side) if args.body == "cube" else case_models(args.case)
    n_points = next(iter(models.values())).body.n_points
    what = f"{args.side}^3 cube" if args.body == "cube" else args.case
    for threads in args.threads:
        numba.set_num_threads(threads)
        load = os.getloadavg()[0]
        print(f"{what}: {n_points} points, {n_bonds} directed bonds, {threads} threads, load {load:.2f}")
        for line in interleaved(models, n_bonds, args.rounds):
            print("  " + line, flush=True)
    print(f"load {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()
