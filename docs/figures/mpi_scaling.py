"""The scaling model of docs/mpi.md: checked against the measured runs, projected to large runs.

    PYTHONPATH=src python docs/figures/mpi_scaling.py [benchmarks/bench_mpi.json]

reads the runs of ``benchmarks/bench_mpi.py`` and prints two Markdown tables (the model against
the measured 2- and 3-rank runs; time per step and memory per rank for 1e7, 1e8 and 1e9 points
on 16 to 1024 ranks), then draws ``docs/figures/mpi_scaling.png``.

One explicit step on P ranks of one thread each takes

    t(P) = t_bond B_r + t_point N_r + t_root + t_halo + t_gather

- ``t_bond``: seconds per directed bond of the force on one thread, and ``t_point`` seconds per
  point of the rest of the step (integration, loads), from the serial step's parts measured on
  one thread (``peridyn bench --case``: force / B, rest / N); B_r and N_r the largest rank's
  share (owned points, bonds in proportion), times P / C when the P ranks outnumber the C
  cores (3 ranks on this machine's 2 cores), over the efficiency e of a core when they all work
  (e = t(1 x 1) / (C t(1 x C)), the 1-rank runs on one and on C threads; ``core_efficiency``:
  what the one-thread coefficients miss in a whole step on all cores, the threaded run's serial
  parts included; not the cores' sharing alone, which ``benchmarks/core_sharing.py`` measures);
- ``t_root``: the recorder's time per step (observers), on rank 0 alone, not divided (the other
  ranks wait for its outcome: ``benchmarks/mpi_wait_trace.py``);
- ``t_halo = m alpha + s / beta``: the largest rank's counted messages m and bytes s per step,
  with the latency alpha and bandwidth beta of ``benchmarks/mpi_pingpong.py``;
- ``t_gather``: a series record checks the state (an allgather: ``2 log2(P) alpha``), gathers
  u at the recorder's k probe points (24 B each, ``probe_points`` of the record; the other
  ranks own ``k (N - N_0) / N`` of them) on rank 0 and broadcasts rank 0's outcome
  (``log2(P) alpha``): ``(P - 1 + 3 log2(P)) alpha + 24 k (N - N_0) / (N beta)``; the
  sensors' velocities and the whole state at the few snapshots are left out.

Projections (no recording of whole fields per step: sensors only, so no ``t_root`` nor
``t_gather``): a cube of N points, horizon 3.015 spacings (122 bonds per point), LPS, parts
that are cubes of n = N / P points with a ghost shell two search reaches thick (6 spacings):
g = (n^(1/3) + 12)^3 - n ghosts, 26 neighbour ranks, 24 bytes per ghost per step, and the LPS
dilatation of every ghost at half the force's cost per bond (an estimate); the latency
and bandwidth of a cluster interconnect (``CLUSTER``, stated, not measured here) and this
machine's t_bond and t_point per core measured quietly (``QUIET``); plus the state check's
allgather every 10 steps (2 log2(P) alpha / 10). Memory per rank: ``peridyn.setup.estimate``'s
explicit costs (300 MB base, 350 B per point, 116 B per directed bond) on the rank's owned and
ghost points, plus the whole body that every rank builds today (``WHOLE_BODY_BYTES`` per point
of the whole body).
"""

from __future__ import annotations

import json
import math
import sys
from pathlib import Path

import numpy as np

from peridyn.setup.estimate import BASE_BYTES, COSTS

HERE = Path(__file__).resolve().parent
ROOT = HERE.parents[1]

#: a cluster interconnect (100 Gb/s InfiniBand class): latency, s, and bandwidth, bytes/s
CLUSTER = {"latency_s": 1.5e-6, "bandwidth_bytes_per_s": 12.5e9}
#: bonds per point of a 3D grid with horizon 3.015 spacings (lattice vectors of length <= 3.015)
BONDS_PER_POINT = 122
#: thickness of the ghost shell in spacings: two layers of the search reach (3.015 spacings)
SHELL = 6
#: bytes per point of the whole body that every rank holds today (``setup/build.py``
#: ``_build_part`` builds the whole point cloud, then its part), counted: the body (points,
#: volumes, cells, sets: 64 B, as ``peridyn.setup.estimate`` counts it), the partition (8 B) and
#: the ghost search's k-d tree on every point (a copy of the points and an index: 32 B), and the
#: whole loading's per-point flags (about 6 B)
WHOLE_BODY_BYTES = 110.0
#: compute coefficients of the projections, per thread, from the quiet-machine measurement of
#: the Lamb plate case (benchmarks/HISTORY.md, "Whole explicit steps against the force kernel",
#: load 5: force 54.9 ms and rest 4.1 ms per step on 2 threads, 9 322 368 bonds, 125 250
#: points): the runs of bench_mpi.py so far met loads of 12-25, which inflate them 2-4x
QUIET = {"t_bond": 54.9e-3 * 2 / 9_322_368, "t_point": 4.1e-3 * 2 / 125_250}
RANKS = (16, 64, 256, 1024)
SIZES = (1e7, 1e8, 1e9)


def load(path: Path) -> dict:
    return json.loads(path.read_text())


def coefficients(record: dict) -> dict:
    """t_bond and t_point (s), t_root (s per step) from the serial parts; alpha, beta."""
    base = next(r for r in record["runs"] if r["ranks"] == 1 and r["threads"] == 1)
    parts = record["serial_parts"]["seconds_per_step"]
    return {
        "t_bond": parts["force"] / base["bonds"],
        "t_point": parts["rest"] / base["points"],
        "t_root": parts["observers"],
        "alpha": record["pingpong"]["latency_s"],
        "beta": record["pingpong"]["bandwidth_bytes_per_s"],
        "points": base["points"],
        "cpus": record["cpus"],
        "bonds": base["bonds"],
        "probe_points": record["probe_points"],
        "core_efficiency": core_efficiency(record["runs"]),
    }


def core_efficiency(runs: list[dict]) -> float:
    """How much of its one-core speed each core keeps in a whole step when all of them work at
    once: the 1-rank step on one thread over the threads x the 1-rank step on all the machine's
    threads (1.0 without such a run)."""
    one = next(r for r in runs if r["ranks"] == 1 and r["threads"] == 1)
    many = [r for r in runs if r["ranks"] == 1 and r["threads"] > 1]
    if not many:
        return 1.0
    best = max(many, key=lambda r: r["threads"])
    return one["step_seconds"] / (best["threads"] * best["step_seconds"])


def predicted_step(c: dict, run: dict) -> dict:
    """The model's seconds per step of a measured MPI run, by term."""
    per_rank = run["per_rank"]
    owned = [r["owned"] for r in per_rank]
    n_r = max(owned)
    ranks = run["ranks"]
    halo = max(r["messages_per_step"] * c["alpha"] + r["bytes_per_step"] / c["beta"] for r in per_rank)
    messages = ranks - 1 + 3 * math.log2(ranks)
    others = c["probe_points"] * (c["points"] - owned[0]) / c["points"]
    gather = messages * c["alpha"] + 24.0 * others / c["beta"]
    shared = max(1.0, ranks / c["cpus"])  # more ranks than cores: each gets cpus / ranks of one
    shared /= c["core_efficiency"]  # several cores at work: each slower in a whole step
    terms = {
        "compute": shared * (c["t_bond"] * c["bonds"] * n_r / c["points"] + c["t_point"] * n_r),
        "root": c["t_root"],
        "halo": halo,
        "gather": gather,
    }
    terms["total"] = sum(terms.values())
    return terms


def part_bytes(local_points: float, bonds_per_point: float) -> float:
    """Peak bytes of a rank's part of ``local_points`` (owned and ghosts), the explicit costs of
    ``peridyn.setup.estimate`` (which hold within 3 % of the measured serial Lamb runs)."""
    costs = COSTS["explicit"]
    return BASE_BYTES + (costs.per_point + costs.per_bond * bonds_per_point) * local_points


def rank_bytes(run: dict) -> list[float]:
    """The model's peak bytes of each rank of a measured run: its part and the whole body."""
    bonds_per_point = run["bonds"] / run["points"]
    if run["ranks"] == 1:
        return [part_bytes(run["points"], bonds_per_point)]
    return [
        part_bytes(r["owned"] + r["ghosts"], bonds_per_point) + WHOLE_BODY_BYTES * run["points"]
        for r in run["per_rank"]
    ]


def projected(c: dict, points: float, ranks: int, cluster=CLUSTER) -> dict:
    """Seconds per step (compute, halo, collectives) and bytes per rank of a cube of ``points``."""
    n = points / ranks
    side = n ** (1.0 / 3.0)
    ghosts = (side + 2 * SHELL) ** 3 - n
    alpha, beta = cluster["latency_s"], cluster["bandwidth_bytes_per_s"]
    # the owned points' force, and the LPS dilatation of the ghosts (read by the boundary
    # points' force; estimated at half the force's cost per bond, an upper bound: the outer
    # ghosts' families are partial)
    compute = c["t_bond"] * BONDS_PER_POINT * (n + 0.5 * ghosts) + c["t_point"] * n
    halo = 26 * alpha + 24.0 * ghosts / beta
    collectives = 2 * math.log2(ranks) * alpha / 10
    part = part_bytes(n + ghosts, BONDS_PER_POINT)
    whole = WHOLE_BODY_BYTES * points
    return {
        "compute": compute,
        "halo": halo,
        "collectives": collectives,
        "step": compute + halo + collectives,
        "halo_share": halo / (compute + halo + collectives),
        "part_bytes": part,
        "whole_bytes": whole,
        "bytes": part + whole,
    }


def check_table(record: dict, c: dict) -> str:
    lines = [
        "| ranks | measured ms/step | model ms/step (compute + root + halo + gather) | model / measured "
        "| measured peak MiB/rank | model MiB/rank |",
        "|---|---|---|---|---|---|",
    ]
    for run in record["runs"]:
        if run["threads"] != 1:
            continue
        measured = run["step_seconds"] / run["steps"]
        if run["ranks"] == 1:
            model = c["t_bond"] * c["bonds"] + c["t_point"] * c["points"] + c["t_root"]
            detail = f"{1e3 * model:.1f}"
        else:
            t = predicted_step(c, run)
            model = t["total"]
            detail = (
                f"{1e3 * model:.1f} ({1e3 * t['compute']:.1f} + {1e3 * t['root']:.1f} + "
                f"{1e3 * t['halo']:.2f} + {1e3 * t['gather']:.2f})"
            )
        peaks = "/".join(f"{b / 2**20:.0f}" for b in run["peak_memory_bytes"])
        memory = "/".join(f"{b / 2**20:.0f}" for b in rank_bytes(run))
        ratio = model / measured
        lines.append(
            f"| {run['ranks']} | {1e3 * measured:.1f} | {detail} | {ratio:.2f} | {peaks} | {memory} |"
        )
    return "\n".join(lines)


def projection_table(c: dict) -> str:
    lines = [
        "| points | ranks | ms/step | halo share | GB/rank (part) | GB/rank (+ whole body) |",
        "|---|---|---|---|---|---|",
    ]
    for points in SIZES:
        for ranks in RANKS:
            p = projected(c, points, ranks)
            lines.append(
                f"| {points:.0e} | {ranks} | {1e3 * p['step']:.3g} | {p['halo_share']:.3f} "
                f"| {p['part_bytes'] / 1e9:.3g} | {p['bytes'] / 1e9:.3g} |"
            )
    return "\n".join(lines)


def draw(c: dict, path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    ranks = np.array([16, 32, 64, 128, 256, 512, 1024])
    fig, (ax_t, ax_m) = plt.subplots(1, 2, figsize=(10, 4))
    for points, colour in zip(SIZES, ("C0", "C1", "C2"), strict=True):
        rows = [projected(c, points, int(r)) for r in ranks]
        ax_t.loglog(ranks, [1e3 * p["step"] for p in rows], "-o", color=colour, label=f"{points:.0e} points")
        ax_t.loglog(ranks, [1e3 * p["halo"] for p in rows], ":", color=colour)
        ax_m.loglog(ranks, [p["part_bytes"] / 1e9 for p in rows], "-o", color=colour, label=f"{points:.0e}")
        ax_m.loglog(ranks, [p["bytes"] / 1e9 for p in rows], "--", color=colour)
    ax_t.set_xlabel("ranks (one thread each)")
    ax_t.set_ylabel("time per step, ms (dotted: halo exchange)")
    ax_t.legend()
    ax_t.grid(True, which="both", alpha=0.3)
    ax_m.set_xlabel("ranks")
    ax_m.set_ylabel("memory per rank, GB (dashed: + whole body)")
    ax_m.axhline(4.0, color="k", lw=0.8)
    ax_m.text(17, 4.4, "4 GB per core", fontsize=8)
    ax_m.legend(title="points")
    ax_m.grid(True, which="both", alpha=0.3)
    fig.suptitle("peridyn explicit LPS step under MPI: model (docs/mpi.md)")
    fig.tight_layout()
    fig.savefig(path, dpi=110)


def main(argv: list[str]) -> int:
    record = load(Path(argv[0]) if argv else ROOT / "benchmarks" / "bench_mpi.json")
    c = coefficients(record)
    print(
        f"t_bond {c['t_bond'] * 1e9:.2f} ns, t_point {c['t_point'] * 1e9:.1f} ns, t_root "
        f"{c['t_root'] * 1e3:.2f} ms, alpha {c['alpha'] * 1e6:.1f} us, beta {c['beta'] / 1e9:.2f} GB/s, "
        f"core efficiency {c['core_efficiency']:.2f}"
    )
    print(check_table(record, c))
    print()
    print(projection_table(QUIET))
    draw(QUIET, HERE / "mpi_scaling.png")
    return 0


if __name__ == "__main__":
    raise SystemExit(main(sys.argv[1:]))
