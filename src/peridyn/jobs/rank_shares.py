"""How many points each MPI rank of an explicit run gets: rank 0 also records, so it gets fewer.

At every recorded step rank 0 receives the probe values of every rank and writes them
(``parallel.observers``, ``io.recorder``) while the other ranks wait for it at the next
collective. With that work worth ``E`` points of force computation (the values it records a
step times ``RECORD_COST_BONDS``, over the bonds a point has), the step is balanced when rank 0
holds ``N / P - E (P - 1) / P`` of the ``N`` points and each other rank ``N / P + E / P``: all
then finish a step together. Rank 0 keeps at least ``MIN_ROOT_SHARE`` of an equal share.
Static and modal runs record once, at the end: equal shares.
"""

from __future__ import annotations

import numpy as np
from scipy.spatial import cKDTree

from peridyn.discretization.body import Body
from peridyn.io.case import Case

#: Bond updates of the force (one thread) worth the recording of one value by rank 0: on the
#: seed Lamb plate on 2 ranks (2026-11-28, AMD EPYC, ``benchmarks/bench_mpi.py``) rank 0 spent
#: 1.47 ms a step recording 126 000 values (the top plane, a line, sensors: 11.7 ns a value)
#: while a thread updates a bond in 5.87 ns (the fused LPS force).
RECORD_COST_BONDS = 2.0

#: Smallest share of rank 0, as a fraction of an equal share.
MIN_ROOT_SHARE = 0.25

#: Points sampled to count the bonds a point has (every k-th point of the body).
BOND_SAMPLE = 2000


def rank_shares(case: Case, body: Body, n_ranks: int, reach: float) -> np.ndarray | None:
    """(n_ranks,) relative shares of the points for ``parallel.partition.rcb``, or None (equal)
    for one rank or a run that records nothing at each step. ``reach``: the bond search
    distance (m), to count the bonds a point has on a sample of the body."""
    if n_ranks == 1 or case.solver.type not in ("explicit", "newmark"):
        return None
    n = body.n_points
    equivalent = recorded_values_per_step(case, body) * RECORD_COST_BONDS / bonds_per_point(body, reach)
    root = max(n / n_ranks - equivalent * (n_ranks - 1) / n_ranks, MIN_ROOT_SHARE * n / n_ranks)
    others = (n - root) / (n_ranks - 1)
    return np.array([root] + [others] * (n_ranks - 1))


def recorded_values_per_step(case: Case, body: Body) -> float:
    """Values rank 0 records a step, on average: u of the line and plane points and of the
    sensors, v of the sensors (3 each), every ``output.every`` steps, and the whole body's u at
    every ``output.snapshot_every``-th step."""
    out = case.output
    points = sum(line.points for line in out.lines.values())
    points += sum(len(body.node_set(name)) for name in out.planes.values())
    values = 3.0 * (points + 2 * len(out.sensors)) / out.every
    if out.snapshot_every:
        values += 3.0 * body.n_points / out.snapshot_every
    return values


def bonds_per_point(body: Body, reach: float) -> float:
    """Mean neighbours within ``reach`` (m) of every k-th point (about ``BOND_SAMPLE`` points),
    at least 1."""
    sample = body.points[:: max(1, body.n_points // BOND_SAMPLE)]
    counts = cKDTree(body.points).query_ball_point(sample, reach, return_length=True)
    return max(1.0, float(np.mean(counts)) - 1.0)
