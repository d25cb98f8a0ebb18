"""Explicit runs on lattice storage against the same runs on bond lists (shipped grid cases,
shortened), a restart on lattice storage, and what an explicit ``storage: lattice`` refuses.

Tolerance: the two storages hold each bond's reference vector differently (per offset, per
bond from rounded coordinates: ~1e-16 of the coordinates apart), so a force differs at ~1e-13
relative per evaluation (``tests/kernels/test_kernel_lattice.py``) and the stable step at
round-off; over the few hundred steps of a shortened run these stay within 1e-10 of each
series' largest value (the acceptance of lattice storage).
"""

import json
from dataclasses import replace
from pathlib import Path

import h5py
import numpy as np
import pytest
from conftest import results_datasets

from peridyn.cli import main
from peridyn.errors import CaseFileError
from peridyn.io.case import load_case
from peridyn.setup.build import build, build_points
from peridyn.setup.storage import choose_storage

ROOT = Path(__file__).resolve().parents[2]
RTOL = 1e-10
#: Shipped grid cases that lattice storage runs, with their shortened run time (s): PMB 2D with
#: a pre-crack, PMB 2D impact, LPS 3D driven by a pulse. The pulse runs until the bond strains
#: pass ~1e-5: the float64 force of either storage rounds to ~1e-16 / strain of itself
#: (``|Y| - |xi|`` cancels), so at the 1e-7 strains of its first steps neither is a reference
#: to 1e-10. (``plate2d_stretch``, edge forces ramped from 0, stays there: at 10 us its
#: displacements agree to 2e-12, its velocities, which carry that rounding at the grid's
#: highest frequencies, to 6.5e-10.)
CASES = {"plate2d_precrack_pull": 0.3e-6, "kalthoff_winkler": 0.3e-6, "bar_pulse": 3e-6}


def _run(case: str, out: Path, storage: str, capsys, *extra, time=0.3e-6) -> dict:
    args = ["run", str(ROOT / "cases" / f"{case}.yaml"), "--set", f"solver.time={time}"]
    args += ["--set", "output.plots=false", "--set", f"discretization.storage={storage}"]
    assert main([*args, *extra, "--json", "--no-progress", "-o", str(out)]) == 0
    return json.loads(capsys.readouterr().out)


@pytest.mark.parametrize("case", sorted(CASES))
def test_lattice_run_matches_bond_lists(case, tmp_path, capsys):
    """Every recorded series and final field within RTOL of the largest value of its quantity
    in the body (a displacement series of the largest displacement, a velocity series of the
    largest velocity: where the motion has not arrived, a sensor holds the rounding noise of
    the body's motion, ~1e-22 m of bond lists); the same bonds, the same broken bonds; the
    summary says which storage ran."""
    bonds = _run(case, tmp_path / "bonds", "bonds", capsys, time=CASES[case])
    lattice = _run(case, tmp_path / "lattice", "lattice", capsys, time=CASES[case])
    assert (bonds["storage"], lattice["storage"]) == ("bonds", "lattice")
    for key in ("points", "bonds", "broken_bonds", "steps"):
        assert lattice[key] == bonds[key], key
    want = results_datasets(tmp_path / "bonds" / "results.h5")
    got = results_datasets(tmp_path / "lattice" / "results.h5")
    assert sorted(got) == sorted(want)
    motion = {"u": np.abs(want["final/u"]).max(), "v": np.abs(want["final/v"]).max()}
    for name, value in want.items():
        if value.dtype.kind != "f":
            np.testing.assert_array_equal(got[name], value, err_msg=name)
            continue
        scale = max(np.abs(value).max(), motion["v" if "_v/" in name else "u"] if "/data" in name else 0.0)
        assert np.abs(got[name] - value).max() <= RTOL * scale, name
    for key in ("strain_energy_j", "kinetic_energy_j", "max_damage", "dt_s"):
        assert lattice[key] == pytest.approx(bonds[key], rel=RTOL, abs=1e-300), key


def test_lattice_restart_continues_the_run(tmp_path, capsys):
    """A lattice run checkpointed, then restarted to a later time, ends with the state and broken
    bits of the uninterrupted run, bit for bit (bonds break on the way)."""
    case = "plate2d_stretch"
    whole = _run(case, tmp_path / "whole", "lattice", capsys, time=0.6e-6)
    _run(case, tmp_path / "parts", "lattice", capsys, "--checkpoint-every", "4")
    resumed = _run(case, tmp_path / "parts", "lattice", capsys, "--restart", time=0.6e-6)
    assert resumed["broken_bonds"] == whole["broken_bonds"] > 0
    with h5py.File(tmp_path / "whole" / "results.h5") as a, h5py.File(tmp_path / "parts" / "results.h5") as b:
        np.testing.assert_array_equal(a["final/u"][...], b["final/u"][...])
        np.testing.assert_array_equal(a["final/damage"][...], b["final/damage"][...])


@pytest.mark.parametrize(
    ("case", "edit", "named"),
    [
        ("plate2d_cyclic", [], "contact"),
        ("bimaterial_bar", [], "several blocks"),
        ("bar_tension_static", [], "static solver"),
        ("bar_pulse", ["--set", "output.stress=true"], "stress and strain outputs"),
    ],
)
def test_explicit_lattice_refuses_what_needs_bond_lists(case, edit, named, tmp_path):
    """``storage: lattice`` on a case lattice storage cannot run is refused before its bonds are
    built, naming why; ``auto`` chooses bond lists for it."""
    path = ROOT / "cases" / f"{case}.yaml"
    with pytest.raises(CaseFileError, match=named):
        build(load_case(path, ["discretization.storage=lattice", *edit[1::2]]), path.parent)
    auto = load_case(path, ["discretization.storage=auto", *edit[1::2]])
    assert choose_storage(auto, None) == "bonds"


def test_auto_takes_the_lattice_where_nothing_needs_bond_lists():
    """``storage: auto`` on a grid case that lattice storage runs (an LPS plate with the shear
    factor, PZT actuator and sensors) chooses the lattice; on a body that is not a grid (cells
    of several sizes) bond lists."""
    path = ROOT / "cases" / "lamb_plate.yaml"
    case = load_case(path, ["discretization.storage=auto"])
    body = build_points(case, path.parent)
    assert choose_storage(case, body) == "lattice"
    uneven = replace(body, cells=np.where(np.arange(body.n_points)[:, None] == 0, 2.0, 1.0) * body.cells)
    assert choose_storage(case, uneven) == "bonds"
    with pytest.raises(CaseFileError, match="not a grid"):
        choose_storage(load_case(path, ["discretization.storage=lattice"]), uneven)
