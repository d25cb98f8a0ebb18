"""``mpiexec -n 2`` and ``-n 3 peridyn modal`` (the distributed LOBPCG: issue 20 item 5) give the
serial run's modes: elastic frequencies equal to 1e-6 relative, mode shapes with MAC above 0.999
(summed over a degenerate pair),
the same mode types, in results.h5 and modes.json of the same layout.

Reference: the serial ``peridyn modal`` of the same case (shift-invert Lanczos, VALIDATION.md V4).
Cases: the free-free PMMA plate (cases/pmma_plate.yaml) at 4 mm, and the clamped aluminium bar
(cases/bar_tension_static.yaml) at 2 mm as a modal case, 7 modes (its bending pairs whole; no
rigid modes: the held dofs enter the rigid-mode constraints and the preconditioner). The mode
types are compared where no two frequencies coincide (the square bar's bending pairs come out in
any basis of their plane, classified either way, and the orders of the later modes with them).

Run with ``PYTHONPATH=src python -m pytest -m mpi -q -p no:cacheprovider tests/mpi``.
"""

import json
import shutil
from pathlib import Path

import h5py
import numpy as np
import pytest
from conftest import peridyn_process

from peridyn.analysis.modes import mac_matrix

pytestmark = pytest.mark.mpi

ROOT = Path(__file__).resolve().parents[2]

CASES = {
    "plate": ("pmma_plate.yaml", ["discretization.spacing=4e-3"]),
    "clamped_bar": ("bar_tension_static.yaml", ["discretization.spacing=2e-3", "solver.modes=7"]),
}


def _modal(case: str, out: Path, ranks: int) -> dict:
    path, sets = CASES[case]
    argv = ["modal", str(ROOT / "cases" / path), "-o", str(out), "--json"]
    for s in ["output.plots=false", *sets]:
        argv += ["--set", s]
    done = peridyn_process(argv, ranks)
    assert done.returncode == 0, done.stderr
    return json.loads(done.stdout)


def _modes(folder: Path) -> dict:
    with h5py.File(folder / "results.h5") as f:
        return {
            "frequencies": f["modes/frequencies"][()],
            "shapes": f["modes/shapes"][()],
            "rigid": f["modes/rigid"][()].astype(bool),
            "volumes": f["geometry/volumes"][()],
        }


def _cluster_mac(mac: np.ndarray, frequencies: np.ndarray) -> np.ndarray:
    """For each serial mode, the sum of its MAC with the modes of the other run whose serial
    frequency equals its own to 1e-6 (a degenerate pair, as the square bar's two bending
    modes, is any basis of its plane): the share of the mode in that subspace, 1 when the
    subspaces agree."""
    same = np.abs(frequencies[:, None] / frequencies[None, :] - 1) < 1e-6
    return np.sum(np.where(same, mac, 0.0), axis=1)


@pytest.fixture(scope="module")
def serial(tmp_path_factory):
    if shutil.which("mpiexec") is None:
        pytest.skip("mpiexec not installed (pip install 'peridyn[mpi]')")
    pytest.importorskip("mpi4py")
    base = tmp_path_factory.mktemp("serial")
    return {case: (_modal(case, base / case, 1), _modes(base / case)) for case in CASES}


@pytest.mark.parametrize("ranks", [2, 3])
@pytest.mark.parametrize("case", list(CASES))
def test_mpi_modal_gives_the_serial_modes(case, ranks, serial, tmp_path):
    """``peridyn modal`` on 2 and 3 ranks gives the serial modes: the same points, bonds and rigid
    modes, elastic frequencies to 1e-6 (the eigensolver's tolerance), shapes with a MAC above 0.999 per
    cluster, the same mode types where no frequencies are degenerate, residuals below 1e-6. The
    rigid-mode flags are booleans, compared exactly: the rigid frequencies lie orders of magnitude below
    the elastic ones."""
    want_summary, want = serial[case]
    summary = _modal(case, tmp_path / "run", ranks)
    got = _modes(tmp_path / "run")
    assert summary["points"] == want_summary["points"] and summary["bonds"] == want_summary["bonds"]
    assert summary["rigid_modes"] == want_summary["rigid_modes"] == (6 if case == "plate" else 0)
    assert got["shapes"].shape == want["shapes"].shape
    np.testing.assert_array_equal(got["rigid"], want["rigid"])
    e = ~want["rigid"]
    np.testing.assert_allclose(got["frequencies"][e], want["frequencies"][e], rtol=1e-6)
    mac = mac_matrix(want["shapes"][e], got["shapes"][e], want["volumes"])  # uniform density
    assert _cluster_mac(mac, want["frequencies"][e]).min() > 0.999
    f = want["frequencies"]
    if np.all(np.abs(np.diff(f[e])) > 1e-6 * f[e][1:]):  # no degenerate pair (whose basis is any)
        for a, b in zip(summary["modes"], want_summary["modes"], strict=True):
            assert (a["type"], a["order"]) == (b["type"], b["order"])
    assert max(m["residual"] for m in summary["modes"]) < 1e-6


#: the static case: the clamped bar under 100 N at 2 mm, LPS as well as the case's PMB
STATIC = ("bar_tension_static.yaml", ["discretization.spacing=2e-3", "output.plots=false"])


def _static(out: Path, ranks: int, *extra: str) -> dict:
    argv = ["run", str(ROOT / "cases" / STATIC[0]), "-o", str(out), "--json", "--no-progress"]
    for s in [*STATIC[1], *extra]:
        argv += ["--set", s]
    done = peridyn_process(argv, ranks)
    assert done.returncode == 0, done.stderr
    return json.loads(done.stdout)


@pytest.mark.parametrize("ranks", [2, 3])
@pytest.mark.parametrize("material", ["pmb", "lps"])
def test_mpi_static_reaches_the_serial_equilibrium(material, ranks, tmp_path):
    """The MPI static run (modified Newton + CG) stops at an equilibrium that meets the serial
    criterion: the serial model's out-of-balance force at the MPI displacement, relative to the
    larger of load and reactions (``solvers.relaxation``), is below the case's tolerance; and the
    serial run (dynamic relaxation) meets the same criterion."""
    if shutil.which("mpiexec") is None:
        pytest.skip("mpiexec not installed")
    pytest.importorskip("mpi4py")
    from peridyn.io.case import load_case
    from peridyn.setup.build import build
    from peridyn.solvers.relaxation import _relative_residual

    extra = [f"material.model={material}"]
    runs = {r: _static(tmp_path / f"r{r}", r, *extra) for r in (1, ranks)}
    case = load_case(ROOT / "cases" / STATIC[0], [*STATIC[1], *extra])
    setup = build(case, ROOT / "cases")
    free = ~setup.loading.constrained
    b = setup.loading.body_force_density(1.0, np.zeros((setup.body.n_points, 3)))
    for r, summary in runs.items():
        with h5py.File(tmp_path / f"r{r}" / "results.h5") as f:
            u = f["final/u"][()]
        residual = _relative_residual(np.asarray(setup.model.force(u), dtype=float), b, free)
        assert residual < case.solver.tolerance, r
        assert summary["points"] == runs[1]["points"] and summary["bonds"] == runs[1]["bonds"]
