"""An earlier run's files are never touched unless asked, restarts refuse a checkpoint of
another run, every job records its status, and an unstable run stops before writing NaN
(issue 17, items 2, 3 and 7)."""

import hashlib
import re
import signal
from pathlib import Path

import numpy as np
import pytest
import yaml

from peridyn.cli import main
from peridyn.discretization.state import State, check_state
from peridyn.errors import InputError, InstabilityError, Interrupted
from peridyn.io.case import load_case, validate_case
from peridyn.io.outdir import json_job_status, read_status
from peridyn.io.results import Results
from peridyn.jobs.run import run_case
from peridyn.setup.build import build
from peridyn.solvers import ExplicitSolver
from peridyn.solvers.stepping import advance

ROOT = Path(__file__).resolve().parents[2]

BAR = {
    "name": "bar",
    "geometry": {"type": "box", "size": [0.012, 0.004, 0.004]},
    "discretization": {"spacing": 1e-3, "horizon": 2.015},
    "material": {"model": "pmb", "E": 70e9, "density": 2700},
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
    "output": {"every": 2, "snapshot_every": 10, "sensors": {"mid": [0.006, 0.002, 0.002]}, "plots": False},
}


def _case(solver=None, material=None, output=None):
    raw = {**BAR}
    raw["solver"] = {**BAR["solver"], **(solver or {})}
    raw["material"] = {**BAR["material"], **(material or {})}
    raw["output"] = {**BAR["output"], **(output or {})}
    return validate_case(raw)


def _digests(folder) -> dict:
    """SHA-256 of every file under ``folder`` but ``run.log``: the folder's journal, to which
    every job, a refused one too, appends its lines (docs/user-guide.md, "Outputs")."""
    return {
        p: hashlib.sha256(p.read_bytes()).hexdigest()
        for p in sorted(folder.rglob("*"))
        if p.is_file() and p.name != "run.log"
    }


@pytest.fixture(scope="module")
def finished(tmp_path_factory):
    """A finished, checkpointed run's folder."""
    out = tmp_path_factory.mktemp("finished")
    run_case(_case(), out, checkpoint_every=20)
    return out


def test_a_finished_run_is_complete(finished):
    assert Results(finished / "results.h5").status() == "complete"


@pytest.mark.parametrize(
    "kwargs, message",
    [
        ({}, "holds an earlier run's results.h5: pass --overwrite to replace it, --restart to continue"),
        (
            {"checkpoint_every": -5, "overwrite": True},
            "--checkpoint-every must be a whole number of steps >= 1",
        ),
        (
            {"checkpoint_every": -5, "restart": True},
            "--checkpoint-every must be a whole number of steps >= 1",
        ),
        ({"overwrite": True, "restart": True}, "--overwrite and --restart exclude each other"),
        (
            {"case": _case(material={"E": 100e9}), "restart": True},
            "made for another run (case: material.E 70000000000.0 -> 100000000000.0; time step",
        ),
        (
            {"case": _case(solver={"dt": 1e-8}), "restart": True},
            "(case: solver.dt None -> 1e-08; time step (s) ",
        ),
        # found by tests/fuzz: the recorder reopened results.h5 ("running") and failed on the
        # last snapshot ("step 40 does not exceed the last recorded step 40")
        ({"restart": True}, "--restart: the checkpoint is at step 40 and the run ends at step 40: nothing"),
        (
            {"case": _case(solver={"steps": 30}), "restart": True},
            "the checkpoint is at step 40 and the run ends at step 30: nothing is left to run",
        ),
    ],
)
def test_an_earlier_run_is_left_alone(finished, kwargs, message):
    """Issue 17 item 2/3: every refusal comes before a byte of the earlier run changes."""
    before = _digests(finished)
    case = kwargs.pop("case", _case())
    with pytest.raises(InputError, match=re.escape(message)) as info:
        run_case(case, finished, **kwargs)
    assert "\n" not in str(info.value)
    assert _digests(finished) == before


@pytest.mark.bitwise
def test_overwrite_replaces_and_restart_extends(finished, tmp_path):
    """--overwrite starts again; --restart with a longer run continues the checkpoint (the run
    length is not part of the case hash) and equals the longer run made in one go. Bit for bit: the
    restart continues from the checkpoint's exact state with the same operations in the same order, and
    the kernels are compiled without value-changing fast-math flags (``peridyn.kernels.FASTMATH``), so
    this holds on every CPU."""
    whole = run_case(_case(solver={"steps": 60}), tmp_path)
    again = run_case(_case(solver={"steps": 60}), tmp_path, overwrite=True)
    assert again["steps"] == 60
    resumed = run_case(_case(solver={"steps": 60}), finished, restart=True)
    assert resumed["steps"] == whole["steps"] == 60
    np.testing.assert_array_equal(
        Results(finished / "results.h5").array("final/u"), Results(tmp_path / "results.h5").array("final/u")
    )


@pytest.mark.parametrize("every, caught_at", [(2, 24), (40, 30)])
def test_instability_stops_before_a_nan_is_written(monkeypatch, tmp_path, every, caught_at):
    """A NaN appearing at step 23 is caught at the next record (every 2 steps) or, between
    rarer records, at the solver's check (every 10 steps): status failed, no NaN stored."""
    original = ExplicitSolver._acceleration

    def poisoned(self, state, **kwargs):
        original(self, state, **kwargs)
        if state.step >= 23:
            state.a[5, 1] = np.nan

    monkeypatch.setattr(ExplicitSolver, "_acceleration", poisoned)
    with pytest.raises(
        InstabilityError, match=rf"step {caught_at} .*point \d+: (displacement u|velocity v) not finite"
    ):
        run_case(_case(output={"every": every}), tmp_path)
    results = Results(tmp_path / "results.h5")
    assert results.status().startswith(f"failed: unstable at step {caught_at} ")
    for name in results.series_names():
        steps, _, data = results.series(name)
        assert np.isfinite(data).all() and steps.max() < caught_at


def test_a_runaway_displacement_is_named():
    """Finite but 100 times the body's size: a runaway, named with point and field."""
    state = State.zeros(4)
    state.u[2, 0] = 5.0
    check_state(state, 10.0)
    state.u[3, 2] = 11.0
    with pytest.raises(InstabilityError, match="point 3: displacement u above 10 m"):
        check_state(state, 10.0)


def test_modal_and_json_jobs_record_their_status(tmp_path):
    run_case(_case(solver={"type": "modal", "modes": 8, "steps": None}), tmp_path / "modal")
    assert Results(tmp_path / "modal/results.h5").status() == "complete"
    with json_job_status(tmp_path):
        assert read_status(tmp_path) == "running"
    assert read_status(tmp_path) == "complete"
    with pytest.raises(InputError), json_job_status(tmp_path):
        raise InputError("bad spacing")
    assert read_status(tmp_path) == "failed: bad spacing"


def test_the_step_loop_defers_a_signal_and_restores_the_handlers():
    """A signal raised inside a step ends the loop after that step, as Interrupted; the
    previous handler is back afterwards."""
    setup = build(_case())
    solver = ExplicitSolver(setup.model, setup.loading)
    state = solver.initial_state()

    class Stopper:
        def observe(self, state, solver):
            if state.step == 3:
                signal.raise_signal(signal.SIGTERM)

    before = signal.getsignal(signal.SIGTERM)
    with pytest.raises(Interrupted) as info:
        advance(solver, state, 10, [Stopper()])
    assert (info.value.signal_name, info.value.step, info.value.exit_code) == ("SIGTERM", 3, 143)
    assert state.step == 3
    assert signal.getsignal(signal.SIGTERM) is before


def test_the_command_line_refuses_an_earlier_runs_folder(finished, capsys):
    """``peridyn run`` (and modal, fatigue, study, demo: the same check) into a finished run's
    folder: one line naming the folder and both flags, exit status 1, no byte changed."""
    before = _digests(finished)
    case = finished / "case.yaml"
    case.write_text(yaml.safe_dump(BAR))
    before[case] = hashlib.sha256(case.read_bytes()).hexdigest()
    assert main(["run", str(case), "-o", str(finished), "--no-progress"]) == 1
    err = capsys.readouterr().err
    line = err.strip().splitlines()[-1]  # after the run's banner line
    assert "Traceback" not in err and line.startswith("peridyn run: error: output folder")
    assert str(finished) in line and "--overwrite" in line and "--restart" in line
    assert _digests(finished) == before


def test_a_run_whose_results_cannot_fit_on_the_disk_is_refused_before_writing(tmp_path):
    """``solver.time = 1e300`` ran until killed (found by tests/fuzz): its records would need more
    than any disk. The run is refused before its folder is made, naming the steps and the space."""
    out = tmp_path / "never"
    with pytest.raises(InputError, match=r"\d\.\d+e\+30\d steps .* more results than any disk holds"):
        run_case(_case(solver={"steps": None, "time": 1e300}), out)
    assert not out.exists()


@pytest.mark.parametrize(
    "case_of",
    [
        lambda: _case(),
        lambda: _case(output={"every": 1, "snapshot_every": 5, "snapshot_times": [3.3e-6, 1.0]}),
        lambda: load_case(
            ROOT / "cases" / "plate2d_precrack_pull.yaml",
            ["discretization.spacing=1e-3", "solver.time=null", "solver.steps=60", "output.plots=false"],
        ),
    ],
    ids=["bar", "bar every step", "plate2d"],
)
def test_the_output_estimate_is_within_30_percent_of_what_a_run_writes(case_of, tmp_path):
    """The disk guard estimated 2.0 MB for a run that wrote 6.9 MB: ``RecorderSpec.output_bytes``
    now counts every series in whole chunks, the geometry and final fields, the VTU snapshots
    as written (base64, 3 components) and snapshot times after the end as none. Measured
    0.77-0.93 of the bytes written for the bar and the 2D plate at two spacings each."""
    from peridyn.setup.recording import recorder_spec
    from peridyn.setup.solver_choice import step_count, time_stepper

    case = case_of()
    setup = build(case, ROOT / "cases")
    solver = time_stepper(case, setup)
    n_steps = step_count(case, solver)
    body = setup.whole_body
    estimate = recorder_spec(case, body, solver.dt).output_bytes(
        body.n_points, n_steps, body.dim, setup.damage is not None
    )
    run_case(case, tmp_path, base_dir=ROOT / "cases")
    written = sum(p.stat().st_size for p in tmp_path.rglob("*") if p.is_file())
    assert 0.7 * written <= estimate <= 1.3 * written, (estimate, written)


def _flip(path, dataset: str, index: int) -> None:
    """Invert one stored byte of ``dataset`` (a contiguous dataset of a checkpoint)."""
    import h5py

    with h5py.File(path, "r") as f:
        offset = f[dataset].id.get_offset()
    with open(path, "r+b") as f:
        f.seek(offset + index)
        byte = f.read(1)[0]
        f.seek(offset + index)
        f.write(bytes([byte ^ 0xFF]))


@pytest.fixture
def interrupted(tmp_path):
    """A finished 20-step run with its checkpoint at step 20, which a 60-step run continues."""
    run_case(_case(solver={"steps": 20}), tmp_path, checkpoint_every=20)
    return tmp_path


def test_a_restart_from_a_corrupted_checkpoint_is_refused(interrupted):
    """A checkpoint with flipped bytes was restarted from (exit 0, displacements 47x the true
    ones): now refused by its seal, naming the file, and nothing of the earlier run changes."""
    _flip(interrupted / "checkpoint.h5", "u", 11)
    before = _digests(interrupted)
    with pytest.raises(InputError, match="checkpoint.h5: its bytes do not match its seal .* --overwrite"):
        run_case(_case(solver={"steps": 60}), interrupted, restart=True)
    assert _digests(interrupted) == before


def test_a_restart_without_its_results_file_is_refused(interrupted):
    """--restart after results.h5 was deleted gave status complete with 3 of 154 sensor records."""
    (interrupted / "results.h5").unlink()
    with pytest.raises(
        InputError, match="results.h5' is missing: the records before the checkpoint's step 20"
    ):
        run_case(_case(solver={"steps": 60}), interrupted, restart=True)
    assert not (interrupted / "results.h5").exists()


def test_a_restart_with_another_runs_results_is_refused(interrupted, tmp_path_factory):
    other = tmp_path_factory.mktemp("other")
    run_case(_case(solver={"steps": 20}), other)
    (other / "results.h5").replace(interrupted / "results.h5")
    with pytest.raises(InputError, match="written by another run than the checkpoint"):
        run_case(_case(solver={"steps": 60}), interrupted, restart=True)


def test_a_folder_in_use_is_refused_and_overwrite_removes_the_earlier_files(tmp_path):
    """Two runs into one folder mixed their snapshots and lost the first's results; --overwrite
    left the earlier run's snapshots beside the new ones."""
    from peridyn.io.lock import LOCK_FILE, OutputLock

    run_case(_case(), tmp_path)  # snapshots at steps 0, 10, 20, 30, 40
    before = _digests(tmp_path)
    with OutputLock(tmp_path):  # another run writing the folder
        with pytest.raises(InputError, match=r"in use by another run \(process \d+ on "):
            run_case(_case(output={"snapshot_every": 20}), tmp_path, overwrite=True)
        assert {p: d for p, d in _digests(tmp_path).items() if p.name != LOCK_FILE} == before
    run_case(_case(output={"snapshot_every": 20}), tmp_path, overwrite=True)
    names = sorted(p.name for p in (tmp_path / "snapshots").iterdir())
    assert names == ["step_00000000.vtu", "step_00000020.vtu", "step_00000040.vtu"]
    assert not (tmp_path / LOCK_FILE).exists()
