"""The figure worker (``peridyn.jobs.figure_worker``): a run's figures drawn in a second process
are the same files, with the same summary, as those drawn in the run's own process; a worker
that died costs the run nothing; small, meshed, one-thread and MPI runs start none."""

import os
from pathlib import Path

import pytest

import peridyn.jobs.figure_worker as fw
import peridyn.jobs.run as run_module
from peridyn.io.case import load_case
from peridyn.jobs.run import run_case

ROOT = Path(__file__).resolve().parents[2]

#: The seed Lamb plate cut to 60 x 39.6 mm (8 250 points) and 4 us, with every figure of a plate
#: run: sensors, B-scan, final fields, the wavefield, the cut under the actuator, the PZT sensor.
SMALL_LAMB = [
    "geometry.size=[0.06, 0.0396, 0.002]",
    "actuators.pzt.center=[0.0306, 0.0198]",
    "output.sensors={top: [0.0426, 0.0198, 0.002], centre: [0.0306, 0.0198, 0.002]}",
    "output.lines={x_axis: {start: [0.0006, 0.0198, 0.002], end: [0.0594, 0.0198, 0.002], points: 50}}",
    "output.pzt_sensors={p: {center: [0.0426, 0.0198], size: 2.4e-3}}",
    "output.snapshot_times=[2.0e-6]",
    "output.vtu=false",
    "analysis={}",
    "solver.time=4e-6",
]

#: Summary entries that differ between two runs of one case (timings, memory, folder, paths).
PER_RUN = {"seconds", "step_seconds", "peak_memory_bytes", "output_dir", "plots", "provenance"}


def _case():
    return load_case(ROOT / "cases" / "lamb_plate.yaml", SMALL_LAMB)


@pytest.fixture
def worker_allowed(monkeypatch):
    """The worker's conditions met on any machine: no size floor, two threads."""
    monkeypatch.setattr(fw, "MIN_POINTS", 0)
    monkeypatch.setattr(fw, "_threads", lambda: 2)


def test_worker_draws_the_same_figures_and_summary(tmp_path, worker_allowed, monkeypatch):
    drawn_by = []

    def spy(pending, draw, *args):
        drawn_by.append("worker" if pending is not None else "run")
        return fw.figures_of(pending, draw, *args)

    monkeypatch.setattr(run_module, "figures_of", spy)
    here = run_case(_case(), tmp_path / "here", base_dir=ROOT / "cases")
    there = run_case(_case(), tmp_path / "there", base_dir=ROOT / "cases", figure_worker=True)
    assert drawn_by == ["run", "worker"]
    names = [Path(p).name for p in here["plots"]]
    assert names == [Path(p).name for p in there["plots"]]
    assert {"sensors.png", "wavefield.png", "cut_pzt.png", "pzt_sensors.png"} <= set(names)
    for name in names:  # matplotlib draws the same pixels and metadata in either process
        assert (tmp_path / "here" / name).read_bytes() == (tmp_path / "there" / name).read_bytes(), name
    assert {k: v for k, v in here.items() if k not in PER_RUN} == {
        k: v for k, v in there.items() if k not in PER_RUN
    }


def test_a_dead_worker_leaves_the_drawing_to_the_run(worker_allowed):
    with fw.figure_worker_for(_case(), ROOT / "cases") as pool:
        assert pool is not None
        with pytest.raises(fw.BrokenProcessPool):
            pool.submit(os._exit, 1).result()  # the worker dies (as if killed)
        pending = fw.submit(pool, sum, [1, 2])
        assert fw.figures_of(pending, sum, [1, 2]) == 3


@pytest.mark.parametrize(
    "why",
    ["small", "one thread", "not wanted"],
)
def test_no_worker_where_it_cannot_pay(why, monkeypatch):
    monkeypatch.setattr(fw, "_threads", lambda: 1 if why == "one thread" else 2)
    if why != "small":
        monkeypatch.setattr(fw, "MIN_POINTS", 0)
    with fw.figure_worker_for(_case(), ROOT / "cases", wanted=why != "not wanted") as pool:
        assert pool is None


#: A run's process that starts its figure worker, prints the worker's pid and is then killed
#: outright (SIGKILL: no shutdown of the pool runs).
KILLED_PARENT = """
import os, signal, sys
import peridyn.jobs.figure_worker as fw
from peridyn.io.case import load_case

fw.MIN_POINTS = 0
fw._threads = lambda: 2
if __name__ == "__main__":
    with fw.figure_worker_for(load_case(sys.argv[1], sys.argv[2:])) as pool:
        print(pool.submit(os.getpid).result(timeout=120), flush=True)
        os.kill(os.getpid(), signal.SIGKILL)
"""


def _gone(pid: int) -> bool:
    """True when ``pid`` no longer runs (no such process, or a zombie nobody reaped yet)."""
    try:
        state = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0]
    except FileNotFoundError:
        return True
    return state in ("Z", "X")


@pytest.mark.skipif(not Path("/proc").is_dir(), reason="reads process states from /proc")
def test_the_worker_ends_with_a_killed_run(tmp_path):
    """A run killed outright left its figure worker (240 MB) alive: it now ends within a second."""
    import subprocess
    import sys
    import time

    script = tmp_path / "killed.py"
    script.write_text(KILLED_PARENT)
    env = {**os.environ, "PYTHONPATH": str(ROOT / "src")}
    proc = subprocess.run(
        [sys.executable, str(script), str(ROOT / "cases" / "lamb_plate.yaml"), *SMALL_LAMB],
        capture_output=True,
        text=True,
        timeout=180,
        env=env,
    )
    assert proc.returncode == -9, proc.stderr
    worker = int(proc.stdout.split()[0])
    deadline = time.monotonic() + 5.0  # PR_SET_PDEATHSIG acts at once; the watching thread in 0.5 s
    while not _gone(worker) and time.monotonic() < deadline:
        time.sleep(0.05)
    gone = _gone(worker)
    if not gone:
        os.kill(worker, 9)
    assert gone
