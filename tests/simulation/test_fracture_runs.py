"""Fracture outputs of a run: crack paths in the summary (VALIDATION.md, "Machine-readable
output") and the fracture plots."""

import pytest

from peridyn.io.case import validate_case
from peridyn.jobs.run import run_case

H = 0.5e-3


def split_plate(tmp_path):
    """A 20 x 20 mm plate cut through by a horizontal pre-crack at y = 10 mm and pulled apart:
    its crack is the pre-crack's line, 20 mm long (the rows either side of it have
    phi = 0.394 >= 0.35, docs/theory.md)."""
    raw = {
        "name": "split_plate",
        "geometry": {"type": "rectangle", "size": [0.020, 0.020], "thickness": 1e-3},
        "discretization": {"spacing": H, "horizon": 3.015, "partial_volumes": False},
        "material": {"model": "pmb", "E": 70e9, "density": 2700, "damage": {"critical_bond_stress": 700e6}},
        "node_sets": {
            "top": {"type": "face", "face": "y+", "depth": 1e-3},
            "bottom": {"type": "face", "face": "y-", "depth": 1e-3},
        },
        "precracks": [{"type": "segment", "start": [-0.001, 0.010], "end": [0.021, 0.010]}],
        "boundary_conditions": [
            {"set": "top", "kind": "velocity", "components": "y", "value": 5.0},
            {"set": "bottom", "kind": "velocity", "components": "y", "value": -5.0},
        ],
        "solver": {"type": "explicit", "steps": 200},
        "output": {"snapshot_every": 50, "plots": True, "vtu": False},
    }
    return run_case(validate_case(raw), tmp_path)


def test_run_summary_holds_the_pre_crack_as_its_crack_path(tmp_path):
    summary = split_plate(tmp_path)
    paths = summary["crack_paths"]
    assert len(paths) == 1
    (path,) = paths
    assert set(path) == {"length_m", "angle_deg", "max_deviation_m"}
    assert path["length_m"] == pytest.approx(0.020, abs=2 * H)
    assert path["angle_deg"] == pytest.approx(0.0, abs=2.0)
    assert path["max_deviation_m"] <= 0.5 * H
    history = summary["crack_length_history"]
    assert history["time_s"] == sorted(history["time_s"]) and len(history["time_s"]) == 4
    assert history["length_m"][-1] == pytest.approx(path["length_m"])
    assert (tmp_path / "crack_paths.png").is_file() and (tmp_path / "crack_length.png").is_file()


def test_plot_command_redraws_the_crack_figures_from_the_results(tmp_path, capsys):
    """`peridyn plot DIR` on a fracture run redraws the damage map with crack paths and the
    crack length against time from results.h5 alone, and finds the same crack: the
    pre-crack's line, 20 mm long and horizontal (as in the run above)."""
    import json

    from peridyn.cli import main

    split_plate(tmp_path)
    for png in ("crack_paths.png", "crack_length.png"):
        (tmp_path / png).unlink()
    assert main(["plot", str(tmp_path), "--json"]) == 0
    redrawn = json.loads(capsys.readouterr().out)
    names = {p.split("/")[-1] for p in redrawn["plots"]}
    assert {"crack_paths.png", "crack_length.png"} <= names
    assert (tmp_path / "crack_paths.png").stat().st_size > 0
    assert (tmp_path / "crack_length.png").stat().st_size > 0
    (path,) = redrawn["crack_paths"]
    assert path["length_m"] == pytest.approx(0.020, abs=2 * H)
    assert path["angle_deg"] == pytest.approx(0.0, abs=2.0)


def test_a_run_reads_its_results_once_for_its_figures(tmp_path, monkeypatch):
    """The results file of a run with damage is opened as one ``Results`` that the run's
    figures, analyses and crack figures share (before, each drawing reopened it by path:
    the field figures and the crack figures, twice here)."""
    from peridyn.io import results as results_module

    opened = []
    real = results_module.Results.__init__

    def counted(self, path):
        opened.append(str(path))
        real(self, path)

    monkeypatch.setattr(results_module.Results, "__init__", counted)
    summary = split_plate(tmp_path)
    assert opened == [str(tmp_path / "results.h5")]
    assert {"crack_paths.png", "damage.png"} <= {p.rsplit("/", 1)[-1] for p in summary["plots"]}
