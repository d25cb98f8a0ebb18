"""Memory estimated before allocation by the dispersion, modal and sweep commands (as lamb's
Rayleigh-Lamb scan is, tests/unit/cli/test_cli_bounds.py): a request beyond the machine is
refused at once with one line giving the numbers, and the estimates follow measured peaks."""

from __future__ import annotations

import time
import tracemalloc
import warnings
from pathlib import Path

import numpy as np
import pytest
import yaml

from peridyn.analysis.dispersion import Medium, dispersion_relation, relation_bytes
from peridyn.cli import main

ROOT = Path(__file__).resolve().parents[3]
DISPERSION = ["dispersion", "--model", "pmb", "--rho", "7800", "--E", "2e11", "--nu", "0.25"]
STEEL = Medium(2e11, 0.25, 7800)


def _refused(argv: list[str], capsys) -> tuple[str, float]:
    """Run ``argv``; its error line and the peak of Python's allocations (bytes) meanwhile."""
    tracemalloc.start()
    start = time.perf_counter()
    status = main(argv)
    elapsed = time.perf_counter() - start
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    err = capsys.readouterr().err.strip().splitlines()
    assert status == 1 and elapsed < 30.0, err
    assert "Traceback" not in "\n".join(err)
    return err[-1], peak


def test_dispersion_of_too_many_wavenumbers_is_refused_before_allocating(capsys):
    """``--points 1e9`` asked numpy for 51 TiB (an "out of memory" after the attempt): now refused
    with the estimate, having allocated under 20 MB."""
    line, peak = _refused(
        [*DISPERSION, "--horizon", "3e-3", "--spacing", "1e-3", "--points", "1000000000"], capsys
    )
    assert line.startswith("peridyn dispersion: error: the dispersion relation at 1e+09 wavenumbers")
    assert "GB, more than the" in line and "--points" in line
    assert peak < 20e6


def test_dispersion_of_a_huge_lattice_horizon_is_refused_before_the_search(capsys):
    """A horizon of 300 spacings: the bond search of its lattice block alone would need ~1e8 GB."""
    line, peak = _refused(
        [*DISPERSION, "--horizon", "0.3", "--spacing", "1e-3", "--discrete", "--points", "10"], capsys
    )
    assert "a horizon of 300 spacings needs about" in line
    assert peak < 20e6


@pytest.mark.parametrize(
    ("discrete", "horizon", "dim"),
    [(False, 3e-3, 3), (True, 6e-3, 3), (True, 8e-3, 3), (False, 3e-3, 2)],
)
def test_the_dispersion_estimate_follows_its_measured_peak(discrete, horizon, dim):
    """``relation_bytes`` against tracemalloc's peak of the whole relation at 400 wavenumbers, 1 mm
    spacing (measured 23-241 MB): within 25 % (TENSOR_BYTES and SEARCH_BYTES were fitted to two of
    these four cases)."""
    tracemalloc.start()
    dispersion_relation("pmb", STEEL, horizon=horizon, spacing=1e-3, dim=dim, discrete=discrete, points=400)
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    estimate = relation_bytes(horizon, 1e-3, dim, 400, discrete, np.pi / 1e-3)
    assert 0.75 * peak < estimate < 1.25 * peak


@pytest.fixture
def tiny_case(tmp_path) -> Path:
    """The bar of cases/bar_pulse.yaml at 5 mm spacing (160 points)."""
    raw = yaml.safe_load((ROOT / "cases" / "bar_pulse.yaml").read_text())
    raw["discretization"]["spacing"] = 5.0e-3
    raw["output"]["plots"] = False
    case = tmp_path / "tiny.yaml"
    case.write_text(yaml.safe_dump(raw))
    return case


def test_modal_with_too_many_modes_is_refused_before_the_build(tiny_case, tmp_path, capsys):
    """``--modes 1e8`` of a 160-point bar: the mode shapes and LOBPCG's blocks (``MODE_BYTES``) are
    part of the estimate, so it is refused before the bonds are searched or a folder is made,
    naming the modes rather than a spacing."""
    out = tmp_path / "out"
    line, _ = _refused(["modal", str(tiny_case), "--modes", "100000000", "-o", str(out)], capsys)
    assert line.startswith("peridyn modal: error: bar_pulse: this modal job would hold about 160 points")
    assert "the 100000000 modes asked for take" in line and "ask for fewer (--modes)" in line
    assert not out.exists()


def test_a_sweep_beyond_memory_is_refused_before_any_run(tmp_path, capsys):
    """A sweep whose second run is at 20 um spacing (~2e4 GB): refused before its folder is made,
    naming the run, instead of starting the first run and failing the second."""
    sweep = tmp_path / "sweep.yaml"
    spec = {
        "name": "big",
        "base": str(ROOT / "cases" / "bar_pulse.yaml"),
        "command": "run",
        "set": {"output.plots": False},
        "vary": {"product": {"discretization.spacing": [1.0e-3, 2.0e-5]}},
    }
    sweep.write_text(yaml.safe_dump(spec))
    out = tmp_path / "out"
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        line, _ = _refused(["sweep", str(sweep), "-o", str(out)], capsys)
    run = "run 1 ({'discretization.spacing': 2e-05}) needs ~"
    assert line.startswith(f"peridyn sweep: error: {sweep}: {run}")
    assert "1 at once need" in line and "fewer --workers" in line
    assert not out.exists()


def test_bloch_dispersion_of_a_huge_horizon_is_refused_before_the_tiled_model(capsys):
    """``dispersion CASE`` of the Lamb plate with a horizon of 60 spacings: its tiled model
    (123 x 123 x 3 points of ~3.4e4 bonds each) would need ~150 GB; refused at once."""
    case = str(ROOT / "cases" / "lamb_plate.yaml")
    argv = ["dispersion", case, "--frequencies", "150e3", "--set", "discretization.horizon=60"]
    line, peak = _refused(argv, capsys)
    assert line.startswith("peridyn dispersion: error: the Bloch cell of a horizon of 60 spacings needs")
    assert "GB, more than the" in line
    assert peak < 50e6


@pytest.mark.parametrize(
    ("horizon", "kind", "layers"), [(3, "block", None), (4, "block", None), (3, "plate", 4)]
)
def test_the_bloch_cell_estimate_follows_its_measured_peak(horizon, kind, layers):
    """``cell_bytes`` against tracemalloc's peak of ``bloch_cell`` (measured 4.7-42 MB): within
    the 25 % that its one constant, CELL_BOND_BYTES, allows over these three cells."""
    from peridyn.analysis.bloch import BlochLattice, bloch_cell, cell_bytes

    disc = BlochLattice(
        spacing=1e-3,
        horizon=horizon * 1e-3,
        model="pmb",
        E=2e11,
        nu=0.25,
        density=7800,
        kind=kind,
        thickness=4e-3 if kind == "plate" else None,
        layers=layers,
    )
    tracemalloc.start()
    bloch_cell(disc)
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    assert 0.75 * peak < cell_bytes(disc) < 1.3 * peak
