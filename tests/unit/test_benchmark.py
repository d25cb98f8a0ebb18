"""The benchmark machinery (``peridyn.jobs.bench``, ``peridyn bench``) on a tiny grid: structure only."""

import functools
import json

import pytest

from peridyn.cli import bench_cmd, main
from peridyn.errors import InputError
from peridyn.jobs import bench as benchmark

ROW_KEYS = {
    "model",
    "dtype",
    "points",
    "bonds",
    "bond_updates_per_s",
    "bytes_per_bond",
    "roofline_fraction",
    "speedup_vs_baseline",
}
TINY_TRIAD = 1 << 16


def _check(result, points):
    assert set(result) == {"bandwidth_bytes_per_s", "threads", "results"}
    assert result["bandwidth_bytes_per_s"] > 0
    assert isinstance(result["threads"], int) and result["threads"] >= 1
    rows = result["results"]
    assert [(r["model"], r["dtype"]) for r in rows] == list(benchmark.ROWS)
    for r in rows:
        assert set(r) == ROW_KEYS
        assert r["points"] == points
        assert r["bonds"] > 0
        assert r["bond_updates_per_s"] > 0
        assert r["bytes_per_bond"] > 0
        assert r["roofline_fraction"] > 0
        assert r["speedup_vs_baseline"] > 0
    assert rows[0]["speedup_vs_baseline"] == pytest.approx(1.0)


def test_run_benchmark_tiny_grid():
    result = benchmark.run_benchmark(points=8**3, repeat=1, triad_elements=TINY_TRIAD)
    _check(result, 512)
    assert "pmb-baseline" in benchmark.format_table(result)


def test_bench_cli_json(monkeypatch, capsys):
    monkeypatch.setattr(
        bench_cmd, "run_benchmark", functools.partial(benchmark.run_benchmark, triad_elements=TINY_TRIAD)
    )
    assert main(["bench", "--points", "512", "--repeat", "1", "--partial-volumes", "--json"]) == 0
    _check(json.loads(capsys.readouterr().out), 512)


def test_bytes_per_bond_counts_the_per_bond_arrays():
    assert benchmark.bytes_per_bond("pmb-baseline", "float64") == 4 + 8 + 8 + 1
    assert benchmark.bytes_per_bond("pmb", "float32") == 4 + 4 + 1
    assert benchmark.bytes_per_bond("lps", "float64") == 2 * (4 + 8 + 8 + 1)


def test_bad_arguments():
    with pytest.raises(InputError):
        benchmark.run_benchmark(points=4)
    with pytest.raises(InputError):
        benchmark.run_benchmark(points=512, repeat=0)
