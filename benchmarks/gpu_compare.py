"""Compare two runs of one case, on the CPU and on the GPU backend: one table of the time loops
(``step_seconds``), the bonds broken and each recorded series' largest difference, absolute and
relative to the series' largest value (a series the wave has not reached holds rounding noise
only, e.g. 1e-20 m, and its relative difference says nothing). Used by
``benchmarks/gpu_check.sh``; ``--json`` prints the numbers instead.

    python benchmarks/gpu_compare.py CPU_DIR GPU_DIR [--json]
"""

import argparse
import json
import sys

import numpy as np

from peridyn.io.results import Results


def compare(cpu_dir: str, gpu_dir: str) -> dict:
    """The comparison of the runs in the two output folders (their results.h5)."""
    cpu, gpu = Results(f"{cpu_dir}/results.h5"), Results(f"{gpu_dir}/results.h5")
    c_sum, g_sum = cpu.summary(), gpu.summary()
    series = {}
    for name in cpu.series_names():
        _, _, a = cpu.series(name)
        _, _, b = gpu.series(name)
        largest = float(np.max(np.abs(a)))
        difference = float(np.max(np.abs(b.astype(np.float64) - a)))
        series[name] = {
            "largest": largest,
            "difference": difference,
            "relative": difference / largest if largest else float(difference > 0),
        }
    return {
        "cpu_step_seconds": c_sum["step_seconds"],
        "gpu_step_seconds": g_sum["step_seconds"],
        "speedup": c_sum["step_seconds"] / g_sum["step_seconds"],
        "steps": c_sum["steps"],
        "broken_bonds": [c_sum["broken_bonds"], g_sum["broken_bonds"]],
        "series": series,
    }


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("cpu_dir")
    parser.add_argument("gpu_dir")
    parser.add_argument("--json", action="store_true")
    args = parser.parse_args()
    result = compare(args.cpu_dir, args.gpu_dir)
    if args.json:
        print(json.dumps(result, indent=1))
        return 0
    print(f"{'':<28} {'cpu':>12} {'gpu':>12}")
    print(f"{'time loop (s)':<28} {result['cpu_step_seconds']:>12.3f} {result['gpu_step_seconds']:>12.3f}")
    print(f"{'steps':<28} {result['steps']:>12d} {result['steps']:>12d}")
    print(f"{'broken bonds':<28} {result['broken_bonds'][0]:>12d} {result['broken_bonds'][1]:>12d}")
    print(f"{'gpu speed-up':<28} {result['speedup']:>25.1f}")
    print(f"{'series':<28} {'max |cpu|':>12} {'max |gpu-cpu|':>14} {'relative':>10}")
    for name, d in result["series"].items():
        print(f"{name:<28} {d['largest']:>12.3e} {d['difference']:>14.3e} {d['relative']:>10.2e}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
