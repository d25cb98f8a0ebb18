"""Force-kernel throughput: what ``peridyn bench`` and ``benchmarks/bench_kernels.py`` measure.

The grid is a cube of ``points_per_side**3`` points (``geometry.box``), spacing 1 mm,
horizon 3.015 spacings, constant influence function; by default **without** partial
volumes (every neighbour with |xi| <= delta is a full-volume bond: 122 neighbours in
the bulk, 11.0 M directed bonds for the default 46^3 = 97,336 points), with
``partial_volumes=True`` with them (more, fractional neighbours: 19.4 M bonds).

Each row times one explicit-step internal-force evaluation over all directed bonds
and reports ``bond_updates_per_s`` = directed bonds / seconds (for LPS, both of its
passes count as one update of each bond):

- ``pmb-baseline`` float64: ``kernels.pmb.pmb_force_baseline``, the straightforward
  loop (reference row, ``speedup_vs_baseline`` = 1);
- ``pmb`` and ``lps`` in float64 and float32, through ``model.force(u, out)``, i.e. what
  the solvers run;
- with ``--storage lattice``, ``pmb-lattice`` and ``lps-lattice``: the same models on lattice
  storage (``discretization.lattice``; their ``force`` includes scattering u to the grid and
  gathering f back), which compute each bond pair once and stream its broken bit once a pass
  (1/16 B a bond update and pass; half a pair's square roots and divisions a bond update).

Timing: every row is called once first (JIT compilation or cache load, excluded); then
``repeat`` rounds each call every row once, in turn, and a row's time is its best
round. Interleaving the rows makes their ratios robust to a machine whose load drifts.
The result records ``omp_proc_bind``, the ``OMP_PROC_BIND`` of the process's environment
(``None``: numba's threads unbound). On the 2-core VM of ``benchmarks/HISTORY.md`` ("Chunks of
32, slow processes, ...") about one process in ten ran the kernels at 0.8 of the others' rate for
its whole life, bound or not (see the user guide's "Threads"): compare rows within one result, or
results of several processes.

Memory bandwidth: a STREAM-like triad ``a[:] = b + s c`` (numba ``prange``, float64
arrays of ``triad_elements`` items, 128 MiB each by default, far beyond any L3),
counted as STREAM does, 24 bytes per element (two reads, one write; the
write-allocate read is not counted), best of ``max(repeat, 5)`` runs.

``bytes_per_bond`` is what one bond update must stream from memory: the per-bond
arrays the kernel reads, summed over its passes (:func:`bytes_per_bond`):

- baseline: neighbour index (int32, 4) + reference length (8) + micromodulus (8) +
  intact flag (bool, 1) = 21;
- pmb float64: index 4 + reference bond vector 24 + 1/|xi| 8 + stiffness 8 + intact 1 = 45;
  with the half list (``PMBModel.runs_half_list``: each bond pair once, the row's
  ``half_list`` is true) a pair streams that and the reverse stiffness 8 for two bond
  updates: 26.5, and half a square root and half a division a bond update;
  pmb float32 (cancellation-free kernel, |xi| recomputed from the points): 4 + 4 + 1 = 9;
- lps float64: the dilatation pass (index 4 + bond vector 24 + length 8 + weight 8 +
  intact 1 = 45) and the force pass (the same + deviatoric coefficient 8 = 53) = 98;
  lps float32: (4 + weight 4 + intact 1) + (4 + 4 + deviatoric 4 + 1) = 22.

Not counted: the neighbours' coordinates, displacements and per-point coefficients
(gathered, but neighbours are close in index on a grid, so they come from cache), the
CSR offsets and the force written (per point, amortised over ~100 bonds).

Two roofs, each a bond-update rate that one resource alone would allow:

- memory roof = bandwidth / bytes_per_bond: streaming the per-bond arrays at the triad
  bandwidth; ``memory_roof_fraction`` = bond_updates_per_s / memory roof (1 would be
  memory bound);
- compute roof = 1 / (n_sqrt / sqrt rate + n_div / division rate): issuing the row's
  square roots and divisions per bond (:func:`ops_per_bond`; they share the divider
  unit on x86 cores, so their times add) at the packed throughput measured by the
  probes of ``kernels.roof`` (in-cache arrays, one row per numba thread, the row's
  dtype; best of ``max(repeat, 5)``); ``compute_roof_fraction`` = bond_updates_per_s /
  compute roof. The rest of a bond update (gathers, multiplies, adds) is not counted:
  the larger fraction says which of the two resources is closer to being the limit.
"""

from __future__ import annotations

import os
import time
from collections.abc import Callable

import numba
import numpy as np

from peridyn.discretization import geometry
from peridyn.discretization.bonds import find_bonds
from peridyn.discretization.lattice import build_lattice
from peridyn.errors import InputError
from peridyn.kernels.pmb import pmb_force_baseline
from peridyn.kernels.roof import div_probe, sqrt_probe
from peridyn.kernels.triad import triad
from peridyn.physics.materials import make_model
from peridyn.physics.materials.lattice import make_lattice_model

#: Default grid: 46^3 = 97,336 points.
DEFAULT_POINTS_PER_SIDE = 46
DEFAULT_POINTS = DEFAULT_POINTS_PER_SIDE**3
SPACING = 1e-3  # m
HORIZON_FACTOR = 3.015
#: Triad array length: 2^24 float64 = 128 MiB per array.
DEFAULT_TRIAD_ELEMENTS = 1 << 24
#: Rows in table order: (model, dtype).
ROWS = (
    ("pmb-baseline", "float64"),
    ("pmb", "float64"),
    ("pmb", "float32"),
    ("lps", "float64"),
    ("lps", "float32"),
)
#: Rows of lattice storage (``peridyn bench --storage lattice``, ``discretization.lattice``):
#: the same models and dtypes on a stencil and broken bits, timed with the rows above.
LATTICE_ROWS = (
    ("pmb-lattice", "float64"),
    ("pmb-lattice", "float32"),
    ("lps-lattice", "float64"),
    ("lps-lattice", "float32"),
)
#: Square roots and divisions per bond update of each row (both passes for LPS).
OPS_PER_BOND = {
    ("pmb-baseline", "float64"): (1, 2),  # |Y|; (r - L) / L and c s / r
    ("pmb", "float64"): (1, 1),  # 1 / |Y|
    ("pmb", "float32"): (2, 1),  # |Y|, |xi|; one division
    ("lps", "float64"): (2, 1),  # |Y| in each pass; one division in the force pass
    ("lps", "float32"): (4, 2),  # |Y|, |xi| and one division in each pass
    # the lattice kernels compute each pair once: half a pair's operations a bond update
    ("pmb-lattice", "float64"): (0.5, 0.5),  # 1 / |Y|
    ("pmb-lattice", "float32"): (0.5, 1),  # |Y|; e / (|Y| + |xi|) and 1 / |Y| (|xi| per offset)
    ("lps-lattice", "float64"): (1, 0.5),  # |Y| in each pass; one division in the force pass
    ("lps-lattice", "float32"): (1, 1.5),  # |Y| in each pass; e / (|Y| + |xi|) in each, / |Y| in the force
}
#: Compute probes: elements per row (in L1) and in-place iterations per call.
PROBE_ELEMENTS = 1024
PROBE_REPS = 4000
#: Steel-like constants of the benchmark material (do not affect the timings).
E, NU, DENSITY = 200e9, 0.25, 7850.0


def triad_bandwidth(elements: int = DEFAULT_TRIAD_ELEMENTS, repeat: int = 10) -> float:
    """Memory bandwidth (bytes/s) of the triad ``a = b + s c``, STREAM's count (24 B per element)."""
    b = np.full(elements, 1.0)
    c = np.full(elements, 2.0)
    a = np.zeros(elements)
    triad(a, b, c, 3.0)  # compile (or load) and touch the pages
    return 3 * a.itemsize * elements / best_seconds(lambda: triad(a, b, c, 3.0), repeat)


def op_rates(dtype: str, repeat: int = 5) -> tuple[float, float]:
    """Square roots and divisions per second in ``dtype`` on all numba threads (``kernels.roof``)."""
    # full-mantissa operands (see kernels.roof): a ramp over [1, 2) and c = 1.7
    start = np.linspace(1.0, 2.0, PROBE_ELEMENTS, endpoint=False, dtype=dtype)
    buf = np.tile(start, (numba.get_num_threads(), 1))
    c = buf.dtype.type(1.7)
    sqrt_probe(buf, c, 1)  # compile (or load)
    div_probe(buf, c, 1)
    count = buf.size * PROBE_REPS
    sqrt_rate = count / best_seconds(lambda: sqrt_probe(buf, c, PROBE_REPS), repeat)
    div_rate = count / best_seconds(lambda: div_probe(buf, c, PROBE_REPS), repeat)
    return sqrt_rate, div_rate


def ops_per_bond(model: str, dtype: str, half_list: bool = False) -> tuple[float, float]:
    """(square roots, divisions) one bond update of the row computes (see the module docstring);
    ``half_list``: the PMB float64 half list, one pair's for two bond updates."""
    if (model, dtype) not in OPS_PER_BOND:
        raise InputError(f"unknown benchmark row {model!r} {dtype}")
    n_sqrt, n_div = OPS_PER_BOND[model, dtype]
    return (n_sqrt / 2, n_div / 2) if half_list else (n_sqrt, n_div)


def best_seconds(call: Callable[[], object], repeat: int) -> float:
    """The shortest of ``max(1, repeat)`` timed calls of ``call``, s (warm it up first)."""
    best = np.inf
    for _ in range(max(1, repeat)):
        t0 = time.perf_counter()
        call()
        best = min(best, time.perf_counter() - t0)
    return best


def side_for(points: int) -> int:
    """Points per side of the cube closest to ``points`` points in total."""
    if points < 8:
        raise InputError(f"the benchmark grid needs at least 8 points (2 per side), got {points}")
    return max(2, round(points ** (1.0 / 3.0)))


def benchmark_grid(points_per_side: int = DEFAULT_POINTS_PER_SIDE, partial_volumes: bool = False):
    """The benchmark body and bonds: a cube, 1 mm spacing, horizon 3.015 spacings."""
    body = geometry.box((points_per_side * SPACING,) * 3, SPACING)
    bonds = find_bonds(body, HORIZON_FACTOR * SPACING, partial_volumes=partial_volumes)
    return body, bonds


def bytes_per_bond(model: str, dtype: str, half_list: bool = False) -> float:
    """Bytes of per-bond arrays one bond update streams (see the module docstring);
    ``half_list``: the PMB float64 half list."""
    index, flag = np.dtype(np.int32).itemsize, np.dtype(bool).itemsize
    real = np.dtype(dtype).itemsize
    vector = 3 * real if dtype == "float64" else 0  # the float64 kernels read stored bond vectors
    if model == "pmb-baseline":
        return index + 2 * real + flag  # neighbour, length, micromodulus, intact
    if model == "pmb":
        inverse_length = real if dtype == "float64" else 0  # float32 recomputes |xi| from the points
        full = index + vector + inverse_length + real + flag  # + stiffness
        return (full + real) / 2 if half_list else full  # + the reverse stiffness, per two updates
    if model.endswith("-lattice"):
        return (2 if model == "lps-lattice" else 1) / 16  # a pair's broken bit, per pass
    if model == "lps":
        length = real if dtype == "float64" else 0  # float32 recomputes |xi| from the points
        dilatation = index + vector + length + real + flag  # + weight
        return dilatation + (dilatation + real)  # the force pass also reads the deviatoric coefficient
    raise InputError(f"unknown benchmark row {model!r}")


def _row_callables(
    body, bonds, u64: np.ndarray, lattice=None
) -> tuple[dict[tuple[str, str], Callable[[], np.ndarray]], set]:
    """One zero-argument callable per row, each computing a full force evaluation, and the
    rows that run the PMB half list; with a ``lattice`` of the body, its rows too."""
    calls = {}
    models = {}
    for name, dtype in ROWS:
        if name == "pmb-baseline":
            continue
        models[name, dtype] = make_model(
            name, body, bonds, E=E, nu=NU, density=DENSITY, dtype=np.dtype(dtype)
        )
    for name, dtype in LATTICE_ROWS if lattice is not None else ():
        material = name.removesuffix("-lattice")
        models[name, dtype] = make_lattice_model(
            material, body, lattice, E=E, nu=NU, density=DENSITY, dtype=np.dtype(dtype)
        )
    # the baseline computes the PMB force with c = the PMB bond stiffness (k (1/|xi| - 1/|Y|) Y)
    c = models["pmb", "float64"].bond_stiffness.astype(np.float64)
    out64 = np.empty_like(body.points)

    def baseline():
        return pmb_force_baseline(
            body.points, u64, bonds.offsets, bonds.neighbours, bonds.length, c, bonds.intact, out64
        )

    calls["pmb-baseline", "float64"] = baseline
    for key, model in models.items():
        u = np.ascontiguousarray(u64, dtype=model.dtype)
        out = np.empty_like(model.x)
        calls[key] = lambda model=model, u=u, out=out: model.force(u, out)
    half = {key for key, model in models.items() if key[0] == "pmb" and model.runs_half_list()}
    return calls, half


def run_benchmark(
    points: int = DEFAULT_POINTS,
    repeat: int = 10,
    partial_volumes: bool = False,
    triad_elements: int = DEFAULT_TRIAD_ELEMENTS,
    seed: int = 0,
    log: Callable[[str], None] | None = None,
    lattice: bool = False,
) -> dict:
    """Measure every row and the triad bandwidth; returns the ``peridyn bench --json`` dict.

    Parameters
    ----------
    points : int
        Approximate number of grid points (rounded to a cube, see :func:`side_for`).
    repeat : int
        Timed rounds after the warm-up; each row keeps its best.
    partial_volumes : bool
        Build the bonds with partial volumes (default False: full-volume bonds).
    triad_elements : int
        Length of the triad arrays (keep it far beyond the L3 cache).
    seed : int
        Seed of the random displacement field (amplitude 1e-4 spacing).
    log : callable or None
        Receives progress messages (the CLI sends them to stderr).
    lattice : bool
        Also time the models on lattice storage (``LATTICE_ROWS``), interleaved with the others.
    """
    if repeat < 1:
        raise InputError(f"repeat must be at least 1, got {repeat}")
    say = log or (lambda msg: None)
    side = side_for(points)
    say(f"building a {side}^3 grid (partial volumes {'on' if partial_volumes else 'off'})")
    body, bonds = benchmark_grid(side, partial_volumes)
    rng = np.random.default_rng(seed)
    u64 = 1e-4 * SPACING * rng.standard_normal(body.points.shape)
    grid = build_lattice(body, HORIZON_FACTOR * SPACING, partial_volumes=partial_volumes) if lattice else None
    calls, half = _row_callables(body, bonds, u64, grid)
    rows = ROWS + (LATTICE_ROWS if lattice else ())
    say(f"{body.n_points} points, {bonds.n_bonds} directed bonds; warming up (JIT)")
    for call in calls.values():
        call()
    best = dict.fromkeys(calls, np.inf)
    for r in range(repeat):
        say(f"round {r + 1}/{repeat}")
        for key, call in calls.items():
            t0 = time.perf_counter()
            call()
            best[key] = min(best[key], time.perf_counter() - t0)
    say("triad bandwidth")
    bandwidth = triad_bandwidth(triad_elements, max(repeat, 5))
    say("square-root and division throughput")
    rates = {dtype: op_rates(dtype, max(repeat, 5)) for dtype in ("float64", "float32")}
    base_rate = bonds.n_bonds / best["pmb-baseline", "float64"]
    results = []
    for name, dtype in rows:
        rate = bonds.n_bonds / best[name, dtype]
        nbytes = bytes_per_bond(name, dtype, (name, dtype) in half)
        n_sqrt, n_div = ops_per_bond(name, dtype, (name, dtype) in half)
        sqrt_rate, div_rate = rates[dtype]
        memory_roof = bandwidth / nbytes
        compute_roof = 1.0 / (n_sqrt / sqrt_rate + n_div / div_rate)
        results.append(
            {
                "model": name,
                "dtype": dtype,
                "points": int(body.n_points),
                "bonds": int(bonds.n_bonds),
                "bond_updates_per_s": float(rate),
                "half_list": (name, dtype) in half,
                "bytes_per_bond": float(nbytes),
                "memory_roof_bond_updates_per_s": float(memory_roof),
                "memory_roof_fraction": float(rate / memory_roof),
                "sqrt_per_bond": n_sqrt,
                "div_per_bond": n_div,
                "compute_roof_bond_updates_per_s": float(compute_roof),
                "compute_roof_fraction": float(rate / compute_roof),
                "speedup_vs_baseline": float(rate / base_rate),
            }
        )
    return {
        "bandwidth_bytes_per_s": float(bandwidth),
        "sqrt_per_s": {dtype: float(r[0]) for dtype, r in rates.items()},
        "div_per_s": {dtype: float(r[1]) for dtype, r in rates.items()},
        "threads": int(numba.get_num_threads()),
        "omp_proc_bind": os.environ.get("OMP_PROC_BIND"),
        "results": results,
    }


def _binding(result: dict) -> str:
    """`` (OMP_PROC_BIND=...)`` when the benchmark's threads were bound, else nothing."""
    bind = result.get("omp_proc_bind")
    return f" (OMP_PROC_BIND={bind})" if bind else ""


def format_table(result: dict) -> str:
    """Readable table of a :func:`run_benchmark` result."""
    rows = result["results"]
    head = (
        f"{rows[0]['points']} points, {rows[0]['bonds']} directed bonds, "
        f"{result['threads']} numba threads{_binding(result)}, triad bandwidth "
        f"{result['bandwidth_bytes_per_s'] / 1e9:.1f} GB/s; square roots / divisions per ns: "
        + ", ".join(
            f"{dtype} {result['sqrt_per_s'][dtype] / 1e9:.2f} / {result['div_per_s'][dtype] / 1e9:.2f}"
            for dtype in result["sqrt_per_s"]
        )
    )
    lines = [
        head,
        "",
        f"{'model':<13} {'dtype':<8} {'M bond/s':>9} {'x baseline':>10} {'B/bond':>7} "
        f"{'mem roof':>9} {'share':>6} {'sqrt,div':>8} {'cpu roof':>9} {'share':>6}",
    ]
    for r in rows:
        lines.append(
            f"{r['model']:<13} {r['dtype']:<8} {r['bond_updates_per_s'] / 1e6:>9.1f} "
            f"{r['speedup_vs_baseline']:>10.2f} {r['bytes_per_bond']:>7.1f} "
            f"{r['memory_roof_bond_updates_per_s'] / 1e6:>9.0f} {r['memory_roof_fraction']:>6.2f} "
            f"{str(r['sqrt_per_bond']) + ',' + str(r['div_per_bond']):>8} "
            f"{r['compute_roof_bond_updates_per_s'] / 1e6:>9.0f} {r['compute_roof_fraction']:>6.2f}"
        )
    return "\n".join(lines)
