"""What an explicit run loads: not the packages only other jobs use.

Every process of a run pays for what it imports, and under MPI every rank does: the
interpreter with numpy, scipy.spatial, numba (and its compiler, once a kernel runs), h5py,
pydantic and mpi4py is about 200 MB a process, against the 130 MB a rank holding half of a
2 x 10^6-point lattice plate needs (docs/mpi.md, "Lattice storage under MPI"). pyamg (AMG
preconditioning of static solves), meshio and the rich console it loads (VTU output),
scipy.optimize and scipy.integrate (root finding for dispersion curves, radial moments of
non-constant influence functions) cost about 25 MB more and are imported where they are used.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import peridyn

SRC = Path(peridyn.__file__).parents[1]
CASE = SRC.parent / "cases" / "lamb_plate.yaml"

#: packages an explicit run without VTU output, static solves or dispersion analysis never uses
UNUSED = ("pyamg", "meshio", "rich", "scipy.optimize", "scipy.integrate")

#: runs the CLI in this process, then prints which of the packages argv[1:] names it loaded
PROBE = """
import json, sys
from peridyn.cli import main
names, sys.argv = sys.argv[1].split(","), ["peridyn"] + sys.argv[2:]
try:
    main()
except SystemExit as exc:
    assert not exc.code, exc.code
print(json.dumps(sorted(n for n in names if n in sys.modules)))
"""


def test_an_explicit_lattice_run_loads_no_solver_mesh_or_root_finding_package(tmp_path):
    overrides = {
        "discretization.spacing": "4e-3",  # 12 000 points, 3 layers
        "discretization.storage": "lattice",
        "solver.time": "0.3e-6",
        "analysis": "{}",
        "output.planes": "{}",
        "output.lines": "{}",
        "output.snapshot_times": "[]",
        "output.plots": "false",
    }
    sets = [a for k, v in overrides.items() for a in ("--set", f"{k}={v}")]
    done = subprocess.run(
        [sys.executable, "-c", PROBE, ",".join(UNUSED), "run", str(CASE), "-o", str(tmp_path / "run"), *sets],
        capture_output=True,
        text=True,
        env={**os.environ, "PYTHONPATH": str(SRC)},
        timeout=600,
    )
    assert done.returncode == 0, done.stderr
    assert json.loads(done.stdout.splitlines()[-1]) == []
