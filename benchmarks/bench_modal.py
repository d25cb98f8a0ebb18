"""Time and peak memory of the PMMA plate's 12 lowest modes (VALIDATION.md V4), any size and horizon.

    PYTHONPATH=src python benchmarks/bench_modal.py --spacing 0.001 --horizon 3.001 \\
        --eigensolver lobpcg

Prints one JSON object: points, bonds, eigensolver, seconds to build the body and
bonds and to solve, peak resident memory (``resource``: the whole process), the
frequencies (Hz, rigid modes first) and the relative residuals ||K x - lambda M x|| / ||K x||.
"""

from __future__ import annotations

import argparse
import json
import resource
import time

from peridyn.discretization import geometry
from peridyn.discretization.bonds import find_bonds
from peridyn.physics.materials import make_model
from peridyn.physics.materials.lps import SURFACE_CORRECTIONS
from peridyn.setup.eigensolver import choose_eigensolver
from peridyn.solvers.modal import modal_analysis

#: PMMA plate of VALIDATION.md V4: size (m), E (Pa), nu, density (kg/m^3).
SIZE, E, NU, RHO = (0.10, 0.05, 0.008), 5.35e9, 0.33, 1200.0


def main(argv=None) -> dict:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--spacing", type=float, default=0.002, help="grid spacing h, m")
    parser.add_argument("--horizon", type=float, default=3.001, help="horizon / h")
    parser.add_argument("--modes", type=int, default=12)
    parser.add_argument("--eigensolver", default="auto", choices=["auto", "shift-invert", "lobpcg"])
    parser.add_argument("--correction", default="none", choices=SURFACE_CORRECTIONS)
    args = parser.parse_args(argv)
    start = time.perf_counter()
    body = geometry.box(SIZE, args.spacing)
    bonds = find_bonds(body, args.horizon * args.spacing, partial_volumes=False)
    model = make_model("lps", body, bonds, E=E, nu=NU, density=RHO, surface_correction=args.correction)
    method = choose_eigensolver(model, args.eigensolver)
    built = time.perf_counter()
    result = modal_analysis(model, args.modes, method=method)
    solved = time.perf_counter()
    summary = {
        "points": body.n_points,
        "bonds": bonds.n_bonds,
        "horizon_spacings": args.horizon,
        "eigensolver": method,
        "build_s": round(built - start, 2),
        "solve_s": round(solved - built, 2),
        "peak_rss_gb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1e6,
        "rigid_modes": result.n_rigid,
        "frequencies_hz": [round(float(f), 4) for f in result.frequencies],
        "residuals": [float(f"{r:.2e}") for r in result.residuals],
    }
    print(json.dumps(summary))
    return summary


if __name__ == "__main__":
    main()
