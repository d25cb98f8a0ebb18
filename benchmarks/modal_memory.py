"""Where the memory of a LOBPCG modal analysis goes, phase by phase (issue 22, item 3).

    PYTHONPATH=src python benchmarks/modal_memory.py --spacing 0.001
    PYTHONPATH=src python benchmarks/modal_memory.py cases/pmma_plate.yaml --spacing 0.00066667 --json

Builds the case (default ``cases/pmma_plate.yaml``, LPS with the energy correction, horizon
1.4143 h) at the given spacing and solves its modes with LOBPCG, recording the process's
resident memory (Linux ``/proc/self/status``) around each phase of
``solvers.eigen_iterative.lobpcg_modes``: building the body and bonds, the matrix-free
operator, the preconditioner's sparse proxy, its aggregates, the AMG hierarchy (pyamg),
the block V-cycle's arrays, every LOBPCG call and the residuals. The peak of each phase is
the kernel's high-water mark (VmHWM), reset before the phase (``/proc/self/clear_refs``).

Prints one row per phase: MiB resident before, the phase's peak above that, and what the
phase leaves resident (after - before); then the whole run's peak (the resets make
``/usr/bin/time``'s maximum resident size that of the last phase only: read this one).

With ``--cli OUTPUT`` the phases are those of ``peridyn modal CASE --set
discretization.spacing=... --set discretization.horizon=... --modes N --json --output OUTPUT``
run in this process (the case's eigensolver choice, then the output files).
"""

from __future__ import annotations

import argparse
import functools
import json
import time
from pathlib import Path

import peridyn.linalg.amg as amg
import peridyn.linalg.block_amg as block_amg
import peridyn.solvers.eigen_iterative as eigen_iterative
import peridyn.solvers.modal as modal
from peridyn.io.case import load_case
from peridyn.setup.build import build

MIB = 2**20


def _status(field: str) -> float:
    """``field`` (VmRSS, VmHWM) of /proc/self/status, MiB."""
    for line in Path("/proc/self/status").read_text().splitlines():
        if line.startswith(field + ":"):
            return int(line.split()[1]) * 1024 / MIB
    raise RuntimeError(f"{field} not in /proc/self/status")


def _reset_peak() -> None:
    """Reset the high-water mark VmHWM to the current resident size (Linux >= 4.0)."""
    Path("/proc/self/clear_refs").write_text("5")


class PhaseLog:
    """Rows (phase, MiB before, peak above before, retained, seconds) of the wrapped calls."""

    def __init__(self):
        self.rows = []
        self.whole_peak = 0.0

    def measure(self, name, call, *args, **kwargs):
        """``call(*args, **kwargs)``, recording one row named ``name``."""
        before = _status("VmRSS")
        self.whole_peak = max(self.whole_peak, _status("VmHWM"))
        _reset_peak()
        start = time.perf_counter()
        result = call(*args, **kwargs)
        seconds = time.perf_counter() - start
        peak = _status("VmHWM")
        self.whole_peak = max(self.whole_peak, peak)
        after = _status("VmRSS")
        self.rows.append(
            {
                "phase": name,
                "before_mib": round(before),
                "peak_above_mib": round(peak - before),
                "retained_mib": round(after - before),
                "seconds": round(seconds, 2),
            }
        )
        return result

    def wrap(self, module, attribute: str, name: str) -> None:
        """Record every call of ``module.attribute`` as a row ``name``."""
        original = getattr(module, attribute)

        @functools.wraps(original)
        def measured(*args, **kwargs):
            return self.measure(name, original, *args, **kwargs)

        setattr(module, attribute, measured)


def _count_calls(cls) -> list[int]:
    """A one-item list counting the calls of ``cls`` instances (the preconditioner's
    applications: one per LOBPCG iteration)."""
    count = [0]
    original = cls.__call__

    def counted(self, *args, **kwargs):
        count[0] += 1
        return original(self, *args, **kwargs)

    cls.__call__ = counted
    return count


def main(argv=None) -> dict:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("case", nargs="?", default="cases/pmma_plate.yaml")
    parser.add_argument("--spacing", type=float, default=0.001, help="grid spacing, m")
    parser.add_argument("--horizon", type=float, default=1.4143, help="horizon / spacing")
    parser.add_argument("--modes", type=int, default=12)
    parser.add_argument("--json", action="store_true", help="one JSON object instead of the table")
    parser.add_argument("--cli", metavar="OUTPUT", help="run `peridyn modal` itself, writing to OUTPUT")
    args = parser.parse_args(argv)
    log = PhaseLog()
    log.wrap(eigen_iterative, "block_stiffness_operator", "matrix-free operator")
    log.wrap(eigen_iterative, "proxy_stiffness", "proxy matrix")
    log.wrap(eigen_iterative, "proxy_aggregates", "aggregates")
    log.wrap(amg, "smoothed_aggregation_hierarchy", "AMG hierarchy (pyamg)")
    log.wrap(amg, "BlockVCycle", "V-cycle arrays")
    log.wrap(eigen_iterative, "_quiet_lobpcg", "LOBPCG")
    log.wrap(modal, "_result", "residuals and shapes")
    v_cycles = _count_calls(block_amg.BlockVCycle)
    overrides = [f"discretization.spacing={args.spacing}", f"discretization.horizon={args.horizon}"]
    start = time.perf_counter()
    if args.cli:
        from peridyn.cli import main as peridyn_main

        sets = [word for item in overrides for word in ("--set", item)]
        peridyn_main(["modal", args.case, *sets, "--modes", str(args.modes), "--json", "--output", args.cli])
        summary = {}
    else:
        case = load_case(args.case, overrides)
        setup = log.measure("body, bonds, model", build, case, Path(args.case).parent)
        result = modal.modal_analysis(setup.model, args.modes, method="lobpcg")
        summary = {
            "points": setup.body.n_points,
            "bonds": setup.bonds.n_bonds,
            "elastic_hz": [round(float(f), 3) for f in result.elastic().frequencies],
        }
    summary.update(
        seconds=round(time.perf_counter() - start, 1),
        peak_mib=round(max(log.whole_peak, _status("VmHWM"))),
        lobpcg_calls=sum(row["phase"] == "LOBPCG" for row in log.rows),
        v_cycles=v_cycles[0],
        phases=log.rows,
    )
    if args.json:
        print(json.dumps(summary))
    else:
        print(json.dumps({key: value for key, value in summary.items() if key != "phases"}))
        print(f"{'phase':<24} {'before':>8} {'peak+':>8} {'kept':>8} {'s':>8}   (MiB)")
        for row in log.rows:
            print(
                f"{row['phase']:<24} {row['before_mib']:>8} {row['peak_above_mib']:>8} "
                f"{row['retained_mib']:>8} {row['seconds']:>8}"
            )
    return summary


if __name__ == "__main__":
    main()
