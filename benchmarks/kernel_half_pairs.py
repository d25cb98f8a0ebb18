"""Issue 22 item 1: the PMB float64 force with each bond pair computed once (the half list,
``kernels.pmb.pmb_pair_force``) against the full list, A/B interleaved in one process.

Rows (each through ``kernel_candidates.compare``: the before / candidate ratio of the best wall
and CPU times, and the largest force difference):

- ``pmb_force`` in one chain per family (the order up to stop 24) / the same kernel in the
  row-block order (``discretization.pairs``: two chains per family; what MPI ranks and bodies
  with too few row blocks run);
- the block order / the half list (``PMBModel.force``): the same bits, ``max |df|`` 0;
- one chain / the half list: the speed-up of ``peridyn bench``'s PMB float64 row.

With and without 5 % of the bonds broken (in both directions). Results in HISTORY.md, "Each bond pair
once: the PMB float64 half list; ..." (2026-11-28); the current figures in RESULTS.md.

    PYTHONPATH=src python benchmarks/kernel_half_pairs.py --side 49 --rounds 15
"""

from __future__ import annotations

import argparse
import os

import numba
import numpy as np
from kernel_candidates import compare

from peridyn.jobs.bench import DEFAULT_POINTS_PER_SIDE, SPACING, benchmark_grid
from peridyn.kernels.pmb import pmb_force
from peridyn.physics.materials import make_model

E, DENSITY = 200e9, 7850.0


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--side", type=int, default=DEFAULT_POINTS_PER_SIDE)
    parser.add_argument("--rounds", type=int, default=15)
    parser.add_argument(
        "--broken", type=float, default=0.05, help="share of the bonds broken (both directions)"
    )
    args = parser.parse_args(argv)
    body, b = benchmark_grid(args.side)
    rng = np.random.default_rng(0)
    u = 1e-4 * SPACING * rng.standard_normal(body.points.shape)
    model = make_model("pmb", body, b, E=E, density=DENSITY)
    assert model.runs_half_list(), "too few row blocks for the half list on this many threads"
    xi = model.bond_vectors
    out = {key: np.empty_like(model.x) for key in "ab"}
    per_bond = (b.offsets, b.neighbours, model.inv_length, model.bond_stiffness, b.intact)
    print(
        f"{args.side}^3 grid, {b.n_bonds} bonds, {len(model._pairs.blocks) - 1} row blocks, "
        f"{numba.get_num_threads()} threads, load {os.getloadavg()[0]:.2f}"
    )

    def one_chain():
        return pmb_force(xi, u, *per_bond, out["a"])

    def block_order(key):
        return lambda: pmb_force(xi, u, *per_bond, out[key], 0, -1, model._split)

    def half_list():
        return model.force(u, out["b"])

    for broken in (0.0, args.broken):
        b.intact[:] = True
        cut = rng.random(b.n_bonds) < broken / 2
        b.intact[cut | cut[b.reverse()]] = False
        tag = f"{np.count_nonzero(~b.intact) / b.n_bonds:.0%} broken"
        for name, before, cand in (
            (f"one chain / block order ({tag})", one_chain, block_order("b")),
            (f"block order / half list ({tag})", block_order("a"), half_list),
            (f"one chain / half list ({tag})", one_chain, half_list),
        ):
            print(compare(name, before, cand, b.n_bonds, args.rounds), flush=True)
    print(f"load {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()
