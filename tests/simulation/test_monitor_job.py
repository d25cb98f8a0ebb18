"""``peridyn monitor`` end to end on the small notched-hole plate of cases/monitoring/monitor_small.yaml: a
fatigue life, three interrogations by three PZTs, the dataset, the summary, the figures redrawn
by ``peridyn plot`` and resuming."""

import json
import shutil
from pathlib import Path

import matplotlib.image
import numpy as np
import pytest
import xarray as xr

from peridyn.cli import main
from peridyn.errors import InputError
from peridyn.io.job_files import read_job
from peridyn.jobs.monitor import run_monitor
from peridyn.jobs.sweep_run import RECORD

TINY = Path(__file__).parents[2] / "cases" / "monitoring" / "monitor_small.yaml"


def test_monitor_job_writes_a_labelled_dataset_and_its_summary_and_resumes(tmp_path, capsys):
    out = tmp_path / "mon"
    # one numba thread per run: on a loaded machine two threads wait on each other at every step
    args = ["monitor", str(TINY), "-o", str(out), "--set", "check_transfer=false", "--threads", "1", "--json"]
    assert main(args) == 0
    summary = json.loads(capsys.readouterr().out)
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
        run_monitor(TINY, out, overrides=["check_transfer=false"])
    (out / "monitor.json").unlink()
    runs = sorted((out / "interrogations").iterdir())
    kept = {p.name: json.loads((p / RECORD).read_text())["finished"] for p in runs}
    shutil.rmtree(runs[-1])
    again = run_monitor(TINY, out, overrides=["check_transfer=false"], threads=1)
    after = {p.name: json.loads((p / RECORD).read_text())["finished"] for p in runs}
    assert [name for name in kept if after[name] != kept[name]] == [runs[-1].name]
    assert again["monitoring"] == m


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
