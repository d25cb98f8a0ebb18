"""Bloch-wave study of the seed 000 aluminium plate (2 mm, V1): S0/A0 errors and cost of
100 discretisations (layers x spacing x horizon x surface correction, LPS, cell-centred
layers, no partial volumes, constant influence), and the timing of one case prediction.

Run from the repository root:  PYTHONPATH=src python benchmarks/bloch_study.py
Prints the Markdown table of docs/bloch.md (best first) and the timings (seconds).
"""

from __future__ import annotations

import sys
import time

from peridyn.analysis.bloch import BlochLattice
from peridyn.analysis.bloch_study import format_study, predict, study
from peridyn.io.case import load_case

FREQUENCIES = (110e3, 150e3, 185e3, 225e3)


def main() -> None:
    disc = BlochLattice.from_case(load_case("cases/lamb_plate_converged.yaml"))
    predict(disc, [150e3])  # compile the numba kernels once
    start = time.perf_counter()
    predict(BlochLattice.from_case(load_case("cases/lamb_plate_converged.yaml")), [110e3, 150e3, 225e3])
    print(
        f"prediction at three frequencies (converged preset): {time.perf_counter() - start:.2f} s",
        file=sys.stderr,
    )
    start = time.perf_counter()
    seed = BlochLattice.from_case(load_case("cases/lamb_plate.yaml"))
    predict(seed, [110e3, 150e3, 225e3])
    print(
        f"prediction at three frequencies (seed case): {time.perf_counter() - start:.2f} s", file=sys.stderr
    )
    start = time.perf_counter()
    rows = study(disc, FREQUENCIES)
    print(
        f"study of {len(rows)} discretisations at {len(FREQUENCIES)} frequencies: "
        f"{time.perf_counter() - start:.1f} s",
        file=sys.stderr,
    )
    print(format_study(rows))


if __name__ == "__main__":
    main()
