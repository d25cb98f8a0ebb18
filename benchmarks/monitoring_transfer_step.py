"""The monitoring job's two damage transfers on the clean crack against the fatigue step
(docs/monitoring.md, "Where they must agree, and how far they do"): the clean-crack job of
tests/simulation/test_monitor_transfer.py on the 0.5 mm grid (5 layers), its fatigue mapped with
``STEPS`` steps of 1 / ``TAU`` cycles (the test: 175 steps of 1 000 cycles), interrogated at
the same schedule (5.75 and 6.75 mm on that grid).

    PYTHONPATH=src python benchmarks/monitoring_transfer_step.py OUTPUT_DIR TAU STEPS

Prints each index of the crossed path by both routes and ``|bonds - cut| / bonds`` at each
interrogation, and how far past the tip rule's point the broken bonds reach there; writes
OUTPUT_DIR/step.json.
"""

from __future__ import annotations

import importlib.util
import json
import sys
import time
from pathlib import Path

import numpy as np

from peridyn.jobs.monitor import SUMMARY

ROOT = Path(__file__).resolve().parents[1]
_spec = importlib.util.spec_from_file_location(
    "test_monitor_transfer", ROOT / "tests" / "simulation" / "test_monitor_transfer.py"
)
clean = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(clean)


def main(folder: Path, tau: float, steps: int) -> None:
    start = time.perf_counter()
    folder.mkdir(parents=True, exist_ok=True)
    m, history = clean._job(folder, 0.5e-3, 5, steps, tau=tau)
    t = m["transfer"]
    cycles = np.asarray(json.loads((folder / "out" / SUMMARY).read_text())["cycles"])[t["interrogations"]]
    lengths = np.array([history.crack_length[np.argmax(history.cycles >= c)] for c in cycles])
    row = {
        "tau": tau,
        "steps": steps,
        "cycles": cycles.tolist(),
        "crack_lengths_m": lengths.tolist(),
        "reach_m": [clean._reach(history, c, a) for c, a in zip(cycles, lengths, strict=True)],
        "crossed_paths": m["crossed_paths"],
        "seconds": time.perf_counter() - start,
    }
    for name in clean.INDICES:
        row[name] = {k: t[name][k] for k in ("bonds", "cut", "relative_difference")}
    (folder / "step.json").write_text(json.dumps(row, indent=1))
    print(json.dumps(row, indent=1))


if __name__ == "__main__":
    main(Path(sys.argv[1]), float(sys.argv[2]), int(sys.argv[3]))
