"""``peridyn plot DIR`` redraws the figures of a fatigue job, a convergence study, a sweep and a
monitoring job from the files they leave (crack_length.csv, study.json, dataset.nc,
monitoring.nc), not only a run's."""

from __future__ import annotations

import json
from pathlib import Path

import matplotlib.image
import numpy as np
import pytest

from peridyn.cli import main
from peridyn.io.dataset import build_dataset, write_dataset
from peridyn.jobs.study import StudyRun, fit_series, write_study

ROOT = Path(__file__).resolve().parents[3]
H = (4e-3, 2e-3, 1e-3)  # spacings of the study's levels, m


def _plotted(argv, capsys) -> list[str]:
    assert main(["plot", *argv, "--json"]) == 0
    return json.loads(capsys.readouterr().out)["plots"]


def test_fatigue_folder_gets_its_crack_length_figure(tmp_path, capsys):
    (tmp_path / "fatigue.json").write_text("{}")
    (tmp_path / "crack_length.csv").write_text(
        "cycles,crack_length_m,fatigue_broken_bonds\n0,0.005,0\n1000,0.0055,4\n2500,0.0061,9\n"
    )
    assert _plotted([str(tmp_path)], capsys) == [str(tmp_path / "crack_length.png")]
    assert matplotlib.image.imread(tmp_path / "crack_length.png").shape[2] in (3, 4)


def test_study_folder_gets_its_convergence_figure(tmp_path, capsys):
    """Three levels of one horizon, frequencies converging as f = 1000 + 50 h^2 (h in mm)."""
    runs = [
        StudyRun(h, 1.4143, 100, 1000, 1.0, {"1st bending": 1000 + 50 * (h * 1e3) ** 2})
        for h in (4e-3, 2e-3, 1e-3)
    ]
    write_study(tmp_path, runs, fit_series(runs), {"case": "plate"}, 0.0)
    assert _plotted([str(tmp_path)], capsys) == [str(tmp_path / "study.png")]
    assert (tmp_path / "study.png").stat().st_size > 0
    assert [StudyRun.from_dict(r.to_dict()) for r in runs] == runs


def test_sweep_folder_gets_its_figures_from_the_dataset(tmp_path, capsys):
    """The shipped demo sweep's parameters (and its derived run length); a result that varies
    gets its figure."""
    ds = build_dataset(
        {"run_id": ["a", "b", "c", "d"], "material.E": [150e9, 150e9, 200e9, 200e9],
         "material.density": [7850, 2700, 7850, 2700], "solver.time": [7e-6, 4e-6, 6e-6, 3e-6]},
        {"status": ["complete"] * 4, "time_s": [1e-5, 2e-5, 3e-5, 4e-5]},
        {},
        {"sweep_file": str(ROOT / "sweeps" / "demo.yaml")},
    )  # fmt: skip
    write_dataset(ds, tmp_path / "dataset.nc")
    assert _plotted([str(tmp_path)], capsys) == [str(tmp_path / "figures" / "time_s.png")]


def test_a_monitoring_folder_without_its_dataset_is_named(tmp_path, capsys):
    """A monitoring job's figures are redrawn from monitoring.nc alone (the end to end test:
    tests/simulation/test_monitor_job.py); without it the error names the file, in one line."""
    (tmp_path / "summary.json").write_text(json.dumps({"kind": "monitor"}))
    assert main(["plot", str(tmp_path)]) != 0
    err = capsys.readouterr().err.strip().splitlines()
    missing = f"monitoring dataset {str(tmp_path / 'monitoring.nc')!r} does not exist"
    assert len(err) == 1 and missing in err[0]


def test_a_folder_without_results_is_named(tmp_path, capsys):
    assert main(["plot", str(tmp_path)]) != 0
    err = capsys.readouterr().err.strip().splitlines()[-1]
    assert "holds no results.h5, fatigue.json, study.json or dataset.nc" in err


@pytest.fixture(autouse=True)
def _no_stray_figures():
    yield
    import matplotlib.pyplot as plt

    plt.close("all")
    np.seterr(all="warn")
