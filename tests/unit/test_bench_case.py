"""``peridyn bench --case`` (``peridyn.jobs.bench_case``) on a coarse bar: what it builds, runs and
writes. No timed assertions: the rates are only checked to be positive and finite."""

import json
import math
from pathlib import Path

import pytest

from peridyn.cli import main
from peridyn.errors import InputError
from peridyn.io.case import load_case
from peridyn.jobs import bench_case
from peridyn.jobs.bench_case import run_case_benchmark
from peridyn.setup.build import build
from peridyn.setup.recording import recorder_spec
from peridyn.setup.solver_choice import step_count, time_stepper

CASES = Path(__file__).resolve().parents[2] / "cases"
BAR = CASES / "bar_pulse.yaml"
#: 2500 points; series every 2 steps, snapshots every 3; a critical stretch adds the breaking test.
TINY = [
    "discretization.spacing=0.002",
    "output.snapshot_every=3",
    "material.damage.critical_stretch=0.01",
]
KEYS = {
    "case",
    "backend",
    "points",
    "bonds",
    "steps",
    "dt",
    "seconds",
    "kernel_seconds",
    "kernel_bond_updates_per_s",
    "step_bond_updates_per_s",
    "step_share",
    "parts",
    "observer_calls",
    "records",
    "threads",
    "cpus",
    "load_average",
}


@pytest.fixture
def isolated(tmp_path, monkeypatch):
    """An empty working directory and an empty folder for temporary files."""
    work, tmp = tmp_path / "work", tmp_path / "tmp"
    work.mkdir()
    tmp.mkdir()
    monkeypatch.chdir(work)
    monkeypatch.setattr("tempfile.tempdir", str(tmp))
    return work, tmp


def test_case_benchmark_runs_the_case_as_peridyn_run(isolated):
    work, tmp = isolated
    case = load_case(BAR, TINY)
    steps = 5
    result = run_case_benchmark(case, BAR.parent, BAR, steps=steps, repeat=2)
    assert set(result) == KEYS
    # the counts are the built case's (setup.build.build, as peridyn run builds it)
    setup = build(case, BAR.parent)
    solver = time_stepper(case, setup)
    assert result["points"] == setup.body.n_points
    assert result["bonds"] == setup.bonds.n_bonds
    assert result["dt"] == solver.dt
    assert result["steps"] == steps
    for key in ("seconds", "kernel_seconds", "kernel_bond_updates_per_s", "step_bond_updates_per_s"):
        assert result[key] > 0 and math.isfinite(result[key])
    assert result["step_share"] == pytest.approx(
        result["step_bond_updates_per_s"] / result["kernel_bond_updates_per_s"], rel=1e-12
    )
    # the case's damage makes the breaking test a part of its own
    assert set(result["parts"]) == {"force", "damage", "observers", "rest"}
    assert all(result["parts"][k] > 0 for k in ("force", "damage", "observers"))
    # the observers ran after every timed step, and the recorder wrote what the case asks at the
    # initial state (step 0), the warm-up step (1) and the timed steps (2 .. steps + 1)
    assert result["observer_calls"] == steps
    spec = recorder_spec(case, setup.body, solver.dt)
    series = sum(spec.series_due(s) for s in range(steps + 2))
    snapshots = sum(spec.snapshot_due(s) for s in range(steps + 2))
    assert snapshots == 3 and series == 4  # steps 0, 3, 6 and 0, 2, 4, 6: both kinds are timed
    expected = {f"sensor_{q}": series for q in "uv"} | {"line_axis": series, "field_u": snapshots}
    assert result["records"] == expected
    # the temporary results are gone and nothing was written to the working directory
    assert list(tmp.iterdir()) == []
    assert list(work.iterdir()) == []


def test_default_steps_are_the_cases_own_capped(isolated, monkeypatch):
    cap = 4  # DEFAULT_MAX_STEPS, lowered to keep the test fast
    monkeypatch.setattr(bench_case, "DEFAULT_MAX_STEPS", cap)
    timed = []
    for end in (3e-7, 1e-6):  # s: fewer steps than the cap, and more
        case = load_case(BAR, ["discretization.spacing=0.004", f"solver.time={end}"])
        own = step_count(case, time_stepper(case, build(case, BAR.parent)))
        timed.append((own, run_case_benchmark(case, BAR.parent, repeat=1)["steps"]))
    (few, few_timed), (many, many_timed) = timed
    assert few < cap < many
    assert (few_timed, many_timed) == (few, cap)


def test_bench_case_cli_json(isolated, capsys):
    work, tmp = isolated
    sets = [a for item in TINY for a in ("--set", item)]
    assert main(["bench", "--case", str(BAR), *sets, "--steps", "2", "--repeat", "1", "--json"]) == 0
    result = json.loads(capsys.readouterr().out)
    assert set(result) == KEYS and result["steps"] == 2 and result["case"] == "bar_pulse"
    assert list(tmp.iterdir()) == [] and list(work.iterdir()) == []


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["--case", str(CASES / "bar_tension_static.yaml")], "only explicit cases are benchmarked"),
        (["--case", "no_such_case.yaml"], "no_such_case.yaml"),
        (["--steps", "3"], "give --case"),
        (["--case", str(BAR), "--points", "512"], "not a --case run"),
    ],
)
def test_bench_case_errors_are_one_line(argv, message, capsys):
    assert main(["bench", *argv]) != 0
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and message in err[0]


def test_bad_step_count():
    with pytest.raises(InputError, match="--steps"):
        run_case_benchmark(load_case(BAR, TINY), BAR.parent, steps=0)
