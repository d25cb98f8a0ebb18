"""``solver.type: newton`` and ``newmark`` from case files, through the Recorder and HDF5 output."""

import copy

import numpy as np
import pytest

from peridyn.errors import CaseFileError
from peridyn.io.case import validate_case
from peridyn.io.results import Results
from peridyn.jobs.run import run_case

BAR = {
    "name": "bar",
    "geometry": {"type": "box", "size": [0.012, 0.004, 0.004]},
    "discretization": {"spacing": 1e-3, "horizon": 2.015},
    "material": {"model": "pmb", "E": 70e9, "nu": 0.25, "density": 2700},
    "node_sets": {"clamp": {"type": "face", "face": "x-"}, "end": {"type": "face", "face": "x+"}},
    "boundary_conditions": [
        {
            "set": "end",
            "kind": "displacement",
            "components": "x",
            "value": {"type": "ramp", "start": 0, "end": 1e-6, "end_value": 1e-6},
        }
    ],
    "solver": {"type": "explicit", "steps": 40},
    "output": {"every": 1, "sensors": {"mid": [0.006, 0.002, 0.002]}, "plots": False, "vtu": False},
}


def _case(solver, bcs=None):
    raw = copy.deepcopy(BAR)
    raw["solver"] = solver
    if bcs is not None:
        raw["boundary_conditions"] = bcs
    return validate_case(raw)


def test_newmark_case_records_like_the_explicit_one(tmp_path):
    """A bar whose end is pulled by a displacement ramp: the Newmark run (dt = 20 ns, below the
    explicit limit) writes the same sensor series as velocity Verlet at the same dt, within 2%
    of the peak (measured 0.3%; both are second order in time)."""
    explicit = run_case(_case({"type": "explicit", "steps": 60, "dt": 2e-8}), tmp_path / "e")
    implicit = run_case(_case({"type": "newmark", "steps": 60, "dt": 2e-8}), tmp_path / "i")
    assert implicit["steps"] == explicit["steps"] == 60
    _, t_e, u_e = Results(tmp_path / "e/results.h5").series("sensor_u")
    _, t_i, u_i = Results(tmp_path / "i/results.h5").series("sensor_u")
    np.testing.assert_allclose(t_i, t_e)
    scale = np.abs(u_e[..., 0]).max()
    print("largest sensor difference / peak", np.abs(u_i - u_e).max() / scale)
    assert scale > 0 and np.abs(u_i - u_e).max() < 0.02 * scale


def test_newton_case_matches_the_static_case(tmp_path):
    """Clamped bar with 10 N on its free end: ``newton`` and ``static`` (ADR, tolerance 1e-8)
    give the same final displacement to 1e-5 of its largest value."""
    bcs = [
        {"set": "clamp", "kind": "displacement", "components": "xyz", "value": 0.0},
        {"set": "end", "kind": "force", "components": "x", "value": 10.0},
    ]
    newton = run_case(_case({"type": "newton", "tolerance": 1e-10}, bcs), tmp_path / "n")
    run_case(_case({"type": "static", "tolerance": 1e-8}, bcs), tmp_path / "s")
    u_n = Results(tmp_path / "n/results.h5").array("final/u")
    u_s = Results(tmp_path / "s/results.h5").array("final/u")
    assert newton["residual"] < 1e-10
    assert np.abs(u_n - u_s).max() < 1e-5 * np.abs(u_s).max()


@pytest.mark.parametrize(
    "solver, message",
    [
        ({"type": "newmark", "steps": 10}, "needs dt"),
        ({"type": "newmark", "dt": 1e-8}, "exactly one of steps or time"),
        ({"type": "newmark", "steps": 10, "dt": 1e-8, "displacement_tolerance": -1.0}, "greater than 0"),
        ({"type": "newton", "newton_iterations": 0}, "greater than or equal to 1"),
    ],
)
def test_implicit_solver_keys_are_checked(solver, message):
    """Bad implicit-solver keys are refused with a message naming the problem."""
    with pytest.raises(CaseFileError, match=message):
        _case(solver)


def test_explicit_stage_continues_the_newton_run(tmp_path):
    """``solver.then``: an explicit stage after Newton's last load step starts from its state
    (the displacement, and the velocity of the last load step, (u_4 - u_3) / (T / 4)) at
    its time T, its steps numbered on from the load steps (its start one step after the last
    load step) and the loads' time functions read on: the pulled end holds the ramp's end
    value, 1e-6 m, at every step of the stage."""
    from peridyn.io.exodus import read_exodus

    T, dt, steps = 1e-6, 2e-8, 30
    raw = copy.deepcopy(BAR)
    raw["boundary_conditions"].append(
        {"set": "clamp", "kind": "displacement", "components": "xyz", "value": 0.0}
    )
    raw["solver"] = {
        "type": "newton",
        "time": T,
        "load_steps": 4,
        "tolerance": 1e-10,
        "then": {"dt": dt, "steps": steps},
    }
    raw["output"]["exodus"] = {"file": "bar.e", "every": 1, "variables": ["Displacement", "Velocity"]}
    summary = run_case(validate_case(raw), tmp_path / "run")
    assert summary["steps"] == 4 + 1 + steps
    mesh = read_exodus(tmp_path / "run" / "bar.e")
    # records: t = 0, the 4 load steps, the stage's start (at T again) and its steps
    expected = np.concatenate([np.arange(5) * T / 4, T + np.arange(steps + 1) * dt])
    np.testing.assert_allclose(mesh.times, expected, rtol=0, atol=1e-20)
    ux, vx = mesh.nodal_variables["DisplacementX"], mesh.nodal_variables["VelocityX"]
    assert np.array_equal(ux[5], ux[4])  # the stage starts from the last load step's u ...
    np.testing.assert_allclose(vx[5], (ux[4] - ux[3]) / (T / 4), rtol=1e-12, atol=0)  # ... and v
    assert np.abs(vx[5]).max() > 0
    end = np.isclose(mesh.coordinates[:, 0], mesh.coordinates[:, 0].max())
    np.testing.assert_allclose(ux[5:, end], 1e-6, rtol=1e-12)
