"""Force-kernel throughput of the GPU backend: ``peridyn bench --backend gpu``.

The grid, the rows and the counts of ``peridyn.jobs.bench`` (a cube, 1 mm spacing, horizon
3.015 spacings; directed bond updates per second, both LPS passes counting as one update),
with the force of ``solvers.gpu_force.DeviceForce`` on the Warp device (a CUDA GPU, or Warp's
CPU device with ``PERIDYN_GPU_ON_CPU=1``): PMB and LPS in float64 and float32.

Timing: each row is launched once first (Warp compiles or loads its kernels); then ``repeat``
rounds launch every row ``INNER`` times in turn and wait for the device, and a row's time is
its best round over ``INNER``.

Memory roof: a device-to-device copy of ``copy_bytes`` (256 MiB by default, far beyond the
device's caches), counted as two bytes moved per byte copied (read and write), best of
``max(repeat, 5)``; ``bytes_per_bond`` is that of the CPU rows without the half list
(``jobs.bench.bytes_per_bond``: the ELL kernels read the same per-bond arrays, and not the
padding), and ``memory_roof_fraction`` = rate / (bandwidth / bytes_per_bond).
"""

from __future__ import annotations

import time
from collections.abc import Callable

import numpy as np

from peridyn.errors import InputError
from peridyn.jobs.bench import (
    DEFAULT_POINTS,
    DENSITY,
    NU,
    SPACING,
    E,
    benchmark_grid,
    bytes_per_bond,
    side_for,
)
from peridyn.kernels.gpu import device, device_description, warp
from peridyn.physics.materials import make_model
from peridyn.solvers.gpu_force import DeviceForce, check_fits

#: The rows, in table order.
GPU_ROWS = (("pmb", "float64"), ("pmb", "float32"), ("lps", "float64"), ("lps", "float32"))
#: Force evaluations per timed round (amortises the launch and the wait).
INNER = 10
#: Bytes of the copy that measures the device's memory bandwidth: 256 MiB.
DEFAULT_COPY_BYTES = 1 << 28


def device_bandwidth(name: str, nbytes: int = DEFAULT_COPY_BYTES, repeat: int = 5) -> float:
    """Bytes/s moved by a copy of ``nbytes`` on the Warp device ``name`` (read + write counted)."""
    wp = warp()
    n = max(1, nbytes // 8)
    src = wp.full(n, 1.0, dtype=wp.float64, device=name)
    dst = wp.zeros(n, dtype=wp.float64, device=name)
    wp.copy(dst, src)
    wp.synchronize_device(name)
    best = np.inf
    for _ in range(max(1, repeat)):
        t0 = time.perf_counter()
        wp.copy(dst, src)
        wp.synchronize_device(name)
        best = min(best, time.perf_counter() - t0)
    return 2.0 * 8 * n / best


def force_seconds(force: DeviceForce, u, repeat: int, inner: int = INNER) -> float:
    """Best time, s, of one force evaluation of ``force`` at the device displacement ``u``
    (Warp (n, 3) float64), over ``repeat`` rounds of ``inner`` evaluations after a warm-up."""
    wp, name = force.wp, force.device
    force.compute(u)
    wp.synchronize_device(name)
    best = np.inf
    for _ in range(max(1, repeat)):
        t0 = time.perf_counter()
        for _ in range(inner):
            force.compute(u)
        wp.synchronize_device(name)
        best = min(best, (time.perf_counter() - t0) / inner)
    return best


def run_gpu_benchmark(
    points: int = DEFAULT_POINTS,
    repeat: int = 10,
    partial_volumes: bool = False,
    copy_bytes: int = DEFAULT_COPY_BYTES,
    seed: int = 0,
    log: Callable[[str], None] | None = None,
) -> dict:
    """Measure every GPU row and the device's copy bandwidth; the ``peridyn bench --backend gpu
    --json`` dict (``backend``, ``device``, ``device_name``, ``bandwidth_bytes_per_s``,
    ``results``: one dict per row with the keys of the CPU rows that apply)."""
    if repeat < 1:
        raise InputError(f"repeat must be at least 1, got {repeat}")
    say = log or (lambda msg: None)
    name = device()
    side = side_for(points)
    say(f"building a {side}^3 grid (partial volumes {'on' if partial_volumes else 'off'})")
    body, bonds = benchmark_grid(side, partial_volumes)
    rng = np.random.default_rng(seed)
    u64 = 1e-4 * SPACING * rng.standard_normal(body.points.shape)
    forces = {}
    for model_name, dtype in GPU_ROWS:
        model = make_model(model_name, body, bonds, E=E, nu=NU, density=DENSITY, dtype=np.dtype(dtype))
        check_fits(model, False, name)
        forces[model_name, dtype] = DeviceForce(model, name)
    wp = warp()
    u = wp.array(u64, dtype=wp.float64, device=name)
    say(f"{body.n_points} points, {bonds.n_bonds} directed bonds on {device_description(name)}; warming up")
    best = {}
    for key, force in forces.items():
        best[key] = force_seconds(force, u, 1, 1)
    for r in range(repeat):
        say(f"round {r + 1}/{repeat}")
        for key, force in forces.items():
            best[key] = min(best[key], force_seconds(force, u, 1))
    say("device copy bandwidth")
    bandwidth = device_bandwidth(name, copy_bytes, max(repeat, 5))
    results = []
    for model_name, dtype in GPU_ROWS:
        rate = bonds.n_bonds / best[model_name, dtype]
        nbytes = bytes_per_bond(model_name, dtype)
        roof = bandwidth / nbytes
        results.append(
            {
                "model": model_name,
                "dtype": dtype,
                "points": int(body.n_points),
                "bonds": int(bonds.n_bonds),
                "k_max": int(forces[model_name, dtype].slots.k_max),
                "bond_updates_per_s": float(rate),
                "bytes_per_bond": float(nbytes),
                "memory_roof_bond_updates_per_s": float(roof),
                "memory_roof_fraction": float(rate / roof),
            }
        )
    return {
        "backend": "gpu",
        "device": name,
        "device_name": device_description(name),
        "warp_version": str(wp.__version__),
        "bandwidth_bytes_per_s": float(bandwidth),
        "results": results,
    }


def format_gpu_table(result: dict) -> str:
    """Readable table of a :func:`run_gpu_benchmark` result."""
    rows = result["results"]
    lines = [
        f"{rows[0]['points']} points, {rows[0]['bonds']} directed bonds on {result['device_name']} "
        f"({result['device']}, Warp {result['warp_version']}), copy bandwidth "
        f"{result['bandwidth_bytes_per_s'] / 1e9:.1f} GB/s",
        "",
        f"{'model':<6} {'dtype':<8} {'G bond/s':>9} {'B/bond':>7} {'mem roof':>9} {'share':>6}",
    ]
    for r in rows:
        lines.append(
            f"{r['model']:<6} {r['dtype']:<8} {r['bond_updates_per_s'] / 1e9:>9.2f} "
            f"{r['bytes_per_bond']:>7.1f} {r['memory_roof_bond_updates_per_s'] / 1e9:>9.1f} "
            f"{r['memory_roof_fraction']:>6.2f}"
        )
    return "\n".join(lines)
