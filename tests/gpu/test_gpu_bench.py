"""``peridyn bench --backend gpu`` (the grid rows) and ``--case --backend gpu`` (whole steps)."""

import json
from pathlib import Path

import pytest
import warp_device  # noqa: F401 - skips without Warp, picks the device (before peridyn)

from peridyn.cli import main
from peridyn.jobs.bench import benchmark_grid, bytes_per_bond
from peridyn.jobs.bench_gpu import GPU_ROWS, run_gpu_benchmark

pytestmark = pytest.mark.gpu

CASES = Path(__file__).resolve().parents[2] / "cases"


def test_gpu_bench_rows():
    """Every row on the grid's directed bonds, its roof share consistent with the measured copy
    bandwidth and the CPU rows' bytes per bond (``jobs.bench``)."""
    result = run_gpu_benchmark(points=216, repeat=1, copy_bytes=1 << 20)
    _, bonds = benchmark_grid(6)
    assert [(r["model"], r["dtype"]) for r in result["results"]] == list(GPU_ROWS)
    assert result["backend"] == "gpu" and result["device_name"]
    for r in result["results"]:
        assert r["bonds"] == bonds.n_bonds and r["bond_updates_per_s"] > 0
        assert r["bytes_per_bond"] == bytes_per_bond(r["model"], r["dtype"])
        roof = result["bandwidth_bytes_per_s"] / r["bytes_per_bond"]
        assert r["memory_roof_fraction"] == pytest.approx(r["bond_updates_per_s"] / roof, rel=1e-12)


def test_gpu_bench_case(capsys):
    """Whole steps of a case on the GPU backend against its device force kernel: the step rate
    cannot beat the kernel alone by more than timing noise (a step computes the force once)."""
    args = ["bench", "--case", str(CASES / "bar_pulse.yaml"), "--backend", "gpu", "--json"]
    assert main([*args, "--set", "discretization.spacing=5e-3", "--steps", "5", "--repeat", "2"]) == 0
    result = json.loads(capsys.readouterr().out)
    assert result["backend"] == "gpu" and result["steps"] == 5
    assert "force" not in result["parts"]  # no host force on the GPU backend
    assert 0 < result["step_share"] < 1.5
