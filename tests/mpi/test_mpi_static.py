"""``mpiexec -n 2`` and ``-n 3 peridyn run`` of static cases with bond breaking or contact (issue
20 item 5: dynamic relaxation on each rank's part, ``solvers.relaxation.relax`` with a ``Domain``)
give the serial run bit for bit: every dataset under ``final/`` and ``series/`` of results.h5
equal, and every value of the summary (bonds broken, relaxation iterations, residual, strain
energy, crack paths, contact rebuilds) but the run's own (folder, seconds, memory).

Why equality is the right test: each rank updates its owned points with the serial arithmetic,
its ghosts' u comes from their owners after every update (so the owned forces, the bonds broken
and the contact forces are the serial ones, as in an explicit MPI run, tests/mpi/test_mpi_runs.py),
and the only sums of the method (the adaptive damping's Rayleigh quotient and the residual norms)
are taken on rank 0 over the gathered values in global point order, as in serial.

Cases: the shipped 2D case with bond breaking, cases/plate2d_stretch.yaml, solved as a static case,
and the clamped aluminium bar of cases/bar_tension_static.yaml at 2 mm (500 points) made to break
bonds or touch:

- ``plate2d_static``: the free-free plate with its central crack (seed 004) at 0.25 mm (640
  points) under its final 100 N pulls, bonds breaking above 40 MPa of bond stress: 68 bonds break
  at the crack's tips (besides the 192 it cuts), where the 2-rank partition cuts the plate;

- ``notched``: a pre-crack through half the height at mid-length, where the 2-rank partition
  cuts the bar, and a critical stretch of 8.5e-5 (the largest stretch of the elastic solution is
  9.1e-5, at the crack tip): 64 bonds break at the tip besides the pre-crack's, 3 500 iterations;
- ``lps_two_steps``: LPS (each point's force reads its neighbours' dilatations), critical stretch
  2.1e-5 (elastic maximum 2.2e-5), two load steps (the second starts from the first's solution):
  108 bonds break at both ends;
- ``contact``: the bar cut through at mid-length by a pre-crack and pushed by -100 N, contact at one
  spacing: the loaded half is held by contact alone (without contact the same run is still at a
  residual of 0.32 after ten times the iterations), and on 2 ranks the contact pairs straddle the
  ranks' cut.

Run with ``PYTHONPATH=src python -m pytest -m mpi -q -p no:cacheprovider tests/mpi``.
"""

import json
import os
import shutil
import subprocess
import sys
import textwrap
from pathlib import Path

import h5py
import numpy as np
import pytest
from conftest import peridyn_process

import peridyn

#: at 0.25 mm the plate's 10.125 mm rounds to 10 mm (40 cells), as every run of it says
pytestmark = [pytest.mark.mpi, pytest.mark.filterwarnings("ignore:the spacing does not divide the body")]

ROOT = Path(__file__).resolve().parents[2]
BAR = ("bar_tension_static.yaml", ["discretization.spacing=2e-3", "output.plots=false"])

#: a pre-crack in the plane x = 20 mm through the whole depth z, from y = -1 mm over ``height`` m
#: (6 mm: to mid-height of the 10 mm bar; 12 mm: through it)
PRECRACK = (
    "precracks=[{{type: rectangle, origin: [0.02, -0.001, -0.001], edge_u: [0, {height}, 0], "
    "edge_v: [0, 0, 0.012]}}]"
)

#: name: (case file, overrides)
CASES = {
    "plate2d_static": (
        "plate2d_stretch.yaml",
        ["solver.type=static", "discretization.spacing=0.25e-3", "output.plots=false"],
    ),
    "notched": (BAR[0], [*BAR[1], PRECRACK.format(height=0.006), "material.damage.critical_stretch=8.5e-5"]),
    "lps_two_steps": (
        BAR[0],
        [*BAR[1], "material.model=lps", "material.damage.critical_stretch=2.1e-5", "solver.load_steps=2"],
    ),
    "contact": (
        BAR[0],
        [
            *BAR[1],
            PRECRACK.format(height=0.012),
            "contact={radius: 1.0}",
            "boundary_conditions=[{set: clamp, kind: displacement, components: xyz, value: 0.0}, "
            "{set: loaded, kind: force, components: x, value: -100.0}]",
        ],
    ),
}

#: summary keys that differ between any two runs (the rest must equal the serial run's)
OWN = ("output_dir", "seconds", "peak_memory_bytes")


def _run(case: str, out: Path, ranks: int) -> dict:
    path, sets = CASES[case]
    argv = ["run", str(ROOT / "cases" / path), "-o", str(out), "--json", "--no-progress"]
    for s in sets:
        argv += ["--set", s]
    done = peridyn_process(argv, ranks)
    assert done.returncode == 0, done.stderr
    return json.loads(done.stdout)


def _datasets(folder: Path) -> dict:
    """Every dataset under final/ and series/ of a results.h5, by path."""
    found = {}
    with h5py.File(folder / "results.h5") as f:
        for group in ("final", "series"):
            f[group].visititems(
                lambda name, obj, g=group: (
                    found.__setitem__(f"{g}/{name}", obj[()]) if isinstance(obj, h5py.Dataset) else None
                )
            )
    return found


def _precrack_bonds(case: str) -> int:
    """Directed bonds the case's pre-crack cuts (broken before any load)."""
    from peridyn.io.case import load_case
    from peridyn.setup.build import build

    path, sets = CASES[case]
    setup = build(load_case(ROOT / "cases" / path, sets), ROOT / "cases")
    return int((~setup.bonds.intact).sum())


@pytest.fixture(scope="module")
def serial(tmp_path_factory):
    if shutil.which("mpiexec") is None:
        pytest.skip("mpiexec not installed (pip install 'peridyn[mpi]')")
    pytest.importorskip("mpi4py")
    base = tmp_path_factory.mktemp("serial")
    return {case: (_run(case, base / case, 1), _datasets(base / case)) for case in CASES}


def test_the_serial_runs_break_bonds_and_touch(serial):
    """The cases do what they are for: bonds break under load (beyond the pre-crack's) in the
    damage cases; contact is built in the contact case, whose load crosses the cut."""
    for case in ("plate2d_static", "notched", "lps_two_steps"):
        assert serial[case][0]["broken_bonds"] > _precrack_bonds(case), case
    summary, data = serial["contact"]
    assert summary["contact_rebuilds"] >= 1
    assert summary["broken_bonds"] == _precrack_bonds("contact")
    assert np.all(data["final/u"][:, 0] <= 0)  # pushed towards the clamp, not pulled apart


@pytest.mark.bitwise
@pytest.mark.parametrize("ranks", [2, 3])
@pytest.mark.parametrize("case", list(CASES))
def test_mpi_static_relaxation_is_the_serial_run(case, ranks, serial, tmp_path):
    """A static case on 2 and 3 ranks gives the serial run's summary (but its folder, time and
    memory) and datasets bit for bit: each rank computes its points with the serial operations in
    the serial order, and the global sums are taken over the whole body in global point order on
    rank 0 (``Domain.reduce``); the kernels are compiled without value-changing fast-math flags
    (``peridyn.kernels.FASTMATH``), so this holds on every CPU."""
    want_summary, want = serial[case]
    summary = _run(case, tmp_path / "run", ranks)
    got = _datasets(tmp_path / "run")
    with h5py.File(tmp_path / "run" / "results.h5") as f:
        assert f.attrs["mpi_ranks"] == ranks  # it did run on that many ranks
    assert sorted(summary) == sorted(want_summary)  # broken bonds, iterations, residual, energy...
    for key in set(want_summary) - set(OWN):
        assert summary[key] == want_summary[key], key
    assert sorted(got) == sorted(want)
    for name, values in want.items():
        np.testing.assert_array_equal(got[name], values, err_msg=name)


#: ``python -c`` wrapper of ``peridyn`` that raises a MemoryError on one rank (argv[1]) at its
#: relaxation's bond test number argv[2] (an error no other rank knows of, as from a kernel), then
#: runs ``peridyn`` with the other arguments.
HOOK = textwrap.dedent(
    """
    import sys
    from peridyn.cli import main
    from peridyn.parallel.comm import world
    from peridyn.physics.damage import BondDamage

    rank, at = int(sys.argv[1]), int(sys.argv[2])
    original, calls = BondDamage.update, []

    def update(self, u):
        calls.append(1)
        if world().rank == rank and len(calls) == at:
            raise MemoryError("injected on one rank")
        return original(self, u)

    BondDamage.update = update
    sys.exit(main(sys.argv[3:]))
    """
)


@pytest.mark.parametrize("rank", [0, 1])
def test_an_error_on_one_rank_inside_the_relaxation_ends_every_rank_with_one_line(serial, rank, tmp_path):
    """An error that one rank alone raises in an iteration (the others wait for its halo messages
    or its part of the damping's gather) ends the run at once, not a hang: the failing rank prints
    the one error line and MPI_Abort ends the others (status 1), as in an explicit run."""
    path, sets = CASES["notched"]
    argv = ["run", str(ROOT / "cases" / path), "-o", str(tmp_path / "run"), "--no-progress"]
    for s in sets:
        argv += ["--set", s]
    command = ["mpiexec", "-n", "2", sys.executable, "-c", HOOK, str(rank), "50", *argv]
    env = dict(os.environ, PYTHONPATH=str(Path(peridyn.__file__).parents[1]), NUMBA_NUM_THREADS="1")
    done = subprocess.run(command, capture_output=True, text=True, env=env, timeout=120)
    assert done.returncode == 1, done.stderr
    lines = [line for line in done.stderr.splitlines() if "error:" in line]
    assert len(lines) == 1 and "out of memory (injected on one rank)" in lines[0], done.stderr
