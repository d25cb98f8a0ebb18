"""The benchmark machinery (``peridyn.jobs.bench``, ``peridyn bench``) on a tiny grid: structure only."""

import functools
import json

import numba
import numpy as np
import pytest

from peridyn.cli import bench_cmd, main
from peridyn.errors import InputError
from peridyn.jobs import bench as benchmark
from peridyn.physics.materials import make_model

ROW_KEYS = {
    "model",
    "dtype",
    "points",
    "bonds",
    "bond_updates_per_s",
    "half_list",
    "bytes_per_bond",
    "memory_roof_bond_updates_per_s",
    "memory_roof_fraction",
    "sqrt_per_bond",
    "div_per_bond",
    "compute_roof_bond_updates_per_s",
    "compute_roof_fraction",
    "speedup_vs_baseline",
}
TINY_TRIAD = 1 << 16


def _check(result, points):
    assert set(result) == {
        "bandwidth_bytes_per_s",
        "sqrt_per_s",
        "div_per_s",
        "threads",
        "omp_proc_bind",
        "results",
    }
    bandwidth = result["bandwidth_bytes_per_s"]
    assert bandwidth > 0
    for rates in (result["sqrt_per_s"], result["div_per_s"]):
        assert set(rates) == {"float64", "float32"} and min(rates.values()) > 0
    assert isinstance(result["threads"], int) and result["threads"] >= 1
    rows = result["results"]
    assert [(r["model"], r["dtype"]) for r in rows] == list(benchmark.ROWS)
    for r in rows:
        assert set(r) == ROW_KEYS
        assert r["points"] == points
        assert r["bonds"] > 0
        assert r["bond_updates_per_s"] > 0
        assert r["bytes_per_bond"] > 0
        assert r["half_list"] is False or (r["model"], r["dtype"]) == ("pmb", "float64")
        # the roofs as the module docstring defines them, from the rates the result reports
        rate = r["bond_updates_per_s"]
        assert r["memory_roof_bond_updates_per_s"] == pytest.approx(bandwidth / r["bytes_per_bond"])
        assert r["memory_roof_fraction"] == pytest.approx(rate / r["memory_roof_bond_updates_per_s"])
        seconds = r["sqrt_per_bond"] / result["sqrt_per_s"][r["dtype"]]
        seconds += r["div_per_bond"] / result["div_per_s"][r["dtype"]]
        assert r["compute_roof_bond_updates_per_s"] == pytest.approx(1 / seconds)
        assert r["compute_roof_fraction"] == pytest.approx(rate / r["compute_roof_bond_updates_per_s"])
        assert r["speedup_vs_baseline"] > 0
    assert rows[0]["speedup_vs_baseline"] == pytest.approx(1.0)


def test_run_benchmark_tiny_grid(monkeypatch):
    monkeypatch.delenv("OMP_PROC_BIND", raising=False)
    result = benchmark.run_benchmark(points=8**3, repeat=1, triad_elements=TINY_TRIAD)
    _check(result, 512)
    assert result["omp_proc_bind"] is None
    table = benchmark.format_table(result)
    assert "pmb-baseline" in table and "OMP_PROC_BIND" not in table
    # the table says when the threads were bound
    assert "(OMP_PROC_BIND=spread)" in benchmark.format_table({**result, "omp_proc_bind": "spread"})


def test_bench_cli_json(monkeypatch, capsys):
    monkeypatch.setattr(
        bench_cmd, "run_benchmark", functools.partial(benchmark.run_benchmark, triad_elements=TINY_TRIAD)
    )
    assert main(["bench", "--points", "512", "--repeat", "1", "--partial-volumes", "--json"]) == 0
    _check(json.loads(capsys.readouterr().out), 512)


@pytest.mark.parametrize("dtype", ["float64", "float32"])
def test_bytes_per_bond_counts_the_arrays_the_kernels_read(dtype):
    """The per-bond arrays that ``model.force`` hands its kernels (``PMBModel._kernel_force``;
    ``kernels.lps.lps_dilatation`` and ``lps_pair_force``, or their ``_cf`` forms), by their
    item sizes: float64 reads the stored bond vectors, float32 the points."""
    body, bonds = benchmark.benchmark_grid(4)
    pmb, lps = (
        make_model(m, body, bonds, E=200e9, nu=0.25, density=7850.0, dtype=dtype) for m in ("pmb", "lps")
    )
    index, flag = bonds.neighbours.itemsize, bonds.intact.itemsize
    vector = pmb.bond_vectors[0].nbytes if dtype == "float64" else 0
    inverse_length = pmb.inv_length.itemsize if dtype == "float64" else 0
    stiffness = pmb.bond_stiffness.itemsize
    assert benchmark.bytes_per_bond("pmb", dtype) == index + vector + inverse_length + stiffness + flag
    length = lps.length.itemsize if dtype == "float64" else 0
    dilatation = index + vector + length + lps.w.itemsize + flag
    assert benchmark.bytes_per_bond("lps", dtype) == dilatation + dilatation + lps.dev.itemsize
    baseline = index + bonds.length.itemsize + pmb.bond_stiffness.astype(np.float64).itemsize + flag
    assert benchmark.bytes_per_bond("pmb-baseline", "float64") == baseline


def test_half_list_row_counts_a_pairs_arrays_for_two_bond_updates():
    """The PMB float64 half list (``discretization.pairs.HalfList``) streams, per pair, the
    arrays ``kernels.pmb.pmb_pair_force`` reads and one ``intact`` flag of the full list."""
    body, bonds = benchmark.benchmark_grid(24)
    pmb = make_model("pmb", body, bonds, E=200e9, nu=0.25, density=7850.0)
    threads = numba.get_num_threads()
    try:
        numba.set_num_threads(1)  # 7 row blocks: the half list runs on up to 3 threads
        assert pmb.runs_half_list()
    finally:
        numba.set_num_threads(threads)
    p = pmb._pairs
    per_pair = p.neighbours.itemsize + p.xi[0].nbytes + p.inv_len.itemsize + p.k.itemsize + p.k_rev.itemsize
    assert (
        benchmark.bytes_per_bond("pmb", "float64", half_list=True) == (per_pair + bonds.intact.itemsize) / 2
    )
    assert benchmark.ops_per_bond("pmb", "float64", half_list=True) == (0.5, 0.5)


def test_ops_per_bond_counts_the_kernels_square_roots_and_divisions():
    """Counted in the kernels' loops (``kernels.pmb``, ``kernels.lps``): the baseline divides
    twice, the float64 PMB kernel once; float32 recomputes |xi| (a second square root)."""
    assert benchmark.ops_per_bond("pmb-baseline", "float64") == (1, 2)
    assert benchmark.ops_per_bond("pmb", "float64") == (1, 1)
    assert benchmark.ops_per_bond("pmb", "float32") == (2, 1)
    assert benchmark.ops_per_bond("lps", "float64") == (2, 1)
    assert benchmark.ops_per_bond("lps", "float32") == (4, 2)
    with pytest.raises(InputError):
        benchmark.ops_per_bond("lps", "float16")


def test_bad_arguments():
    with pytest.raises(InputError):
        benchmark.run_benchmark(points=4)
    with pytest.raises(InputError):
        benchmark.run_benchmark(points=512, repeat=0)


def test_bench_storage_lattice_adds_the_lattice_rows(monkeypatch, capsys):
    """``peridyn bench --storage lattice`` times the lattice rows in the same rounds, on the
    same bonds (a lattice bond count equal to the bond list's), each streaming one broken bit
    per bond pair and pass (the lattice kernels compute each pair once)."""
    monkeypatch.setattr(
        bench_cmd, "run_benchmark", functools.partial(benchmark.run_benchmark, triad_elements=TINY_TRIAD)
    )
    assert main(["bench", "--points", "512", "--repeat", "1", "--storage", "lattice", "--json"]) == 0
    rows = json.loads(capsys.readouterr().out)["results"]
    assert [(r["model"], r["dtype"]) for r in rows] == list(benchmark.ROWS + benchmark.LATTICE_ROWS)
    lattice = [r for r in rows if r["model"].endswith("-lattice")]
    assert {r["bonds"] for r in rows} == {rows[0]["bonds"]}
    assert [r["bytes_per_bond"] for r in lattice] == [1 / 16, 1 / 16, 2 / 16, 2 / 16]
    assert min(r["bond_updates_per_s"] for r in lattice) > 0
