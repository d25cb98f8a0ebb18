"""``mpiexec -n 2`` and ``-n 3 peridyn run`` of static cases with bond breaking or contact (issue
20 item 5: dynamic relaxation on each rank's part, ``solvers.static.relax`` with a ``Domain``)
give the serial run bit for bit: every dataset under ``final/`` and ``series/`` of results.h5
equal, the same bonds broken, the same relaxation iterations and residual.

Why equality is the right test: each rank updates its owned points with the serial arithmetic,
its ghosts' u comes from their owners after every update (so the owned forces, the bonds broken
and the contact forces are the serial ones, as in an explicit MPI run, tests/mpi/test_mpi_runs.py),
and the only sums of the method (the adaptive damping's Rayleigh quotient and the residual norms)
are taken on rank 0 over the gathered values in global point order, as in serial.

Cases, from the clamped aluminium bar of cases/bar_tension_static.yaml at 2 mm (500 points):

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
import shutil
from pathlib import Path

import h5py
import numpy as np
import pytest
from conftest import peridyn_process

pytestmark = pytest.mark.mpi

ROOT = Path(__file__).resolve().parents[2]
CASE = ROOT / "cases" / "bar_tension_static.yaml"
BASE = ["discretization.spacing=2e-3", "output.plots=false"]

#: a pre-crack in the plane x = 20 mm through the whole depth z, from y = -1 mm over ``height`` m
#: (6 mm: to mid-height of the 10 mm bar; 12 mm: through it)
PRECRACK = (
    "precracks=[{{type: rectangle, origin: [0.02, -0.001, -0.001], edge_u: [0, {height}, 0], "
    "edge_v: [0, 0, 0.012]}}]"
)

CASES = {
    "notched": [PRECRACK.format(height=0.006), "material.damage.critical_stretch=8.5e-5"],
    "lps_two_steps": ["material.model=lps", "material.damage.critical_stretch=2.1e-5", "solver.load_steps=2"],
    "contact": [
        PRECRACK.format(height=0.012),
        "contact={radius: 1.0}",
        "boundary_conditions=[{set: clamp, kind: displacement, components: xyz, value: 0.0}, "
        "{set: loaded, kind: force, components: x, value: -100.0}]",
    ],
}

#: summary keys that must equal the serial run's
SAME = ("points", "bonds", "broken_bonds", "max_damage", "steps", "iterations", "residual", "strain_energy_j")


def _run(case: str, out: Path, ranks: int) -> dict:
    argv = ["run", str(CASE), "-o", str(out), "--json", "--no-progress"]
    for s in [*BASE, *CASES[case]]:
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
    from peridyn.jobs.build import build

    setup = build(load_case(CASE, [*BASE, *CASES[case]]), ROOT / "cases")
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
    for case in ("notched", "lps_two_steps"):
        assert serial[case][0]["broken_bonds"] > _precrack_bonds(case), case
    summary, data = serial["contact"]
    assert summary["contact_rebuilds"] >= 1
    assert summary["broken_bonds"] == _precrack_bonds("contact")
    assert np.all(data["final/u"][:, 0] <= 0)  # pushed towards the clamp, not pulled apart


@pytest.mark.parametrize("ranks", [2, 3])
@pytest.mark.parametrize("case", list(CASES))
def test_mpi_static_relaxation_is_the_serial_run(case, ranks, serial, tmp_path):
    want_summary, want = serial[case]
    summary = _run(case, tmp_path / "run", ranks)
    got = _datasets(tmp_path / "run")
    with h5py.File(tmp_path / "run" / "results.h5") as f:
        assert f.attrs["mpi_ranks"] == ranks  # it did run on that many ranks
    for key in SAME:
        assert summary[key] == want_summary[key], key
    if case == "contact":
        assert summary["contact_rebuilds"] == want_summary["contact_rebuilds"]
    assert sorted(got) == sorted(want)
    for name, values in want.items():
        np.testing.assert_array_equal(got[name], values, err_msg=name)
