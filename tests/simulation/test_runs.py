"""Whole runs from case files: restart equality, pre-crack separation, outputs, CLI."""

import copy
import json

import numpy as np
import pytest

from peridyn.cli import main
from peridyn.io.case import validate_case
from peridyn.io.results import Results
from peridyn.jobs.run import run_case
from peridyn.setup.build import build

BAR = {
    "name": "bar",
    "geometry": {"type": "box", "size": [0.012, 0.004, 0.004]},
    "discretization": {"spacing": 1e-3, "horizon": 2.015},
    "material": {"model": "lps", "E": 70e9, "nu": 0.3, "density": 2700},
    "node_sets": {"end": {"type": "face", "face": "x+"}},
    "boundary_conditions": [
        {
            "set": "end",
            "kind": "velocity",
            "components": "x",
            "value": {"type": "ramp", "start": 0, "end": 1e-6, "end_value": 1.0},
        }
    ],
    "solver": {"type": "explicit", "steps": 40},
    "output": {
        "every": 2,
        "snapshot_every": 10,
        "sensors": {"mid": [0.006, 0.002, 0.002]},
        "lines": {"axis": {"start": [0, 0.002, 0.002], "end": [0.012, 0.002, 0.002], "points": 12}},
        "plots": False,
    },
}


def _case(**changes):
    raw = copy.deepcopy(BAR)
    for key, value in changes.items():
        section, field = key.split("__")
        raw[section][field] = value
    return validate_case(raw)


@pytest.mark.bitwise
def test_restart_reproduces_an_uninterrupted_run(tmp_path):
    """Checkpoint at step 20, 'crash' at 30, restart to 40: identical to 40 steps in one go. Bit for
    bit: the restart continues from the checkpoint's exact state with the same operations in the same
    order, and the kernels are compiled without value-changing fast-math flags
    (``peridyn.kernels.FASTMATH``), so this holds on every CPU."""
    whole = run_case(_case(), tmp_path / "whole")
    run_case(_case(solver__steps=30), tmp_path / "split", checkpoint_every=20)
    resumed = run_case(_case(), tmp_path / "split", restart=True)
    assert resumed["steps"] == whole["steps"] == 40
    u_whole = Results(tmp_path / "whole/results.h5").array("final/u")
    u_split = Results(tmp_path / "split/results.h5").array("final/u")
    np.testing.assert_array_equal(u_split, u_whole)
    for name in ("sensor_u", "line_axis"):
        s1, t1, d1 = Results(tmp_path / "whole/results.h5").series(name)
        s2, t2, d2 = Results(tmp_path / "split/results.h5").series(name)
        np.testing.assert_array_equal(s1, s2)
        np.testing.assert_array_equal(d1, d2)


def test_outputs_are_written(tmp_path):
    summary = run_case(_case(), tmp_path)
    steps, times, data = Results(tmp_path / "results.h5").series("sensor_u")
    assert steps.tolist() == list(range(0, 41, 2))
    assert data.shape == (21, 1, 3)
    assert (tmp_path / "snapshots.pvd").is_file()
    assert len(list((tmp_path / "snapshots").glob("*.vtu"))) == 5
    assert summary["dt_s"] <= summary["stable_dt_s"]
    # the end moves at 1 m/s after the ramp: the sensor follows, no more than the end
    assert 0 < data[-1, 0, 0] < 40 * summary["dt_s"] * 1.0


def test_precracked_plate_separates_with_half_damage(tmp_path):
    """A 2D plate pulled apart across a full-width pre-crack: the halves separate and the
    damage index of the rows next to the crack is the share of the horizon disc beyond it.

    For a point at distance a = h / 2 from the crack line and horizon delta = 3 h, that share
    is the circular segment (t - sin t) / (2 pi), t = 2 acos(a / delta): 0.394 (0.5 on the
    crack line itself, the "about 0.5" of a crack face).
    """
    raw = {
        "name": "split_plate",
        "geometry": {"type": "rectangle", "size": [0.020, 0.020], "thickness": 1e-3},
        "discretization": {"spacing": 0.5e-3, "horizon": 3.015, "partial_volumes": False},
        "material": {"model": "pmb", "E": 70e9, "density": 2700, "damage": {"critical_stretch": 0.01}},
        "node_sets": {
            "top": {"type": "face", "face": "y+", "depth": 1e-3},
            "bottom": {"type": "face", "face": "y-", "depth": 1e-3},
        },
        "precracks": [{"type": "segment", "start": [-0.001, 0.010], "end": [0.021, 0.010]}],
        "boundary_conditions": [
            {"set": "top", "kind": "velocity", "components": "y", "value": 5.0},
            {"set": "bottom", "kind": "velocity", "components": "y", "value": -5.0},
        ],
        "solver": {"type": "explicit", "steps": 300},
        "output": {"snapshot_every": 300, "plots": True},
    }
    summary = run_case(validate_case(raw), tmp_path)
    results = Results(tmp_path / "results.h5")
    u, phi, x = (results.array(name) for name in ("final/u", "final/damage", "geometry/points"))
    upper, lower = x[:, 1] > 0.010, x[:, 1] < 0.010
    assert u[upper, 1].min() > 0 > u[lower, 1].max()  # the halves move apart, no bridging
    faces = np.abs(x[:, 1] - 0.010) < 0.3e-3
    t = 2 * np.arccos(0.5 / 3.015)
    segment = (t - np.sin(t)) / (2 * np.pi)
    assert np.median(phi[faces]) == pytest.approx(segment, abs=0.02)
    assert summary["max_damage"] >= segment
    assert (tmp_path / "damage.png").is_file()


def test_cli_run_json(tmp_path, capsys):
    path = tmp_path / "bar.yaml"
    import yaml

    path.write_text(yaml.safe_dump(BAR))
    code = main(
        ["run", str(path), "--json", "--no-progress", "-o", str(tmp_path / "out"), "--set", "solver.steps=10"]
    )
    assert code == 0
    summary = json.loads(capsys.readouterr().out)
    assert summary["steps"] == 10 and summary["output_dir"] == str(tmp_path / "out")
    assert summary["seconds"] > 0


def test_cli_reports_bad_case(tmp_path, capsys):
    path = tmp_path / "bad.yaml"
    path.write_text("name: x\ngeometry: {type: box, size: [1, 1]}\n")
    assert main(["validate", str(path)]) == 1
    err = capsys.readouterr().err
    assert "geometry" in err and "size" in err


def test_static_case_runs(tmp_path):
    raw = copy.deepcopy(BAR)
    raw["node_sets"]["start"] = {"type": "face", "face": "x-"}
    raw["boundary_conditions"] = [
        {"set": "start", "kind": "displacement", "components": "xyz", "value": 0.0},
        {"set": "end", "kind": "force", "components": "x", "value": 16.0},
    ]
    raw["solver"] = {"type": "static", "tolerance": 1e-7, "load_steps": 2}
    case = validate_case(raw)
    summary = run_case(case, tmp_path)
    assert summary["residual"] < 1e-7
    u = Results(tmp_path / "results.h5").array("final/u")
    # equilibrium: the bar pulls its clamped end with the whole 16 N load
    setup = build(case)
    f = setup.model.force(u) * setup.body.volumes[:, None]
    pull_on_clamp = f[setup.body.node_set("start")].sum(axis=0)
    assert pull_on_clamp[0] == pytest.approx(16.0, rel=1e-5)
    assert u[:, 0].max() > 0


def test_plot_command_redraws_a_run(tmp_path, capsys):
    """`peridyn plot DIR` rebuilds the case from the results' provenance and redraws."""
    run_case(_case(output__plots=True), tmp_path)
    for png in tmp_path.glob("*.png"):
        png.unlink()
    assert main(["plot", str(tmp_path), "--json"]) == 0
    plots = json.loads(capsys.readouterr().out)["plots"]
    assert {p.split("/")[-1] for p in plots} == {"sensors.png", "bscan_axis.png", "displacement.png"}
    assert all((tmp_path / p.split("/")[-1]).stat().st_size > 0 for p in plots)


def test_plot_command_refuses_a_folder_without_results(tmp_path, capsys):
    assert main(["plot", str(tmp_path)]) == 1
    assert "results.h5" in capsys.readouterr().err
