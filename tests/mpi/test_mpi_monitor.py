"""``mpiexec -n 2 peridyn monitor`` gives the serial job's monitoring.nc bit for bit, and resumes
under MPI as it does in one process.

Case: cases/monitoring/monitor_small.yaml without the transfer check (a 1 568-point fatigue
life, 3 interrogations of 3 runs of 4 704 points). Why bit for bit: an explicit run over the
ranks is the serial run bit for bit (docs/mpi.md); the fatigue under MPI solves its equilibrium by
the distributed CG to the serial tolerance (tests/mpi/test_mpi_fatigue.py), but this life's
steps are its linear mapping's, 2 000 cycles each (not adaptive), so its cycles are exact, and
the bonds that break at each step are the serial ones (measured: the same crack at every
interrogation, the same first-break cycle of every point). The job's own files are rank 0's:
the records it keeps, the dataset, figures and summary.

Run with ``PYTHONPATH=src python -m pytest -m mpi -q -p no:cacheprovider tests/mpi``.
"""

import json
import shutil
from pathlib import Path

import pytest
import xarray as xr
from conftest import peridyn_process

from peridyn.io.dataset import load_dataset
from peridyn.jobs.sweep_run import RECORD

pytestmark = pytest.mark.mpi

CASE = Path(__file__).resolve().parents[2] / "cases" / "monitoring" / "monitor_small.yaml"


def _monitor(out: Path, ranks: int) -> dict:
    """``peridyn monitor`` of the small case into ``out`` on ``ranks`` processes; its summary."""
    argv = ["monitor", str(CASE), "-o", str(out), "--set", "check_transfer=false", "--json"]
    done = peridyn_process(argv, ranks)
    assert done.returncode == 0, done.stderr
    return json.loads(done.stdout.strip().splitlines()[-1])


def _finished(out: Path) -> dict:
    """Each interrogation run's folder name and the moment its record says it ended."""
    return {
        p.name: json.loads((p / RECORD).read_text())["finished"] for p in (out / "interrogations").iterdir()
    }


def _dataset(out: Path):
    return load_dataset(out / "monitoring.nc", "monitoring dataset")


def test_mpi_monitor_gives_the_serial_dataset_and_resumes(tmp_path):
    serial = _monitor(tmp_path / "serial", 1)
    parallel = _monitor(tmp_path / "mpi", 2)
    assert parallel["monitoring"] == serial["monitoring"]
    assert parallel["plots"] and all(Path(p).is_file() for p in parallel["plots"])
    expected = load_dataset(tmp_path / "serial" / "monitoring.nc", "monitoring dataset")
    xr.testing.assert_identical(
        load_dataset(tmp_path / "mpi" / "monitoring.nc", "monitoring dataset"), expected
    )
    # resuming under MPI: only the removed run is run again, and the dataset is the same
    out = tmp_path / "mpi"
    (out / "monitor.json").unlink()
    kept = _finished(out)
    removed = sorted(kept)[-1]
    shutil.rmtree(out / "interrogations" / removed)
    again = _monitor(out, 2)
    after = _finished(out)
    assert [name for name in kept if after[name] != kept[name]] == [removed]
    assert again["monitoring"] == serial["monitoring"]
    xr.testing.assert_identical(_dataset(out), expected)
