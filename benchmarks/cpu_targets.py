"""Shipped explicit cases, shortened, run with the kernels compiled for other CPUs than the host.

numba compiles for the CPU named by ``NUMBA_CPU_NAME`` with the features of
``NUMBA_CPU_FEATURES`` (empty: that CPU's own), whatever the host is, so one machine runs the
code an AVX2-only or an SSE2-only CPU would run. NumPy's own SIMD code is narrowed the same way
with ``NPY_DISABLE_CPU_FEATURES``, down to its SSE4.2 baseline (the tone bursts' sines, the
recorder's arithmetic). Each target gets a fresh numba cache. Every float dataset of each
run's ``results.h5`` is compared with the host run's: ``identical`` (the same bits) or the
largest difference relative to the dataset's largest magnitude.

    PYTHONPATH=src python benchmarks/cpu_targets.py --json benchmarks/cpu_targets.json

What the result means for users: docs/user-guide.md, "Reproducibility".
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

import h5py
import numpy as np

ROOT = Path(__file__).resolve().parents[1]

#: name -> (NUMBA_CPU_NAME, NUMBA_CPU_FEATURES, NPY_DISABLE_CPU_FEATURES); None: the host's
TARGETS = {
    "host": (None, None, None),
    "haswell (AVX2, FMA)": ("haswell", "", "X86_V4 AVX512_ICL AVX512_SPR"),
    "x86-64 (SSE2; NumPy at SSE4.2)": ("generic", "", "X86_V3 X86_V4 AVX512_ICL AVX512_SPR"),
}

#: name -> (case file, --set overrides): short runs of the explicit paths
CASES = {
    "bar LPS float64": ("bar_pulse.yaml", ["discretization.spacing=2.5e-3", "solver.time=3e-6"]),
    "bar LPS float32": (
        "bar_pulse.yaml",
        ["discretization.spacing=2.5e-3", "solver.time=3e-6", "solver.dtype=float32"],
    ),
    "bar PMB float64": (
        "bar_pulse.yaml",
        ["discretization.spacing=2.5e-3", "solver.time=3e-6", "material.model=pmb", "material.nu=0.25"],
    ),
    "Lamb plate (PZT burst)": (
        "lamb_plate.yaml",
        ["discretization.spacing=3e-3", "solver.time=4e-6"],
    ),
    "pre-cracked plate (bonds break)": ("plate2d_precrack_pull.yaml", ["solver.time=12e-6"]),
}


def _environment(target: tuple, cache: Path) -> dict:
    cpu, features, numpy_off = target
    env = {**os.environ, "NUMBA_CACHE_DIR": str(cache), "PYTHONPATH": str(ROOT / "src")}
    for key in ("NUMBA_CPU_NAME", "NUMBA_CPU_FEATURES", "NPY_DISABLE_CPU_FEATURES"):
        env.pop(key, None)
    if cpu is not None:
        env["NUMBA_CPU_NAME"], env["NUMBA_CPU_FEATURES"] = cpu, features
        env["NPY_DISABLE_CPU_FEATURES"] = numpy_off
    return env


def run_case(case: str, sets: list[str], out: Path, env: dict) -> None:
    argv = [sys.executable, "-m", "peridyn", "run", str(ROOT / "cases" / case), "-o", str(out)]
    for item in ("output.plots=false", "output.snapshot_times=[]", *sets):
        argv += ["--set", item]
    done = subprocess.run(argv, env=env, capture_output=True, text=True, timeout=1800)
    if done.returncode != 0:
        raise RuntimeError(f"{case} {sets}: {done.stderr.strip().splitlines()[-1]}")


def float_datasets(path: Path) -> dict[str, np.ndarray]:
    arrays = {}

    def keep(name, obj):
        if isinstance(obj, h5py.Dataset) and obj.dtype.kind == "f":
            arrays[name] = obj[()]

    with h5py.File(path) as f:
        f.visititems(keep)
    return arrays


def largest_difference(reference: dict, other: dict) -> float:
    """Largest |a - b| / max |a| over the datasets (0.0: every bit the same)."""
    worst = 0.0
    for name, a in reference.items():
        b = other[name]
        if np.array_equal(a.view(np.uint8), b.view(np.uint8)):
            continue
        scale = float(np.max(np.abs(a))) or 1.0
        worst = max(worst, float(np.max(np.abs(a.astype(np.float64) - b))) / scale)
    return worst


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--json", type=Path, help="write the table here as JSON")
    args = parser.parse_args()
    table: dict[str, dict[str, float]] = {}
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        for t, target in enumerate(TARGETS.values()):
            env = _environment(target, tmp / f"cache{t}")
            for c, (case, sets) in enumerate(CASES.values()):
                run_case(case, sets, tmp / f"run{t}_{c}", env)
        for c, case_name in enumerate(CASES):
            host = float_datasets(tmp / f"run0_{c}" / "results.h5")
            table[case_name] = {
                name: largest_difference(host, float_datasets(tmp / f"run{t}_{c}" / "results.h5"))
                for t, name in enumerate(TARGETS)
                if t > 0
            }
    names = list(TARGETS)[1:]
    print("| case | " + " | ".join(names) + " |")
    print("|---|" + "---:|" * len(names))
    for case_name, row in table.items():
        cells = ["identical" if row[n] == 0.0 else f"{row[n]:.1e}" for n in names]
        print(f"| {case_name} | " + " | ".join(cells) + " |")
    if args.json:
        args.json.write_text(json.dumps(table, indent=1) + "\n")


if __name__ == "__main__":
    main()
