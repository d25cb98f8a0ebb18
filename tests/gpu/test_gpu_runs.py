"""Shipped explicit cases, shortened, on the GPU backend (Warp's CPU device in CI) against the
same runs on the CPU backend: every recorded series within 1e-10 of its largest value, the same
bonds broken. The two backends sum each family in another order (the numba float64 kernels in
row blocks, ``peridyn.discretization.pairs``), so they differ by roundings of ~1e-16 of each
bond's force, which the wave carries along: the measured differences are 1e-14 to 2e-11.
"""

import json
from pathlib import Path

import numpy as np
import pytest
import warp_device  # noqa: F401 - skips without Warp, picks the device (before peridyn)

from peridyn.cli import main
from peridyn.errors import InputError
from peridyn.io.case import load_case
from peridyn.io.exodus import read_exodus
from peridyn.io.results import Results
from peridyn.jobs.run import run_case
from peridyn.kernels.gpu import unavailable
from peridyn.setup.build import build
from peridyn.solvers import gpu_force
from peridyn.solvers.explicit_gpu import GPUExplicitSolver
from peridyn.solvers.gpu_force import device_bytes

pytestmark = pytest.mark.gpu

CASES = Path(__file__).resolve().parents[2] / "cases"
#: relative agreement of every series (docs/gpu.md)
SERIES_TOL = 1e-10
#: the bar pulse at 2.5 mm (1280 points, LPS, displacement-driven end, sensors and a line)
BAR = ["--set", "discretization.spacing=2.5e-3", "--set", "solver.time=10e-6"]
#: the pre-cracked plate at 1 mm (1600 points, PMB in 2D, velocity-driven edges), with a
#: fracture energy low enough that 9860 directed bonds break in 68 steps
PLATE = [
    "--set",
    "discretization.spacing=1e-3",
    "--set",
    "solver.time=12e-6",
    "--set",
    "material.damage.fracture_energy=20",
    "--set",
    "output.every=5",
]
#: the absorbing Lamb plate cut to 60 x 60 mm (7500 points, LPS with the shear-factor surface
#: correction, the PZT's radial displacement, absorbing layers), two sensors 5 and 12 mm from
#: the PZT; its amplitude 100 times the case's (a linear run: the same waves, scaled) so that
#: the strains at the sensors (~1e-5) keep the rounding differences below 1e-10 (at the case's
#: 1 um they measured 1e-10 to 1e-9 of the sensors' largest values, 4e-12 of the field's)
LAMB = [
    *("--set", "geometry.size=[0.06,0.06,0.002]", "--set", "absorbing.width=0.015"),
    *("--set", "actuators.pzt.center=[0.03,0.03]", "--set", "actuators.pzt.amplitude=1e-4"),
    *("--set", "solver.time=6e-6", "--set", "output.lines={}", "--set", "analysis=null"),
    *("--set", "output.series_dtype=float64"),
    *("--set", "output.sensors={a: [0.035, 0.03, 0.002], b: [0.042, 0.03, 0.0]}"),
]


def _run(case: str, extra: list[str], out: Path, capsys) -> dict:
    args = ["run", str(CASES / case), *extra, "--json", "--no-progress", "-o", str(out)]
    assert main([*args, "--set", "output.plots=false"]) == 0
    return json.loads(capsys.readouterr().out)


@pytest.mark.parametrize(
    "case, extra, dtype",
    [
        ("bar_pulse.yaml", BAR, "float64"),
        ("bar_pulse.yaml", BAR, "float32"),
        ("plate2d_precrack_pull.yaml", PLATE, "float64"),
        ("lamb_plate_absorbing.yaml", LAMB, "float64"),
    ],
    ids=["bar_pulse-lps", "bar_pulse-lps-float32", "precrack_pull-pmb-damage", "lamb-pzt-absorbing"],
)
def test_gpu_run_matches_cpu_run(case, extra, dtype, tmp_path, capsys):
    """Same files (series, steps, times), every series within ``SERIES_TOL`` of the CPU run's
    largest value (float32: 1e-5, its kernels' unit roundoff carried by the wave), the same
    number of broken bonds and the same largest damage."""
    extra = [*extra, "--set", f"solver.dtype={dtype}"]
    cpu = _run(case, extra, tmp_path / "cpu", capsys)
    gpu = _run(case, [*extra, "--backend", "gpu"], tmp_path / "gpu", capsys)
    assert gpu["steps"] == cpu["steps"] and gpu["dt_s"] == cpu["dt_s"]
    assert gpu["broken_bonds"] == cpu["broken_bonds"]
    assert gpu["max_damage"] == cpu["max_damage"]
    if "damage" in case:
        assert cpu["broken_bonds"] > 1000  # the comparison covers fracture
    tol = SERIES_TOL if dtype == "float64" else 1e-5
    c, g = Results(tmp_path / "cpu" / "results.h5"), Results(tmp_path / "gpu" / "results.h5")
    assert g.series_names() == c.series_names()
    for name in c.series_names():
        steps, times, values = c.series(name)
        g_steps, g_times, g_values = g.series(name)
        np.testing.assert_array_equal(g_steps, steps)
        np.testing.assert_array_equal(g_times, times)
        scale = np.max(np.abs(values))
        assert np.max(np.abs(g_values - values)) <= tol * scale, name
    assert sorted(p.name for p in (tmp_path / "gpu").rglob("*")) == sorted(
        p.name for p in (tmp_path / "cpu").rglob("*")
    )


def test_no_gpu_is_a_one_line_error(monkeypatch, tmp_path, capsys):
    """Without a CUDA device and without PERIDYN_GPU_ON_CPU, --backend gpu fails with one line."""
    import warp

    if warp.get_cuda_device_count() > 0:
        pytest.skip("this machine has a CUDA device: --backend gpu runs")
    monkeypatch.delenv("PERIDYN_GPU_ON_CPU", raising=False)
    args = [
        "run",
        str(CASES / "bar_pulse.yaml"),
        *BAR,
        "--backend",
        "gpu",
        "-o",
        str(tmp_path),
        "--no-progress",
    ]
    assert main(args) != 0
    err = [line for line in capsys.readouterr().err.splitlines() if line.startswith("peridyn run: error")]
    assert len(err) == 1 and "no CUDA device" in err[0] and "PERIDYN_GPU_ON_CPU=1" in err[0]
    assert "no CUDA device" in unavailable()  # what the gallery example reports when it falls back
    monkeypatch.setenv("PERIDYN_GPU_ON_CPU", "1")
    assert unavailable() is None


@pytest.fixture(scope="module")
def bar_setup():
    case = load_case(CASES / "bar_pulse.yaml", ["discretization.spacing=5e-3"])
    return build(case, CASES)


def test_contact_and_mpi_refused(bar_setup):
    """Contact and MPI ranks are named in the refusal (they are not on the GPU backend yet)."""
    with pytest.raises(InputError, match="contact"):
        GPUExplicitSolver(bar_setup.model, bar_setup.loading, contact=object())

    class TwoRanks:
        size = 2

    with pytest.raises(InputError, match="MPI ranks"):
        GPUExplicitSolver(bar_setup.model, bar_setup.loading, domain=TwoRanks())


def test_memory_estimate_counts_the_device_arrays(bar_setup):
    """The estimate made before allocating is within 10 % above the bytes the solver's device
    arrays take once allocated (bonds and points of an LPS float64 model without damage)."""
    solver = GPUExplicitSolver(bar_setup.model, bar_setup.loading)
    arrays = [*vars(solver).values(), *vars(solver.force_on_device).values(), *solver.force_on_device.xi]
    allocated = sum(a.capacity for a in arrays if isinstance(a, solver.wp.array))
    estimate = device_bytes(bar_setup.model, damage=False)["total"]
    assert allocated <= estimate <= 1.1 * allocated


def test_series_records_copy_the_probe_points_only(tmp_path, monkeypatch):
    """A series-only step copies no whole field from the device (the probe points' values are
    gathered there): over the shortened bar pulse's 64 steps and 33 series records, whole u, v
    or a come back only for the final snapshot and the end of the run (at most 3 + 3)."""
    copies = []
    original = GPUExplicitSolver.device_array

    def counted(self, name):
        copies.append(name)
        return original(self, name)

    monkeypatch.setattr(GPUExplicitSolver, "device_array", counted)
    case = load_case(CASES / "bar_pulse.yaml", [*BAR[1::2], "solver.backend=gpu", "output.plots=false"])
    summary = run_case(case, tmp_path, overwrite=True)
    steps, _, _ = Results(tmp_path / "results.h5").series("sensor_u")
    assert summary["steps"] == 64 and len(steps) == 33
    assert len(copies) <= 6


def test_a_model_larger_than_the_device_is_refused_with_the_numbers(bar_setup, monkeypatch):
    """The estimate is compared with the CUDA device's free memory before anything is allocated:
    above it, one error giving both (in GiB) and the parts (bonds, points)."""

    class SmallDevice:
        is_cuda, name, free_memory = True, "a 100 kB GPU", 100_000

    class FakeWarp:
        @staticmethod
        def get_device(name):
            return SmallDevice()

    monkeypatch.setattr(gpu_force, "warp", lambda: FakeWarp())
    need = device_bytes(bar_setup.model, damage=False)["total"]
    assert need > SmallDevice.free_memory  # 160 points: about 190 kB
    with pytest.raises(InputError) as info:
        gpu_force.check_fits(bar_setup.model, False, "cuda:0")
    message = str(info.value)
    assert "does not fit on a 100 kB GPU" in message and f"{need / 2**30:.2f} GiB" in message
    assert "0.00 GiB free" in message and "bonds in the ELL layout" in message
    SmallDevice.free_memory = need
    assert gpu_force.check_fits(bar_setup.model, False, "cuda:0")["total"] == need


def test_a_restarted_gpu_run_equals_the_uninterrupted_one(tmp_path, capsys):
    """A GPU run checkpointed at step 30 of 32 (5 us) and continued with --restart to 10 us
    (64 steps) writes every series bit for bit as the run that went through: the checkpoint holds
    the device state copied back (u, v, a) and the restart uploads it again."""
    whole = _run("bar_pulse.yaml", [*BAR, "--backend", "gpu"], tmp_path / "whole", capsys)
    first = [*BAR[:2], "--set", "solver.time=5e-6", "--backend", "gpu", "--checkpoint-every", "10"]
    _run("bar_pulse.yaml", first, tmp_path / "parts", capsys)
    resumed = _run("bar_pulse.yaml", [*BAR, "--backend", "gpu", "--restart"], tmp_path / "parts", capsys)
    assert resumed["steps"] == whole["steps"] == 64
    a, b = Results(tmp_path / "whole" / "results.h5"), Results(tmp_path / "parts" / "results.h5")
    for name in a.series_names():
        for x, y in zip(a.series(name), b.series(name), strict=True):
            np.testing.assert_array_equal(y, x)


PERIDIGM = Path(__file__).resolve().parents[1] / "data" / "peridigm"


@pytest.mark.parametrize("deck", ["WaveInBar.xml", "ElasticBondBased3D.yaml"])
def test_peridigm_decks_write_the_same_exodus_file(deck, tmp_path, capsys):
    """Peridigm decks (their conventions: the differenced velocity of prescribed displacements,
    ``solver.prescribed_velocity: difference``) on both backends: the same Exodus times and every
    nodal variable within 1e-10 of its largest value (measured: 2.3e-14 and 2.4e-13)."""
    for backend in ("cpu", "gpu"):
        args = ["run", str(PERIDIGM / deck), "--backend", backend, "--json", "--no-progress"]
        assert main([*args, "-o", str(tmp_path / backend), "--set", "output.plots=false"]) == 0
    capsys.readouterr()
    (cpu_file,) = (tmp_path / "cpu").glob("*.e")
    cpu, gpu = read_exodus(cpu_file), read_exodus(tmp_path / "gpu" / cpu_file.name)
    np.testing.assert_array_equal(gpu.times, cpu.times)
    for name, values in cpu.nodal_variables.items():
        scale = np.max(np.abs(values))
        assert np.max(np.abs(gpu.nodal_variables[name] - values)) <= SERIES_TOL * scale, name


def test_a_driver_older_than_warps_cuda_is_named(monkeypatch):
    """A machine whose NVIDIA driver predates the CUDA of the Warp wheel has no usable device: the
    error says so with both versions instead of 'no CUDA device'."""
    import peridyn.kernels.gpu as kgpu

    class OldDriver:
        get_cuda_device_count = staticmethod(lambda: 0)
        get_cuda_driver_version = staticmethod(lambda: (12, 4))
        get_cuda_toolkit_version = staticmethod(lambda: (13, 0))

    monkeypatch.delenv("PERIDYN_GPU_ON_CPU", raising=False)
    monkeypatch.setattr(kgpu, "warp", lambda: OldDriver())
    with pytest.raises(InputError, match=r"driver supports CUDA 12\.4, older than the CUDA 13\.0"):
        kgpu.device()
