"""``peridyn monitor`` end to end on the small notched-hole plate of cases/monitoring/monitor_small.yaml: a
fatigue life, three interrogations by three PZTs, the dataset, the summary, the figures redrawn
by ``peridyn plot`` and resuming; the Dask executor gives the serial job's dataset.

Runs have one numba thread (``--threads 1``): on a loaded machine two threads wait on each other
at every step. Every run is deterministic (the same kernels, the same order of sums; sensor noise
from a seeded generator), so the datasets of two executors agree bit for bit (the sweeps'
executors: tests/simulation/test_sweep.py).
"""

import io
import json
import shutil
from contextlib import redirect_stdout
from pathlib import Path

import matplotlib.image
import numpy as np
import pytest
import xarray as xr

from peridyn.cli import main
from peridyn.errors import InputError
from peridyn.io.dataset import load_dataset
from peridyn.io.job_files import read_job
from peridyn.jobs.monitor import run_monitor
from peridyn.jobs.sweep_run import RECORD

TINY = Path(__file__).parents[2] / "cases" / "monitoring" / "monitor_small.yaml"
SETS = ["check_transfer=false"]


@pytest.fixture(scope="module")
def serial(tmp_path_factory):
    """The job by the serial executor via the CLI: (summary, output folder, its dataset as written)."""
    out = tmp_path_factory.mktemp("serial") / "mon"
    args = ["monitor", str(TINY), "-o", str(out), "--set", *SETS, "--threads", "1", "--json"]
    with redirect_stdout(io.StringIO()) as stdout:
        assert main(args) == 0
    summary = json.loads(stdout.getvalue())
    return summary, out, load_dataset(out / "monitoring.nc", "monitoring dataset")


def test_monitor_job_writes_a_labelled_dataset_and_its_summary_and_resumes(serial, tmp_path, capsys):
    summary, out, dataset = serial
    m = summary["monitoring"]
    assert summary["kind"] == "monitor"
    assert m["interrogations"] >= 3 and m["final_crack_length_m"] >= 2e-3
    # the crack grows along y = 20 mm from x = 20 mm: it crosses the path x = 22 mm (t0-t1) only
    assert m["crossed_paths"] == ["t0-t1"]
    assert {"crossed_spearman_min", "crossed_above_uncrossed", "image_peak_error_max_m"} <= m.keys()
    job = read_job(out)  # the output contract of every job kind (peridyn.io.job_files)
    assert job["status"] == "complete" and job["summary"] == summary
    assert job["provenance"]["case_file"] == str(TINY) and "case_json" in job["provenance"]
    _figures_redrawn_from_the_dataset(out, summary["plots"], tmp_path / "drawn", capsys)
    with xr.open_dataset(out / "monitoring.nc", engine="h5netcdf") as ds:
        assert ds["signal"].dims == ("interrogation", "path", "time")
        assert ds["correlation_index"].dims == ("interrogation", "path")
        for name in ds.data_vars:
            assert ds[name].attrs["units"] and ds[name].attrs["long_name"], name
        # the baseline against itself: the index is exactly 0 on every path
        assert np.all(ds["residual_energy_index"][0] == 0.0)
        # the crossed path's index grows from the first growth to the last interrogation (once
        # the crack has crossed the path it may level off: the direct wave is blocked already)
        crossed = ds["correlation_index"].sel(path="t0-t1").values
        assert crossed[-1] > crossed[1] > 0.0
        assert m["crossed_above_uncrossed"] is True
        assert ds["crack_length"][-1] == pytest.approx(m["final_crack_length_m"])
    # a finished folder is refused; without its summary the job resumes and redoes only the run
    # whose folder was removed
    with pytest.raises(InputError, match="monitor.json"):
        run_monitor(TINY, out, overrides=SETS)
    (out / "monitor.json").unlink()
    runs = sorted((out / "interrogations").iterdir())
    kept = {p.name: json.loads((p / RECORD).read_text())["finished"] for p in runs}
    shutil.rmtree(runs[-1])
    again = run_monitor(TINY, out, overrides=SETS, threads=1)
    after = {p.name: json.loads((p / RECORD).read_text())["finished"] for p in runs}
    assert [name for name in kept if after[name] != kept[name]] == [runs[-1].name]
    assert again["monitoring"] == m
    xr.testing.assert_identical(load_dataset(out / "monitoring.nc", "monitoring dataset"), dataset)


def test_dask_executor_gives_the_serial_dataset(serial, tmp_path):
    """A local Dask cluster of 2 workers, one thread each: the serial job's dataset bit for bit."""
    pytest.importorskip("dask.distributed", reason="the dask executor needs the sweep extra")
    summary, _, dataset = serial
    other = run_monitor(TINY, tmp_path / "dask", overrides=SETS, executor="dask", workers=2, threads=1)
    assert other["monitoring"] == summary["monitoring"]
    xr.testing.assert_identical(load_dataset(other["dataset"], "monitoring dataset"), dataset)


@pytest.mark.parametrize(("executor", "scheduler"), [("processes", None), ("serial", "tcp://host:8786")])
def test_an_executor_under_mpi_is_refused_in_one_line(tmp_path, executor, scheduler):
    """Under mpiexec each run goes over the ranks: an executor of its own would run every run on
    every rank. The refusal comes before anything is written."""

    class TwoRanks:  # what run_monitor asks of a communicator before the first collective call
        size, rank = 2, 0

    with pytest.raises(InputError, match="under mpiexec") as err:
        run_monitor(TINY, tmp_path / "out", executor=executor, scheduler=scheduler, comm=TwoRanks())
    assert "\n" not in str(err.value) and not (tmp_path / "out").exists()


def _figures_redrawn_from_the_dataset(out: Path, plots: list, keep: Path, capsys) -> None:
    """``peridyn plot`` of the folder with its figures removed draws them again from
    monitoring.nc alone (the interrogation runs moved away): the same pixels, as the job draws
    its figures from the same dataset."""
    assert len(plots) == 4
    keep.mkdir()
    drawn = {Path(p).name: matplotlib.image.imread(shutil.move(p, keep)) for p in plots}
    shutil.move(out / "interrogations", keep / "interrogations")
    assert main(["plot", str(out), "--json"]) == 0
    assert sorted(json.loads(capsys.readouterr().out)["plots"]) == sorted(plots)
    for name, pixels in drawn.items():
        again = matplotlib.image.imread(out / name)
        assert again.shape == pixels.shape and np.array_equal(again, pixels), name
    shutil.move(keep / "interrogations", out / "interrogations")
