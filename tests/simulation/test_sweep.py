"""Sweeps run end to end (issue 21, acceptance): the serial, process-pool and dask executors give
the same dataset on sweeps/demo.yaml; a second run skips the complete runs; a failing run is
recorded and the sweep completes; a killed worker's run is run again; Ctrl-C stops the sweep
with exit status 130 and a second run runs only the unfinished runs.

The runs are the steel bar of cases/bar_pulse.yaml on a coarse grid (1280 points), a few
hundred steps each. The serial sweep runs its kernels as compiled in this process, the pool's
workers load them from numba's cache: the datasets agree bit for bit because both give the
same roundings (tests/simulation/test_compile_cache.py).
"""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
import yaml

import peridyn
from peridyn.errors import InputError
from peridyn.io.dataset import load_sweep
from peridyn.jobs.sweep import run_sweep
from peridyn.jobs.sweep_run import CRASH_ONCE_ENV, RECORD, run_tasks, threads_per_worker

xr = pytest.importorskip("xarray", reason="sweeps need the sweep extra (pip install 'peridyn[sweep]')")
ROOT = Path(__file__).resolve().parents[2]
SRC = str(Path(peridyn.__file__).parents[1])
DEMO = ROOT / "sweeps" / "demo.yaml"
#: Values that depend on the machine or the moment, not on the numbers.
VOLATILE = ("seconds", "finished")


def tiny_sweep(tmp_path, vary, name="tiny", time_s=5e-6) -> Path:
    """A sweep of the coarse bar, ``time_s`` long, no figures."""
    path = tmp_path / f"{name}.yaml"
    spec = {
        "base": str(ROOT / "cases" / "bar_pulse.yaml"),
        "set": {
            "discretization.spacing": 2.5e-3,
            "output.snapshot_times": [],
            "output.lines": {},
            "output.plots": False,
            "solver.time": time_s,
        },
        "vary": vary,
        "outputs": {"figures": False},
    }
    path.write_text(yaml.safe_dump(spec))
    return path


@pytest.fixture(scope="module")
def serial(tmp_path_factory):
    out = tmp_path_factory.mktemp("sweep") / "serial"
    return run_sweep(DEMO, out, executor="serial"), out


def test_demo_runs_and_reports(serial):
    summary, out = serial
    assert (summary["runs"], summary["completed"], summary["failed"], summary["skipped"]) == (4, 4, 0, 0)
    ds = load_sweep(summary["dataset"])
    assert list(ds["status"].values) == ["complete"] * 4
    assert ds["sensor_u"].shape[:3] == (4, int(ds["steps"].max()) // 2 + 1, 3)  # output.every = 2
    # each run's dataset row is its own results: the steps of its summary
    for run_id, steps in zip(ds["run_id"].values, ds["steps"].values, strict=True):
        assert json.loads((out / "runs" / run_id / RECORD).read_text())["summary"]["steps"] == steps
    # physics check of the collected signals: the pulse front (|u_x| first above 1% of the
    # 1 um amplitude) reaches the 50 mm sensor after x / c, c = sqrt(E / rho) the bar speed
    # (1D theory; the bar is 10 mm wide, the pulse 50 kHz: ~100 mm long); measured 0.86 to
    # 1.0 x / c (the coarse grid's dispersion and the threshold): tolerance 20%
    c = np.sqrt(ds["material.E"].values / ds["material.density"].values)
    ux = np.abs(ds["sensor_u"].values[:, :, 0, 0])
    t = ds["sensor_u_time"].values
    arrival = np.array([t[i][np.argmax(ux[i] > 1e-8)] for i in range(4)])
    np.testing.assert_allclose(arrival, 0.05 / c, rtol=0.2)
    assert len(summary["figures"]) >= 1 and all(Path(p).is_file() for p in summary["figures"])


@pytest.mark.parametrize("executor", ["processes", "dask"])
def test_executors_give_the_serial_dataset(serial, tmp_path, executor):
    if executor == "dask":
        pytest.importorskip("dask.distributed", reason="the dask executor needs the sweep extra")
    summary, _ = serial
    other = run_sweep(DEMO, tmp_path / executor, executor=executor, workers=2)
    assert other["completed"] == 4
    xr.testing.assert_identical(
        load_sweep(summary["dataset"]).drop_vars(VOLATILE), load_sweep(other["dataset"]).drop_vars(VOLATILE)
    )


def test_second_run_skips_complete_runs(serial):
    summary, out = serial
    stamps = {p: p.stat().st_mtime_ns for p in (out / "runs").glob("*/results.h5")}
    again = run_sweep(DEMO, out, executor="serial")
    assert (again["skipped"], again["completed"]) == (4, 4)
    assert {p: p.stat().st_mtime_ns for p in stamps} == stamps  # no run was written again
    xr.testing.assert_identical(load_sweep(summary["dataset"]), load_sweep(again["dataset"]))


def test_a_failing_run_is_recorded_and_the_sweep_goes_on(tmp_path):
    path = tiny_sweep(tmp_path, {"product": {"solver.dt": [1e-7, 1e-5]}})  # 1e-5 s: above the stable step
    summary = run_sweep(path, tmp_path / "out")
    assert (summary["completed"], summary["failed"]) == (1, 1)
    ds = load_sweep(summary["dataset"])
    assert ds["status"].values[0] == "complete"
    assert ds["status"].values[1].startswith("failed: time step 1e-05 s exceeds the stable step")
    assert "InputError" in ds["error"].values[1] and np.isnan(ds["dt_s"].values[1])


def test_a_sweep_with_failed_runs_exits_non_zero_listing_each(tmp_path, capsys):
    """A sweep with a failed run exited 0: now 1, one line naming the failed run and why, and
    with --json the sweep's summary (its failed runs listed) is still the JSON on stdout."""
    from peridyn.cli import main

    path = tiny_sweep(tmp_path, {"product": {"solver.dt": [1e-7, 1e-5]}})  # 1e-5 s: above the stable step
    assert main(["sweep", str(path), "-o", str(tmp_path / "out"), "--json", "--no-progress"]) == 1
    captured = capsys.readouterr()
    summary = json.loads(captured.out)
    (failed,) = summary["failed_runs"]
    assert failed["status"].startswith("failed: time step 1e-05 s exceeds the stable step")
    line = captured.err.strip().splitlines()[-1]
    assert line.startswith(f"peridyn sweep: error: 1 of 2 runs failed ({failed['run_id']}: failed: time step")
    assert summary["error"] == line.split("error: ", 1)[1] and summary["completed"] == 1


#: A sweep's process that starts its pool as ``_run_processes`` does, prints a worker's pid
#: and is then killed outright (SIGKILL: no shutdown of the pool runs).
KILLED_SWEEP = """
import multiprocessing, os, signal
from concurrent.futures import ProcessPoolExecutor
from peridyn.jobs.sweep_run import _quiet_worker

if __name__ == "__main__":
    pool = ProcessPoolExecutor(
        1, mp_context=multiprocessing.get_context("spawn"), initializer=_quiet_worker, initargs=(os.getpid(),)
    )
    print(pool.submit(os.getpid).result(timeout=120), flush=True)
    os.kill(os.getpid(), signal.SIGKILL)
"""


@pytest.mark.skipif(not Path("/proc").is_dir(), reason="reads process states from /proc")
def test_sweep_workers_end_with_a_killed_sweep(tmp_path):
    """A killed sweep left its pool workers running: they now end with it."""
    script = tmp_path / "killed.py"
    script.write_text(KILLED_SWEEP)
    env = {**os.environ, "PYTHONPATH": str(ROOT / "src")}
    proc = subprocess.run([sys.executable, str(script)], capture_output=True, text=True, timeout=180, env=env)
    assert proc.returncode == -9, proc.stderr
    worker = int(proc.stdout.split()[0])
    deadline = time.monotonic() + 5.0  # PR_SET_PDEATHSIG acts at once; the watching thread in 0.5 s
    while not _gone(worker) and time.monotonic() < deadline:
        time.sleep(0.05)
    assert _gone(worker)


def _gone(pid: int) -> bool:
    """True when ``pid`` no longer runs (no such process, or a zombie nobody reaped yet)."""
    try:
        return Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0] in ("Z", "X")
    except FileNotFoundError:
        return True


def test_a_killed_worker_is_replaced_and_its_run_done(tmp_path, monkeypatch):
    marker = tmp_path / "crashed"
    monkeypatch.setenv(CRASH_ONCE_ENV, str(marker))  # the first run to start kills its worker
    path = tiny_sweep(tmp_path, {"product": {"material.density": [7850, 7000, 6000]}})
    summary = run_sweep(path, tmp_path / "out", executor="processes", workers=2)
    assert marker.is_file()
    assert (summary["completed"], summary["failed"]) == (3, 0)


def test_dask_without_dask_installed_names_the_extra(monkeypatch):
    monkeypatch.setitem(sys.modules, "dask.distributed", None)  # import fails as if not installed
    with pytest.raises(InputError, match=r"peridyn\[sweep\]"):
        run_tasks([], lambda record: True, executor="dask", workers=1)


def test_ctrl_c_keeps_finished_runs_and_a_second_run_does_the_rest(tmp_path):
    path = tiny_sweep(
        tmp_path, {"product": {"material.density": [7850, 7600, 7400, 7200, 7000]}}, time_s=4e-5
    )
    out = tmp_path / "out"
    command = [sys.executable, "-m", "peridyn", "sweep", str(path), "-o", str(out), "--json"]
    env = {**os.environ, "PYTHONPATH": SRC}
    proc = subprocess.Popen(command, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    deadline = time.monotonic() + 120
    while not list(out.glob(f"runs/*/{RECORD}")) and time.monotonic() < deadline and proc.poll() is None:
        time.sleep(0.05)
    proc.send_signal(signal.SIGINT)
    stdout, stderr = proc.communicate(timeout=120)
    assert proc.returncode == 130, stderr
    assert "sweep interrupted (SIGINT)" in stderr and "run the same command again" in stderr
    done = [json.loads(p.read_text()) for p in out.glob(f"runs/*/{RECORD}")]
    complete = sum(r["status"] == "complete" for r in done)
    assert 1 <= complete < 5
    ds = load_sweep(out / "dataset.nc")  # the finished runs are in the dataset
    assert int((ds["status"].values == "complete").sum()) == complete
    again = json.loads(subprocess.run(command, env=env, capture_output=True, text=True, check=True).stdout)
    assert (again["skipped"], again["completed"], again["runs"]) == (complete, 5, 5)


@pytest.mark.filterwarnings("ignore:the spacing does not divide the body")  # 4 mm: 50 -> 48 mm wide
def test_modal_sweep_against_a_reference_gives_shifts_and_mac(tmp_path):
    """sweeps/pmma_cracks.yaml on a 4 mm grid, its first two runs (edge cracks 2.5 and 5 mm):
    each elastic mode of the healthy plate is paired by MAC and its frequency change is the
    ratio of the two frequencies; a crack removes stiffness and no mass, so no paired mode
    rises (Rayleigh quotient; tolerance 1e-6 for the eigensolver), and the longer crack lowers
    the 1st in-plane bending mode more (its bending stress is largest where the crack cuts)."""
    summary = run_sweep(
        ROOT / "sweeps" / "pmma_cracks.yaml",
        tmp_path / "out",
        overrides=["discretization.spacing=4e-3", "solver.modes=12"],
        first=2,
    )
    assert (summary["completed"], summary["failed"]) == (2, 0)
    ds = load_sweep(summary["dataset"])
    reference = json.loads((tmp_path / "out" / "reference" / RECORD).read_text())["summary"]["modes"]
    for run_id in ds["run_id"].values:
        rows = json.loads((tmp_path / "out" / "runs" / run_id / RECORD).read_text())["summary"]["comparison"]
        assert len(rows) == sum(m["type"] != "rigid" for m in reference)
        for row in rows:
            assert row["frequency_change"] == pytest.approx(
                row["frequency_hz"] / row["reference_frequency_hz"] - 1
            )
            assert 0 < row["mac"] <= 1 + 1e-9 and row["frequency_change"] < 1e-6
    changes = [name for name in ds.data_vars if name.startswith("frequency_change.")]
    assert changes and all(f"mac.{n.removeprefix('frequency_change.')}" in ds for n in changes)


def test_bloch_sweep_reports_rayleigh_lamb_theory(tmp_path):
    """sweeps/lamb_layers_bloch.yaml, first run (3 layers, 1.2 mm): the theory wavenumbers in
    the dataset are Rayleigh-Lamb's S0 and A0 of the 2 mm aluminium plate (peridyn.analysis.lamb,
    checked against the literature in tests/unit/analysis), and the error is k / k0 - 1."""
    from peridyn.analysis.lamb import lamb_modes

    summary = run_sweep(ROOT / "sweeps" / "lamb_layers_bloch.yaml", tmp_path / "out", first=1)
    ds = load_sweep(summary["dataset"]).isel(run=0)
    for m in lamb_modes(68.9e9, 0.33, 2700, 0.002, [110e3, 225e3], max_order=0):
        key = f"bloch.{m.mode}.{m.frequency_hz:g}"
        assert float(ds[f"{key}.theory_rad_m"]) == pytest.approx(m.wavenumber_rad_m, rel=1e-12)
        k = float(ds[f"{key}.wavenumber_rad_m"])
        assert float(ds[f"{key}.error"]) == pytest.approx(k / m.wavenumber_rad_m - 1, rel=1e-12)


@pytest.mark.parametrize("executor", ["serial", "processes", "dask"])
def test_threads_per_run_are_set_before_each_run(tmp_path, executor):
    """--threads 1: every run's kernels ran with 1 numba thread (its record), whatever the
    executor's default (cores // workers, or the process's own); the serial sweep gives this
    process its threads back. The runs end one after the other, at the moments recorded."""
    import numba

    if executor == "dask":
        pytest.importorskip("dask.distributed", reason="the dask executor needs the sweep extra")
    before = numba.get_num_threads()
    path = tiny_sweep(tmp_path, {"product": {"material.density": [7850, 7000, 6000]}})
    start = time.time()
    summary = run_sweep(path, tmp_path / "out", executor=executor, workers=1, threads=1)
    assert summary["threads"] == 1 and summary["completed"] == 3
    records = [json.loads(p.read_text()) for p in (tmp_path / "out").glob(f"runs/*/{RECORD}")]
    assert [r["threads"] for r in records] == [1, 1, 1]
    ds = load_sweep(summary["dataset"])
    finished = np.sort(ds["finished"].values)
    assert start < finished[0] and np.all(np.diff(finished) > 0) and finished[-1] < time.time()
    assert numba.get_num_threads() == before


def test_default_threads_share_the_cores_between_the_workers(tmp_path):
    path = tiny_sweep(tmp_path, {"product": {"material.density": [7850, 7000]}})
    summary = run_sweep(path, tmp_path / "out", executor="processes", workers=2)
    records = [json.loads(p.read_text()) for p in (tmp_path / "out").glob(f"runs/*/{RECORD}")]
    assert summary["threads"] == threads_per_worker(2) and {r["threads"] for r in records} == {
        summary["threads"]
    }


def test_bad_executor_arguments_are_refused_before_anything_runs(tmp_path):
    path = tiny_sweep(tmp_path, {"product": {"material.density": [7850]}})
    with pytest.raises(InputError, match="use it with --executor dask"):
        run_sweep(path, tmp_path / "out", executor="processes", scheduler="tcp://127.0.0.1:8786")
    with pytest.raises(InputError, match="executor must be one of"):
        run_sweep(path, tmp_path / "out", executor="threads")
    with pytest.raises(InputError, match="threads must be a whole number >= 1"):
        run_sweep(path, tmp_path / "out", executor="processes", threads=0)
    assert not (tmp_path / "out").exists()


@pytest.mark.bitwise
def test_run_sweep_keeps_its_reference_series_as_the_baseline(tmp_path):
    """A run sweep with a ``reference`` (the healthy body) runs it once and its dataset holds
    the reference's series beside the runs' (``reference_sensor_u``, on the runs' sensor axis):
    a run whose case is the reference's gives the same signals bit for bit (a run is
    deterministic), and a bar of another modulus does not. The same case is computed by the same code in
    the same order, and the kernels are compiled without value-changing fast-math flags
    (``peridyn.kernels.FASTMATH``), so this holds on every CPU."""
    path = tiny_sweep(tmp_path, {"product": {"material.E": [200.0e9, 150.0e9]}})
    spec = yaml.safe_load(path.read_text())
    spec["reference"] = spec["base"]
    spec["outputs"]["series"] = ["sensor_u"]
    path.write_text(yaml.safe_dump(spec))
    summary = run_sweep(path, tmp_path / "out")
    assert (summary["completed"], summary["failed"]) == (2, 0)
    ds = load_sweep(summary["dataset"])
    baseline = ds["reference_sensor_u"]
    assert baseline.dims == ("reference_sensor_u_record", "sensor_u_axis1", "sensor_u_axis2")
    np.testing.assert_array_equal(ds["reference_sensor_u_time"].values, ds["sensor_u_time"].values[0])
    np.testing.assert_array_equal(baseline.values, ds["sensor_u"].values[0])
    assert not np.array_equal(baseline.values, ds["sensor_u"].values[1])


def test_reference_needs_a_modal_or_run_sweep(tmp_path):
    """A fatigue or Bloch sweep has nothing to compare with a reference: the sweep file is
    refused, naming ``reference``."""
    path = tiny_sweep(tmp_path, {"product": {"material.E": [200.0e9]}})
    spec = yaml.safe_load(path.read_text())
    spec.update(reference=spec["base"], command="fatigue")
    path.write_text(yaml.safe_dump(spec))
    with pytest.raises(InputError, match="reference"):
        run_sweep(path, tmp_path / "out")
