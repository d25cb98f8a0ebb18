"""Peridigm's default Verlet step (a deck's ``Solver.Verlet`` without ``Fixed dt``,
docs/peridigm.md): the bond-based stable step of ``PeridigmNS::ComputeCriticalTimeStep``
times ``Safety Factor``, and floor(final / dt) steps, computed here independently of peridyn
from the deck's grid (Peridigm's source, src/core/Peridigm_CriticalTimeStep.cpp and the Verlet
solver of src/core/Peridigm.cpp)."""

import copy
import itertools
import math
from pathlib import Path

import numpy as np
import pytest

from peridyn.io.case import validate_case
from peridyn.io.peridigm_case import deck_case
from peridyn.io.peridigm_deck import read_deck
from peridyn.jobs.run import run_case

DATA = Path(__file__).parents[1] / "data" / "peridigm"


def _deck(model: str) -> dict:
    """Compression_3x1x1 made a 3 x 2 x 2 grid of unit cells (horizon 1.1 m: PdQuickGrid's box
    of one cell per axis, diagonals included) of ``model``, run for 1 ms with Safety Factor 0.9
    and no Fixed dt."""
    deck = copy.deepcopy(read_deck(DATA / "Compression_3x1x1.yaml"))
    grid = deck["Discretization"]["TensorProduct3DMeshGenerator"]
    grid.update({"Number Points Y": 2, "Number Points Z": 2, "Y Length": 2.0, "Z Length": 2.0})
    deck["Materials"]["My Elastic Material"]["Material Model"] = model
    if model == "Elastic Bond Based":
        for key in ("Shear Modulus", "Apply Shear Correction Factor"):
            del deck["Materials"]["My Elastic Material"][key]
    deck["Solver"]["Final Time"] = 1e-3
    deck["Solver"]["Verlet"] = {"Safety Factor": 0.9}
    deck["Output"]["Output Variables"] = {"Displacement": True, "Velocity": True}
    return deck


def _peridigm_step() -> float:
    """Peridigm's formula on the deck's grid: cell centres from X/Y/Z Origin, Length and Number
    Points; each point's neighbours within one cell along every axis; c = 18 K / (pi delta^4)
    (pi itself, as the binary that wrote Peridigm's gold files: the times of its Contact_Cubes
    test, docs/peridigm.md); dt = min_i sqrt(2 rho / sum_j V_j c / |xi_ij|) times 0.9."""
    K, rho, delta, volume = 130.0e9, 7800.0, 1.1, 1.0
    centres = [np.array(c) for c in itertools.product((-1.0, 0.0, 1.0), (-0.5, 0.5), (-0.5, 0.5))]
    c = 18.0 * K / (math.pi * delta**4)
    steps = []
    for x in centres:
        total = sum(
            volume * c / np.linalg.norm(y - x)
            for y in centres
            if np.any(y != x) and np.all(np.abs(y - x) <= 1.0 + 1e-12)
        )
        steps.append(math.sqrt(2.0 * rho / total))
    return 0.9 * min(steps)


def test_default_verlet_step_is_peridigms(tmp_path):
    """A bond-based deck without Fixed dt runs with Peridigm's step (to the rounding of a sum
    of 11 terms) and floor(1 ms / dt) steps."""
    case = validate_case(deck_case(_deck("Elastic Bond Based"), "step", "deck.yaml", DATA))
    assert (case.solver.step_rule, case.solver.safety, case.solver.time) == ("peridigm", 0.9, 1e-3)
    summary = run_case(case, tmp_path)
    dt = _peridigm_step()
    assert summary["dt_s"] == pytest.approx(dt, rel=1e-14)
    assert summary["steps"] == math.floor(1e-3 / dt)


def test_default_verlet_step_beyond_the_lps_bound_runs_with_a_warning(tmp_path):
    """Peridigm bounds LPS with the bond-based step: on Compression_3x1x1 (three points in a
    line) it is 2.6 times peridyn's Gershgorin bound of the LPS stiffness (a sufficient bound,
    not the stable step itself). Without its Fixed dt the deck runs Peridigm's step, as Peridigm
    does, with a warning naming the bound; a state that diverged would stop the run."""
    deck = read_deck(DATA / "Compression_3x1x1.yaml")
    del deck["Solver"]["Verlet"]["Fixed dt"]
    deck["Solver"]["Final Time"] = 1e-3  # 8 steps of Peridigm's 1.24e-4 s
    case = validate_case(deck_case(deck, "step", "deck.yaml", DATA))
    with pytest.warns(UserWarning, match="exceeds the stable step .*Gershgorin bound"):
        summary = run_case(case, tmp_path)
    assert summary["steps"] == 8 and summary["dt_s"] > 2.6 * summary["stable_dt_s"]
