"""``mpiexec -n 2`` and ``-n 3 peridyn run`` on lattice storage give the serial lattice run's
results.h5 bit for bit (every dataset under ``final/`` and ``series/``, dtypes and shapes
included) and its summary: each rank holds a slab of grid planes across x with the ghost planes
either side (``peridyn.parallel.lattice_domain``). Shipped grid cases, shortened: PMB in 2D with
a pre-crack, bonds breaking (plate2d_stretch with a lower bond strength: the crack grows from
6 us) and VTU snapshots (per-rank pieces); the Kalthoff-Winkler plate at 1 mm (removed notches,
pre-cracks, fracture energy, a no-damage set, velocity loading); LPS in 3D (bar_pulse, float64
and float32); the seed Lamb plate cut short (LPS with the shear-factor surface correction, a
PZT actuator, every kind of probe); and a restart on 3 ranks from a 2-rank checkpoint.

Run with ``PYTHONPATH=src python -m pytest -m mpi -q -p no:cacheprovider tests/mpi/test_mpi_lattice.py``.
"""

import json
import shutil
from pathlib import Path

import numpy as np
import pytest
from conftest import peridyn_process, results_datasets
from lamb_probes import LAMB_PROBES
from test_mpi_runs import _assert_same_snapshots

pytestmark = pytest.mark.mpi

ROOT = Path(__file__).resolve().parents[2]
LATTICE = "discretization.storage=lattice"

CASES = {
    "plate2d_stretch": (
        "plate2d_stretch.yaml",
        ["solver.time=10e-6", "material.damage.critical_bond_stress=4e6", "output.vtu=true"],
    ),
    "kalthoff_winkler": ("kalthoff_winkler.yaml", ["discretization.spacing=1e-3", "solver.time=30e-6"]),
    "bar_pulse": ("bar_pulse.yaml", ["solver.time=3e-6"]),
    "bar_pulse_float32": ("bar_pulse.yaml", ["solver.time=3e-6", "solver.dtype=float32"]),
    "lamb_probes": ("lamb_plate.yaml", [*LAMB_PROBES, "output.snapshot_times=[1.0e-6]", "solver.time=2e-6"]),
}

#: The cases whose bonds break during the run.
BREAKING = ("plate2d_stretch", "kalthoff_winkler")

#: Summary keys that a run on ranks must share with the serial run (floats compared exactly).
SAME = ("points", "bonds", "broken_bonds", "max_damage", "steps", "time_s", "dt_s", "stable_dt_s")
SAME += ("kinetic_energy_j", "strain_energy_j", "storage", "crack_length_history", "crack_paths")


def _have_mpi() -> bool:
    if shutil.which("mpiexec") is None:
        return False
    try:
        import mpi4py  # noqa: F401
    except ImportError:
        return False
    return True


def _run(case: str, out: Path, ranks: int, *extra: str, flags=()):
    path, sets = CASES[case]
    argv = ["run", str(ROOT / "cases" / path), "-o", str(out), "--no-progress", "--json", *flags]
    for s in ["output.plots=false", LATTICE, *sets, *extra]:
        argv += ["--set", s]
    return peridyn_process(argv, ranks)


@pytest.fixture(scope="module")
def serial(tmp_path_factory):
    """The serial lattice run of every case (the first one fills numba's cache), and of the
    cases with bond breaking one step, whose broken bonds are the pre-cracks'."""
    if not _have_mpi():
        pytest.skip("mpiexec or mpi4py not installed (pip install 'peridyn[mpi]')")
    base = tmp_path_factory.mktemp("serial")
    refs = {}
    for case in CASES:
        done = _run(case, base / case, 1)
        assert done.returncode == 0, done.stderr
        refs[case] = results_datasets(base / case / "results.h5"), json.loads(done.stdout), base / case
    for case in BREAKING:
        done = _run(case, base / f"{case}-precracks", 1, "solver.time=1e-9")
        assert done.returncode == 0, done.stderr
        refs[case, "precracks"] = json.loads(done.stdout)["broken_bonds"]
    return refs


def _assert_same(got: dict, want: dict) -> None:
    assert got.keys() == want.keys()
    for name, value in want.items():
        assert got[name].dtype == value.dtype and got[name].shape == value.shape, name
        assert np.array_equal(got[name], value), name


@pytest.mark.bitwise
@pytest.mark.parametrize("ranks", [2, 3])
@pytest.mark.parametrize("case", list(CASES))
def test_mpi_lattice_run_equals_the_serial_lattice_run_bit_for_bit(case, ranks, serial, tmp_path):
    """Each case on 2 and 3 ranks writes the serial lattice run's datasets and summary bit for bit.
    Bit for bit: a rank's owned points have their whole families, and the first ghost planes
    theirs, on the rank (two layers of reach), the lattice kernels add each point's bonds in
    stencil order whatever the grid around it, the exchanged displacements are copies, and sums
    over the body are taken on rank 0 in global order (``Domain.reduce``); the kernels are
    compiled without value-changing fast-math flags (``peridyn.kernels.FASTMATH``)."""
    done = _run(case, tmp_path / case, ranks)
    assert done.returncode == 0, done.stderr
    want, reference, folder = serial[case]
    _assert_same(results_datasets(tmp_path / case / "results.h5"), want)
    summary = json.loads(done.stdout)
    for key in SAME:
        assert summary.get(key) == reference.get(key), key
    if "output.vtu=true" in CASES[case][1]:  # the ranks' VTU pieces hold the serial snapshots
        _assert_same_snapshots(tmp_path / case, folder)
    assert summary["storage"] == "lattice"
    if case in BREAKING:  # breaking is covered: bonds broke beyond the pre-cracks
        assert summary["broken_bonds"] > serial[case, "precracks"] > 0
    if case == "lamb_probes":  # every kind of probe series is compared
        kinds = ("sensor_u", "sensor_v", "line_x_axis", "plane_top", "pzt_signal")
        assert {f"series/{k}/data" for k in kinds} <= want.keys()
    mpi = summary["mpi"]
    assert mpi["partition"] == "grid slabs across x" and mpi["mpi_ranks"] == ranks
    assert sum(mpi["points_per_rank"]) == summary["points"]
    # one exchange of u per step: 24 bytes per ghost point of every rank
    sent = sum(r["bytes_per_step"] for r in mpi["per_rank"])
    assert sent == pytest.approx(24 * sum(mpi["ghosts_per_rank"]), rel=1e-12)


@pytest.mark.bitwise
def test_lattice_restart_on_three_ranks_from_a_two_rank_checkpoint_equals_the_serial_run(serial, tmp_path):
    """Checkpoints hold the whole grid's broken words in the serial layout: a 2-rank run to 6 us
    (checkpoints every 20 steps, bonds broken beyond the pre-crack) continued on 3 ranks to
    10 us gives the serial 10 us run's datasets and summary bit for bit (the restart continues
    from the checkpoint's exact state, each rank taking its planes' bits)."""
    out = tmp_path / "run"
    first = _run("plate2d_stretch", out, 2, "solver.time=6e-6", flags=["--checkpoint-every", "20"])
    assert first.returncode == 0, first.stderr
    assert json.loads(first.stdout)["broken_bonds"] > serial["plate2d_stretch", "precracks"]
    done = _run("plate2d_stretch", out, 3, flags=["--restart"])
    assert done.returncode == 0, done.stderr
    want, reference, _ = serial["plate2d_stretch"]
    _assert_same(results_datasets(out / "results.h5"), want)
    resumed = json.loads(done.stdout)
    for key in ("steps", "broken_bonds", "max_damage", "strain_energy_j", "kinetic_energy_j"):
        assert resumed[key] == reference[key], key
