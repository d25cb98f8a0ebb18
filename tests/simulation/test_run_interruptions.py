"""Runs killed (SIGKILL) or interrupted (SIGINT, SIGTERM) in a subprocess, then restarted:
the restarted results equal an uninterrupted run's bit for bit (issue 17, items 3 and 4).

Each run is ``peridyn run`` in a fresh Python process whose ``ExplicitSolver.step`` (or
``Recorder.observe``) sends a signal to its own process at a chosen step: SIGKILL ends it
at once (no handler, no flush, as a crash or the OOM killer would), SIGINT and SIGTERM reach
the run's handlers as Ctrl-C or ``kill`` would. A first fixture runs each case for two steps
(one check reads its broken bonds), which also fills numba's cache for the runs that follow.
"""

from __future__ import annotations

import json
import os
import random
import shlex
import signal
import subprocess
import sys
import textwrap
from pathlib import Path

import h5py
import numpy as np
import pytest

import peridyn
from peridyn.io.results import Results
from peridyn.io.seal import read_seal

ROOT = Path(__file__).resolve().parents[2]
SRC = str(Path(peridyn.__file__).parents[1])

#: Shortened shipped cases: LPS (no damage), PMB with breaking bonds, PMB with contact.
CASES = {
    "bar_pulse": ("bar_pulse.yaml", ["solver.time=4e-6"], 10),
    "plate2d_precrack_pull": (
        "plate2d_precrack_pull.yaml",
        ["solver.time=10e-6", "discretization.spacing=0.5e-3", "output.snapshot_every=20"],
        15,
    ),
    "lamb_breathing_crack": ("lamb_breathing_crack.yaml", ["solver.time=6e-6"], 7),
}

#: ``python -c`` script: ``peridyn.cli.main(argv)`` whose process signals itself at step
#: KILL_AT, in PHASE "step" (right after the step, before its records and checkpoint) or
#: "record" (right after the recorder has written the step's records).
SCRIPT = textwrap.dedent(
    """
    import os, signal, sys
    from peridyn.cli import main
    from peridyn.io.recorder import Recorder
    from peridyn.solvers.explicit import ExplicitSolver

    sig, kill_at, phase = getattr(signal, sys.argv[1]), int(sys.argv[2]), sys.argv[3]
    target = {"step": ExplicitSolver, "record": Recorder}[phase]
    name = "step" if phase == "step" else "observe"
    original = getattr(target, name)

    def signalling(self, state, *args):
        result = original(self, state, *args)
        if state.step == kill_at:
            os.kill(os.getpid(), sig)
        return result

    setattr(target, name, signalling)
    sys.argv = ["peridyn", *sys.argv[4:]]
    sys.exit(main(sys.argv[1:]))
    """
)

#: Summary keys that depend on the machine, the folder or the wall clock.
VOLATILE = {"seconds", "step_seconds", "peak_memory_bytes", "output_dir", "plots", "build_seconds"}


def _argv(case: str, out: Path, *extra: str) -> list[str]:
    path, sets, _ = CASES[case]
    argv = ["run", str(ROOT / "cases" / path), "-o", str(out), "--no-progress", "--json"]
    for s in ["output.plots=false", *sets]:
        argv += ["--set", s]
    return argv + list(extra)


def _peridyn(argv, signal_name="SIGKILL", at=-1, phase="step", cwd=None):
    env = dict(os.environ, PYTHONPATH=SRC)
    return subprocess.run(
        [sys.executable, "-c", SCRIPT, signal_name, str(at), phase, *argv],
        capture_output=True,
        text=True,
        timeout=300,
        env=env,
        cwd=cwd,
    )


def _contents(out: Path) -> dict:
    """Everything a run leaves in results.h5 that does not depend on the clock or folder."""
    results = Results(out / "results.h5")
    found = {name: results.series(name) for name in results.series_names()}
    for name in ("final/u", "final/v", "final/damage"):
        if results.has(name):
            found[name] = results.array(name)
    summary = {k: v for k, v in results.summary().items() if k not in VOLATILE}
    found["summary"] = json.dumps(summary, sort_keys=True)
    found["status"] = results.status()
    return found


def _assert_same(resumed: dict, whole: dict) -> None:
    assert resumed.keys() == whole.keys()
    for key, value in whole.items():
        if isinstance(value, tuple):
            for a, b in zip(resumed[key], value, strict=True):
                np.testing.assert_array_equal(a, b, err_msg=key)
        elif isinstance(value, np.ndarray):
            np.testing.assert_array_equal(resumed[key], value, err_msg=key)
        else:
            assert resumed[key] == value, key


@pytest.fixture(scope="module")
def references(tmp_path_factory):
    """Uninterrupted runs of every case, made after a warm-up run of each (two steps);
    {case: (contents, steps, warm-up summary)}."""
    base = tmp_path_factory.mktemp("references")
    refs = {}
    for case in CASES:
        warm = _peridyn(_argv(case, base / f"{case}-warm", "--set", "solver.time=2e-7"))
        assert warm.returncode == 0, warm.stderr
        done = _peridyn(_argv(case, base / case))
        assert done.returncode == 0, done.stderr
        refs[case] = (_contents(base / case), json.loads(done.stdout)["steps"], json.loads(warm.stdout))
    return refs


def _kill_and_restart(case, references, tmp_path, at, phase):
    out = tmp_path / f"{case}-{at}-{phase}"
    every = CASES[case][2]
    killed = _peridyn(_argv(case, out, "--checkpoint-every", str(every)), "SIGKILL", at, phase)
    assert killed.returncode == -signal.SIGKILL
    assert read_seal(out / "results.h5") is None  # not sealed: read through the probe
    with h5py.File(out / "results.h5", "r") as f:  # the killed run left its status
        assert f.attrs["status"] == "running"
    resumed = _peridyn(_argv(case, out, "--checkpoint-every", str(every), "--restart"))
    assert resumed.returncode == 0, resumed.stderr
    last = (at - 1) - (at - 1) % every  # the kill comes before the checkpoint of step ``at``
    assert f"from the checkpoint at step {last} " in resumed.stderr
    _assert_same(_contents(out), references[case][0])


@pytest.mark.parametrize(
    "case, at, phase",
    [
        ("bar_pulse", 27, "record"),
        ("plate2d_precrack_pull", 95, "step"),
        ("lamb_breathing_crack", 30, "step"),
    ],
)
def test_sigkill_then_restart_equals_the_uninterrupted_run(case, at, phase, references, tmp_path):
    """A checkpointed run killed at one step and restarted gives the same bits as one run."""
    _kill_and_restart(case, references, tmp_path, at, phase)


def test_the_shortened_cases_break_bonds_and_touch(references):
    """The kill tests exercise what they are meant to: the plate breaks bonds during the run
    (more than its pre-crack's) and samples its crack; the Lamb strip runs with contact."""
    plate = json.loads(references["plate2d_precrack_pull"][0]["summary"])
    precrack = references["plate2d_precrack_pull"][2]["broken_bonds"]  # after two steps
    assert plate["broken_bonds"] > 1.5 * precrack
    assert len(plate["crack_length_history"]["length_m"]) >= 5
    assert json.loads(references["lamb_breathing_crack"][0]["summary"])["contact_rebuilds"] >= 1


@pytest.mark.slow
def test_twenty_random_sigkills_restart_bit_for_bit(references, tmp_path):
    """Issue 17 acceptance: 20 random kill points (seeded) over the three cases."""
    rng = random.Random(17)
    for _ in range(20):
        case = rng.choice(sorted(CASES))
        every, steps = CASES[case][2], references[case][1]
        _kill_and_restart(
            case, references, tmp_path, rng.randrange(every + 1, steps), rng.choice(["step", "record"])
        )


@pytest.mark.parametrize("signal_name, code", [("SIGINT", 130), ("SIGTERM", 143), ("SIGHUP", 129)])
def test_a_signal_ends_the_step_and_the_run_resumes(signal_name, code, references, tmp_path):
    """SIGINT/SIGTERM/SIGHUP (SIGHUP killed the run silently, its status left ``running``): exit
    130/143/129 with one line naming the step and the resume command,
    status ``interrupted at step N``, a checkpoint at that step (even with a checkpoint
    interval longer than the run); the resume command completes the run bit for bit."""
    case, at = "plate2d_precrack_pull", 77
    out = tmp_path / "run"
    stopped = _peridyn(_argv(case, out, "--checkpoint-every", "1000"), signal_name, at)
    assert stopped.returncode == code
    lines = stopped.stderr.strip().splitlines()
    assert "Traceback" not in stopped.stderr
    assert f"interrupted ({signal_name}) at step {at}; resume with: " in lines[-1]
    assert Results(out / "results.h5").status() == f"interrupted at step {at}"
    assert Results(out / "results.h5").series("field_u")[0][-1] <= at
    resume = shlex.split(lines[-1].split("resume with: ", 1)[1])
    assert resume[0] == "peridyn" and resume[-1] == "--restart"
    resumed = _peridyn(resume[1:])
    assert resumed.returncode == 0, resumed.stderr
    assert f"from the checkpoint at step {at}" in resumed.stderr
    _assert_same(_contents(out), references[case][0])
