"""``mpiexec -n 2`` and ``-n 3 peridyn run`` give the serial run's results.h5 bit for bit (issue 20,
acceptance): every dataset under ``final/`` and ``series/`` equal with np.array_equal, same dtype
and shape. Shipped cases, shortened: LPS in 3D (bar_pulse), PMB in 2D with pre-crack and breaking
bonds (plate2d_stretch, a lower bond strength so that it cracks within the shorter run), both with
the stress and strain tensors (``output.stress``, ``output.strain``) and VTU snapshots (per-rank
pieces under MPI, compared with the serial snapshots point by point), and the
Kalthoff-Winkler plate (notches, pre-cracks, fracture energy, velocity loading) at 1 mm, also with
contact (radius one spacing: the impacted notch flank moves 1 mm in 30 us, so the contact list is
rebuilt, with new contact ghosts, during the run), and a cut of the seed Lamb plate that records
every kind of probe (sensors, a line, a plane, a PZT sensor) at every step.

Run with ``PYTHONPATH=src python -m pytest -m mpi -q -p no:cacheprovider`` (NUMBA_NUM_THREADS=1
per rank; the runs start after a serial warm-up run that fills numba's cache).
"""

import json
import os
import re
import shutil
import signal
import subprocess
import sys
import textwrap
import time
import xml.etree.ElementTree as ET
from pathlib import Path

import h5py
import meshio
import numpy as np
import pytest
from conftest import peridyn_process, results_datasets
from lamb_probes import LAMB_PROBES

import peridyn
from peridyn.io.vtk import read_pvtu_pieces

pytestmark = pytest.mark.mpi

ROOT = Path(__file__).resolve().parents[2]
SRC = str(Path(peridyn.__file__).parents[1])

#: per-point stress and strain tensors, written at the snapshots and the end
TENSORS = ["output.stress=true", "output.strain=true"]

CASES = {
    "bar_pulse": ("bar_pulse.yaml", ["solver.time=10e-6", "output.snapshot_every=50", *TENSORS]),
    "plate2d_stretch": (
        "plate2d_stretch.yaml",
        ["solver.time=40e-6", "material.damage.critical_bond_stress=15e6", "output.vtu=true", *TENSORS],
    ),
    "kalthoff_winkler": ("kalthoff_winkler.yaml", ["discretization.spacing=1e-3", "solver.time=30e-6"]),
    "kalthoff_contact": (
        "kalthoff_winkler.yaml",
        ["discretization.spacing=1e-3", "solver.time=30e-6", "contact.radius=1.0"],
    ),
    # the seed Lamb plate cut to 60 x 39.6 mm: every kind of probe (sensors, a line, the top
    # plane, a PZT sensor) recorded at every step, gathered as probe values only under MPI
    "lamb_probes": ("lamb_plate.yaml", [*LAMB_PROBES, "output.snapshot_times=[2.0e-6]", "solver.time=4e-6"]),
}


def _have_mpi() -> bool:
    if shutil.which("mpiexec") is None:
        return False
    try:
        import mpi4py  # noqa: F401
    except ImportError:
        return False
    return True


def _run(case: str, out: Path, ranks: int, *extra: str, flags=()) -> subprocess.CompletedProcess:
    path, sets = CASES[case]
    argv = ["run", str(ROOT / "cases" / path), "-o", str(out), "--no-progress", "--json", *flags]
    for s in ["output.plots=false", *sets, *extra]:
        argv += ["--set", s]
    return peridyn_process(argv, ranks)


@pytest.fixture(scope="module")
def serial(tmp_path_factory):
    """The serial run of every case, after a short warm-up run (numba's cache filled)."""
    if not _have_mpi():
        pytest.skip("mpiexec or mpi4py not installed (pip install 'peridyn[mpi]')")
    base = tmp_path_factory.mktemp("serial")
    refs = {}
    for case in CASES:
        warm = _run(case, base / f"{case}-warm", 1, "solver.time=2e-7")
        assert warm.returncode == 0, warm.stderr
        done = _run(case, base / case, 1)
        assert done.returncode == 0, done.stderr
        refs[case] = results_datasets(base / case / "results.h5"), json.loads(done.stdout), base / case
    return refs


def _snapshots(folder: Path) -> list[str]:
    """The files that a run's snapshots.pvd lists, in order."""
    root = ET.parse(folder / "snapshots.pvd").getroot()
    return [item.attrib["file"] for item in root.iter("DataSet")]


def _assert_same_snapshots(pieces_run: Path, serial_run: Path) -> None:
    """The .pvtu snapshots of an MPI run (per-rank .vtu pieces, read by meshio) hold every point of
    the serial run's .vtu snapshots once, with the same point data bit for bit."""
    serial, parallel = _snapshots(serial_run), _snapshots(pieces_run)
    assert len(parallel) == len(serial) > 1
    for whole_file, pvtu in zip(serial, parallel, strict=True):
        assert pvtu == whole_file.replace(".vtu", ".pvtu")
        whole = meshio.read(serial_run / whole_file)
        pieces = [meshio.read(p) for p in read_pvtu_pieces(pieces_run / pvtu)]
        points = np.concatenate([p.points for p in pieces])
        by_whole, by_pieces = np.lexsort(whole.points.T), np.lexsort(points.T)
        assert np.array_equal(whole.points[by_whole], points[by_pieces])  # every point once
        assert all(p.point_data.keys() == whole.point_data.keys() for p in pieces)
        for name, value in whole.point_data.items():
            got = np.concatenate([p.point_data[name] for p in pieces])
            assert got.dtype == value.dtype and np.array_equal(got[by_pieces], value[by_whole]), name


@pytest.mark.bitwise
@pytest.mark.parametrize("ranks", [2, 3])
@pytest.mark.parametrize("case", list(CASES))
def test_mpi_run_equals_the_serial_run_bit_for_bit(case, ranks, serial, tmp_path):
    """Each case on 2 and 3 ranks writes the serial run's results.h5 (every dataset, dtypes and shapes
    included) and VTU snapshots bit for bit, with halo traffic and per-rank metadata as expected. Bit
    for bit: each rank computes its points with the serial operations in the serial order, and the
    global sums are taken over the whole body in global point order on rank 0 (``Domain.reduce``); the
    kernels are compiled without value-changing fast-math flags (``peridyn.kernels.FASTMATH``), so this
    holds on every CPU."""
    done = _run(case, tmp_path / case, ranks)
    assert done.returncode == 0, done.stderr
    assert done.stderr.count("peridyn 0.1") <= 1  # only rank 0 speaks
    got, want = results_datasets(tmp_path / case / "results.h5"), serial[case][0]
    assert got.keys() == want.keys()
    for name, value in want.items():
        assert got[name].dtype == value.dtype and got[name].shape == value.shape, name
        assert np.array_equal(got[name], value), name
    if case not in (
        "bar_pulse",
        "lamb_probes",
    ):  # the damage cases broke bonds: the comparison covers breaking
        assert want["final/damage"].max() > 0
    if case == "lamb_probes":  # every kind of probe series is compared
        kinds = ("sensor_u", "sensor_v", "line_x_axis", "plane_top", "pzt_signal")
        assert {f"series/{k}/data" for k in kinds} <= want.keys()
    if TENSORS[0] in CASES[case][1]:  # the tensors are compared too
        assert {"final/stress", "final/strain", "final/strain_valid"} <= want.keys()
    summary = json.loads(done.stdout)  # the time loop is part of the run (docs/user-guide.md)
    assert 0.0 < summary["step_seconds"] < summary["seconds"]
    if TENSORS[0] in CASES[case][1]:  # these two write VTU snapshots
        _assert_same_snapshots(tmp_path / case, serial[case][2])
    with h5py.File(tmp_path / case / "results.h5") as f:
        assert f.attrs["mpi_ranks"] == ranks
        assert sum(int(n) for n in f.attrs["points_per_rank"][1:-1].split(",")) == len(want["final/u"])
    _assert_halo_traffic(summary, case, ranks)


def _assert_halo_traffic(summary: dict, case: str, ranks: int) -> None:
    """The counted halo traffic is what the halo plans imply: one exchange of u per step, so the
    bytes all ranks send per step are 3 float64 (24 bytes) per ghost point of all ranks (each
    ghost row is received once per step from its owner); contact adds its own halo, so only
    a lower bound holds with it. The times are parts of the rank's time loop."""
    mpi = summary["mpi"]
    per_rank = mpi["per_rank"]
    assert [r["rank"] for r in per_rank] == list(range(ranks)) and mpi["mpi_ranks"] == ranks
    assert [r["owned"] for r in per_rank] == mpi["points_per_rank"]
    assert [r["ghosts"] for r in per_rank] == mpi["ghosts_per_rank"]
    sent = sum(r["bytes_per_step"] for r in per_rank)
    if case.endswith("contact"):
        assert sent >= 24 * sum(mpi["ghosts_per_rank"])
    else:
        assert sent == pytest.approx(24 * sum(mpi["ghosts_per_rank"]), rel=1e-12)
        for r in per_rank:
            assert r["messages_per_step"] == pytest.approx(r["halo_neighbours"], rel=1e-12)
    for r in per_rank:
        assert 0.0 < r["halo_wait_seconds"] <= r["halo_seconds"] < r["step_seconds"]
        assert 0.0 < r["collective_seconds"] < r["step_seconds"] <= summary["step_seconds"]
        assert r["halo_share"] == pytest.approx(r["halo_seconds"] / r["step_seconds"], rel=1e-12)
        assert r["peak_memory_bytes"] > 100e6  # the interpreter with numpy, scipy and numba alone


def test_contact_acts_and_its_list_is_rebuilt_during_the_mpi_run(serial):
    """The contact comparison is not vacuous: the contact list was rebuilt after the first build
    (the rebuild and its new contact ghosts are covered) and the contact forces changed the
    result (the same run without ``contact`` ends elsewhere). (``array_equal`` only shows that the two
    runs differ, by far more than rounding.)"""
    (with_contact, summary, _), without = serial["kalthoff_contact"], serial["kalthoff_winkler"][0]
    assert summary["contact_rebuilds"] >= 2
    assert not np.array_equal(with_contact["final/u"], without["final/u"])


@pytest.mark.bitwise
def test_contact_on_four_ranks_equals_the_serial_run_bit_for_bit(serial, tmp_path):
    """Contact, the case with the most collectives, on four ranks: the serial run's datasets bit for
    bit, for the reasons given in ``test_mpi_run_equals_the_serial_run_bit_for_bit``."""
    done = _run("kalthoff_contact", tmp_path / "run", 4)
    assert done.returncode == 0, done.stderr
    got, want = results_datasets(tmp_path / "run" / "results.h5"), serial["kalthoff_contact"][0]
    assert got.keys() == want.keys()
    for name, value in want.items():
        assert got[name].dtype == value.dtype and np.array_equal(got[name], value), name
    assert json.loads(done.stdout)["contact_rebuilds"] == serial["kalthoff_contact"][1]["contact_rebuilds"]


def test_an_error_ends_every_rank_with_one_line(tmp_path):
    """A failure on rank 0 alone (an earlier run's results in the output folder) is raised on
    every rank: the run ends (no rank waits) with the one-line error, printed once."""
    if not _have_mpi():
        pytest.skip("mpiexec or mpi4py not installed")
    out = tmp_path / "taken"
    out.mkdir()
    (out / "results.h5").write_bytes(b"")
    done = _run("bar_pulse", out, 2, "solver.time=2e-7")
    assert done.returncode == 1
    lines = [line for line in done.stderr.splitlines() if "error:" in line]
    assert len(lines) == 1 and "holds an earlier run's results.h5" in lines[0]


#: ``python -c`` wrapper of ``peridyn`` that acts on one rank before its step ``at`` (argv: rank,
#: at, action, then peridyn's arguments): "raise" raises a MemoryError there (an error no other
#: rank knows of, as from a kernel), "mark" writes the file $PERIDYN_TEST_MARK (for the test to
#: press Ctrl-C once the run has got that far).
HOOK = textwrap.dedent(
    """
    import os, sys
    from pathlib import Path
    from peridyn.cli import main
    from peridyn.parallel.comm import world
    from peridyn.solvers.explicit import ExplicitSolver

    rank, at, action = int(sys.argv[1]), int(sys.argv[2]), sys.argv[3]
    original = ExplicitSolver.step

    def step(self, state):
        if world().rank == rank and state.step + 1 == at:
            if action == "raise":
                raise MemoryError("injected on one rank")
            Path(os.environ["PERIDYN_TEST_MARK"]).touch()
        return original(self, state)

    ExplicitSolver.step = step
    sys.exit(main(sys.argv[4:]))
    """
)


def _hooked(case, out, ranks, rank, at, action, *extra, flags=(), env=None):
    """``mpiexec -n ranks`` of ``HOOK`` on ``case`` (started, not waited for), in its own
    process group, as from a terminal."""
    path, sets = CASES[case]
    argv = ["run", str(ROOT / "cases" / path), "-o", str(out), "--no-progress", *flags]
    for s in ["output.plots=false", *sets, *extra]:
        argv += ["--set", s]
    command = ["mpiexec", "-n", str(ranks), sys.executable, "-c", HOOK, str(rank), str(at), action, *argv]
    env = dict(os.environ, PYTHONPATH=SRC, NUMBA_NUM_THREADS="1", **(env or {}))
    return subprocess.Popen(
        command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env, start_new_session=True
    )


@pytest.mark.parametrize("rank", [0, 1])
def test_an_error_on_one_rank_inside_a_step_ends_every_rank_with_one_line(serial, rank, tmp_path):
    """An error that one rank alone raises inside a step (the others wait for its halo messages)
    ends the run at once, not a hang: the failing rank prints the one error line (rank 1's
    output is otherwise silenced) and MPI_Abort ends the others (status 1)."""
    run = _hooked("bar_pulse", tmp_path / "run", 2, rank, 5, "raise")
    stdout, stderr = run.communicate(timeout=120)
    assert run.returncode == 1, stderr
    lines = [line for line in stderr.splitlines() if "error:" in line]
    assert len(lines) == 1 and "out of memory (injected on one rank)" in lines[0], stderr


@pytest.mark.bitwise
def test_ctrl_c_stops_every_rank_at_one_step_with_a_checkpoint_and_restart_is_bit_for_bit(serial, tmp_path):
    """SIGINT to mpiexec's process group (Ctrl-C in a terminal; mpiexec forwards it to the ranks)
    after step 300 of plate2d_stretch on 2 ranks: the ranks agree on the step to stop after, the
    checkpoint holds that step, the status says it, the exit status is 130 (docs/user-guide.md);
    ``--restart`` on 3 ranks then gives the serial run's datasets bit for bit. The bits agree: the restart
    continues from the checkpoint's exact state with the same operations in the same order, and each
    rank computes its points with the serial operations in the serial order, and the global sums are
    taken over the whole body in global point order on rank 0 (``Domain.reduce``); the kernels are
    compiled without value-changing fast-math flags (``peridyn.kernels.FASTMATH``), so this holds on
    every CPU."""
    out, mark = tmp_path / "run", tmp_path / "mark"
    run = _hooked(
        "plate2d_stretch",
        out,
        2,
        0,
        300,
        "mark",
        flags=["--checkpoint-every", "100000"],
        env={"PERIDYN_TEST_MARK": str(mark)},
    )
    while not mark.exists() and run.poll() is None:
        time.sleep(0.02)
    os.killpg(run.pid, signal.SIGINT)
    stdout, stderr = run.communicate(timeout=120)
    assert run.returncode == 130, stderr
    stopped = int(re.search(r"interrupted \(SIGINT\) at step (\d+); resume with: .* --restart", stderr)[1])
    assert stopped >= 300
    with h5py.File(out / "checkpoint.h5") as f:
        assert f.attrs["step"] == stopped
    with h5py.File(out / "results.h5") as f:
        assert f.attrs["status"] == f"interrupted at step {stopped}"
    done = _run("plate2d_stretch", out, 3, flags=["--restart"])
    assert done.returncode == 0, done.stderr
    want = serial["plate2d_stretch"][0]
    got = results_datasets(out / "results.h5")
    assert got.keys() == want.keys()
    for name, value in want.items():
        assert got[name].dtype == value.dtype and np.array_equal(got[name], value), name
    _assert_same_snapshots(out, serial["plate2d_stretch"][2])


@pytest.mark.bitwise
def test_restart_on_three_ranks_from_a_two_rank_checkpoint_equals_the_serial_run(serial, tmp_path):
    """Checkpoints hold the whole body in serial numbering: a 2-rank run stopped at 38 us (its
    last checkpoint at step 1500, after the crack has started: plate2d_stretch's crack history
    shows it by 35 us) and continued on 3 ranks to 40 us gives the serial 40 us run's datasets,
    bonds broken and crack history bit for bit. The bits agree: the restart continues from the checkpoint's
    exact state with the same operations in the same order, and each rank computes its points with the
    serial operations in the serial order, and the global sums are taken over the whole body in global
    point order on rank 0 (``Domain.reduce``); the kernels are compiled without value-changing fast-math
    flags (``peridyn.kernels.FASTMATH``), so this holds on every CPU."""
    out = tmp_path / "run"
    first = _run("plate2d_stretch", out, 2, "solver.time=38e-6", flags=["--checkpoint-every", "100"])
    assert first.returncode == 0, first.stderr
    assert json.loads(first.stdout)["crack_length_history"]["length_m"][-1] > 0  # cracked before
    done = _run("plate2d_stretch", out, 3, flags=["--restart"])
    assert done.returncode == 0, done.stderr
    want, summary, folder = serial["plate2d_stretch"]
    got = results_datasets(out / "results.h5")
    assert got.keys() == want.keys()
    for name, value in want.items():
        assert got[name].dtype == value.dtype and np.array_equal(got[name], value), name
    _assert_same_snapshots(out, folder)  # the 2-rank pieces after the checkpoint rewritten by 3
    resumed = json.loads(done.stdout)
    for key in ("steps", "broken_bonds", "max_damage", "crack_length_history", "strain_energy_j"):
        assert resumed[key] == summary[key], key


def test_commands_that_do_not_run_over_ranks_are_refused_once():
    """``mpiexec -n 2 peridyn demo`` would run the same job twice into one folder: refused."""
    if not _have_mpi():
        pytest.skip("mpiexec or mpi4py not installed")
    env = dict(os.environ, PYTHONPATH=SRC)
    command = [
        "mpiexec",
        "-n",
        "2",
        sys.executable,
        "-m",
        "peridyn",
        "demo",
    ]
    done = subprocess.run(command, capture_output=True, text=True, timeout=300, env=env)
    assert done.returncode == 1
    lines = [line for line in done.stderr.splitlines() if "error:" in line]
    assert len(lines) == 1 and "does not run over MPI ranks" in lines[0]
