"""Issue 17, item 5: what used to be accepted silently is refused with the key and the numbers:
probes and actuators outside the body, --checkpoint-every < 1, and (validate without --build)
a dt above the stable step, an empty node set, a horizon below the spacing, too much memory."""

import copy
import re
from pathlib import Path

import pytest
import yaml

from peridyn.cli import main
from peridyn.errors import CaseFileError
from peridyn.io.case import apply_override, validate_case
from peridyn.setup.build import build, build_body, check_placements
from peridyn.setup.stable_step import STEP_MARGIN, estimated_stable_step

BAR = {
    "name": "bar",
    "geometry": {"type": "box", "size": [0.06, 0.006, 0.006]},
    "discretization": {"spacing": 1e-3, "horizon": 3.015},
    "material": {"model": "lps", "E": 70e9, "nu": 0.3, "density": 2700},
    "node_sets": {"left": {"type": "face", "face": "x-"}},
    "boundary_conditions": [{"set": "left", "kind": "force", "components": "x", "value": 1.0}],
    "solver": {"type": "explicit", "steps": 5},
}


def _raw(**changes):
    raw = copy.deepcopy(BAR)
    for key, value in changes.items():
        apply_override(raw, f"{key}={value}")
    return raw


def _file(tmp_path, **changes):
    path = tmp_path / "bar.yaml"
    path.write_text(yaml.safe_dump(_raw(**changes)))
    return str(path)


@pytest.mark.parametrize(
    "key, override",
    [
        ("output.sensors.tip", "output.sensors={tip: [3.06, 0.003, 0.003]}"),
        (
            "output.lines.axis.end",
            "output.lines={axis: {start: [0, 0.003, 0.003], end: [0.2, 0.003, 0.003], points: 5}}",
        ),
        ("output.pzt_sensors.p.center", "output.pzt_sensors={p: {center: [0.03, 0.02], size: 0.002}}"),
    ],
)
def test_probe_outside_the_body_is_refused(key, override):
    """The issue's sensor 3 m outside a 60 mm bar (and a line end, a PZT sensor) name the key
    and how far outside they lie (3 m from the x+ face: 3.0 m)."""
    raw = _raw()
    k, v = override.split("=", 1)
    apply_override(raw, f"{k}={v}")
    case = validate_case(raw)
    with pytest.raises(CaseFileError, match=rf"{key} = .*it is [0-9.e+-]+ m outside") as err:
        check_placements(case, build_body(case))
    assert err.value.key == key
    if key == "output.sensors.tip":
        assert "3 m outside" in str(err.value)


@pytest.mark.parametrize("far", ["1e300", "-1e300", "1e200"])
def test_a_probe_at_an_overflowing_distance_is_refused(far):
    """cKDTree finds no neighbour where the squared distance overflows to inf and returns the index
    n_points: an IndexError (an internal error of the CLI) before (found by tests/fuzz)."""
    case = validate_case(_raw(**{"output.sensors": f"{{tip: [{far}, 0.003, 0.003]}}"}))
    with pytest.raises(CaseFileError, match=r"output\.sensors\.tip = .*it is inf m outside"):
        check_placements(case, build_body(case))


def test_actuator_outside_the_body_is_refused():
    raw = _raw()
    raw["geometry"] = {"type": "plate", "size": [0.06, 0.04, 0.002], "layers": 2}
    raw["node_sets"] = {"left": {"type": "face", "face": "x-"}}
    raw["actuators"] = {
        "pzt": {
            "type": "pzt_radial",
            "center": [0.1, 0.02],
            "size": 0.004,
            "signal": {"type": "constant", "value": 1.0},
        }
    }
    with pytest.raises(CaseFileError, match=r"actuators\.pzt\.center = .*0\.04 m outside"):
        build(validate_case(raw))


def test_probes_on_faces_and_corners_are_accepted():
    """A position on the body's surface (half a cell from the outermost points' centres) is inside."""
    sensors = "{corner: [0.0, 0.0, 0.0], far_corner: [0.06, 0.006, 0.006], mid: [0.03, 0.003, 0.0035]}"
    case = validate_case(_raw(**{"output.sensors": sensors}))
    check_placements(case, build_body(case))


def test_checkpoint_every_below_one_is_refused_before_anything(tmp_path, capsys):
    out = tmp_path / "out"
    for value in ("0", "-5", "two"):
        status = main(["run", _file(tmp_path), "--checkpoint-every", value, "-o", str(out), "--no-progress"])
        assert status == 2  # a command line that cannot be parsed
        assert "--checkpoint-every: expected a whole number >= 1" in capsys.readouterr().err
    assert not out.exists()


def test_max_memory_refuses_with_the_numbers(tmp_path, capsys):
    out = tmp_path / "out"
    status = main(["run", _file(tmp_path), "--max-memory", "100MB", "-o", str(out), "--no-progress"])
    assert status == 1
    err = capsys.readouterr().err
    assert "2.16e+03 points" in err and "more than the 0.1 GB available" in err
    assert "libraries alone take" in err
    assert not out.exists()
    assert main(["modal", _file(tmp_path), "--max-memory", "lots"]) == 2
    assert "memory size 'lots'" in capsys.readouterr().err


def test_jobs_called_from_python_check_their_memory_before_building(tmp_path, monkeypatch):
    """``run_case`` and the fatigue job refuse, before building anything or touching the output
    folder, a case whose estimated peak exceeds the memory: from Python as from the command
    line. Python's 0.3 GB of interpreter and libraries (``setup.estimate.BASE_BYTES``) alone
    exceed a 0.1 GB machine, so every case is refused on it."""
    import peridyn.jobs.fatigue
    import peridyn.jobs.run
    from peridyn.discretization import geometry
    from peridyn.errors import InputError
    from peridyn.io.case import load_case

    def build(*args, **kwargs):
        raise AssertionError("the case was built before its memory was checked")

    for job in (peridyn.jobs.run, peridyn.jobs.fatigue):
        monkeypatch.setattr(job, "build", build)
    monkeypatch.setattr(geometry, "memory_limit", lambda: 1e8)
    out = tmp_path / "out"
    with pytest.raises(InputError, match=r"2.16e\+03 points .* more than the 0.1 GB available"):
        peridyn.jobs.run.run_case(validate_case(BAR), out)
    with pytest.raises(InputError, match="more than the 1e-06 GB available"):
        peridyn.jobs.run.run_case(validate_case(BAR), out, max_memory=1e3)
    fatigue = load_case(Path(__file__).parents[2] / "cases" / "sen_fatigue_2d.yaml")
    with pytest.raises(InputError, match="this fatigue job would hold"):
        peridyn.jobs.fatigue.run_fatigue_case(fatigue, out)
    assert not out.exists()


@pytest.mark.parametrize(
    "changes, message",
    [
        ({"solver.dt": "1e-6"}, r"solver.dt = 1e-06: at most the estimated stable step"),
        (
            {"node_sets.left": "{type: box, min: [1, 1, 1], max: [2, 2, 2]}"},
            r"node_sets.left = .*at least one point",
        ),
        ({"discretization.horizon": "0.9"}, r"horizon = 0.9 spacings: at least 1"),
        ({"geometry.size": "[3.0, 3.0, 3.0]", "discretization.spacing": "1e-4"}, r"points and .* GB"),
        (
            {"boundary_conditions.0.value": "{type: tone_burst, frequency: -1, cycles: 3}"},
            r"tone burst frequency must be positive, got -1",
        ),
    ],
)
def test_validate_without_build_refuses(tmp_path, capsys, changes, message):
    """Each of these used to pass ``peridyn validate`` without --build."""
    assert main(["validate", _file(tmp_path)]) == 0
    capsys.readouterr()
    assert main(["validate", _file(tmp_path, **changes)]) == 1
    err = capsys.readouterr().err
    assert err.count("\n") == 1  # one line
    assert re.search(message, err)


@pytest.mark.parametrize(
    "changes",
    [
        {},
        {"material.model": "pmb", "material.nu": "0.25"},
        {"material.model": "pmb", "material.nu": "0.25", "discretization.partial_volumes": "false"},
        {
            "geometry": "{type: plate, size: [0.03, 0.02, 0.002], layers: 3, layer_placement: surface}",
            "node_sets.left": "{type: face, face: x-}",
        },
        {
            "geometry": "{type: rectangle, size: [0.03, 0.02], thickness: 0.001}",
            "material.model": "pmb",
            "material.nu": "0.3333333333",
        },
        {"material.surface_correction": "energy"},
    ],
)
def test_stable_step_estimate_against_the_model(changes):
    """The lattice estimate is the model's own Gershgorin bound for PMB without surface
    correction (to round-off) and never more than STEP_MARGIN longer otherwise
    (setup/stable_step.py)."""
    case = validate_case(_raw(**changes))
    est = estimated_stable_step(case)
    real = build(case).model.critical_time_step()
    if case.material.model == "pmb" and case.material.surface_correction == "none":
        assert est == pytest.approx(real, rel=1e-9)
    else:
        assert 0.85 * real <= est <= (1 + STEP_MARGIN) * real


# --- what a run accepted without a word: each now a warning or an error (docs/user-guide.md,
# "Warnings and errors before a run") ---------------------------------------------------------


def _plan(**changes):
    from peridyn.setup.run_checks import check_run_plan

    case = validate_case(_raw(**changes))
    return lambda dt, steps: check_run_plan(case, dt, steps)


def test_an_excitation_above_the_steps_nyquist_frequency_is_refused():
    """A 10 MHz sine sampled every 0.1 us (Nyquist 5 MHz) is aliased to another frequency."""
    plan = _plan(**{"boundary_conditions.0.value": "{type: sine, frequency: 1.0e7, amplitude: 1.0}"})
    with pytest.raises(
        CaseFileError, match=r"boundary_conditions\[0\].value.frequency = 10000000.0: .* 5e\+06 Hz"
    ):
        plan(1e-7, 100)
    plan(1e-8, 100)  # Nyquist 50 MHz: accepted


@pytest.mark.parametrize(
    "changes, dt, steps, message",
    [
        (
            {"solver.steps": "null", "solver.time": "1e-9"},
            1e-7,
            1,
            r"solver.time = 1e-09 s is shorter than one",
        ),
        ({"output.snapshot_times": "[1.0e-6, 5.0e-5]"}, 1e-7, 100, r"snapshot_times \[5e-05\] come after"),
        ({"output.every": "500"}, 1e-7, 100, r"output.every = 500 steps is longer than the run's 100"),
    ],
)
def test_what_a_run_would_lose_is_warned_of(changes, dt, steps, message):
    with pytest.warns(UserWarning, match=message):
        _plan(**changes)(dt, steps)


def test_a_plain_run_plan_gives_no_warning(recwarn):
    _plan(**{"output.snapshot_times": "[1.0e-6]", "output.every": "10"})(1e-7, 100)
    assert not recwarn.list


def test_a_zero_length_line_probe_is_refused():
    line = "{axis: {start: [0.01, 0.003, 0.003], end: [0.01, 0.003, 0.003], points: 5}}"
    with pytest.raises(CaseFileError, match=r"output.lines.axis.*same point .* a line probe needs a length"):
        validate_case(_raw(**{"output.lines": line}))


def test_a_precrack_outside_the_body_is_refused():
    crack = (
        "[{type: rectangle, origin: [0.5, 0.0, 0.0], edge_u: [0.0, 0.006, 0.0], edge_v: [0.0, 0.0, 0.006]}]"
    )
    case = validate_case(_raw(precracks=crack))
    with pytest.raises(
        CaseFileError, match=r"precracks\[0\] = .*it lies 0.44\d* m outside and would cut no bond"
    ):
        check_placements(case, build_body(case))
    inside = (
        "[{type: rectangle, origin: [0.03, 0.0, 0.0], edge_u: [0.0, 0.006, 0.0], edge_v: [0.0, 0.0, 0.006]}]"
    )
    case = validate_case(_raw(precracks=inside))
    check_placements(case, build_body(case))  # a crack through the bar: accepted


def test_duplicate_mesh_points_are_refused():
    import numpy as np

    from peridyn.errors import InputError
    from peridyn.setup.build import check_distinct_points

    points = np.array([[0.0, 0, 0], [1e-3, 0, 0], [2e-3, 0, 0], [1e-3, 0, 0]])
    with pytest.raises(InputError, match=r"mesh.txt: points 1 and 3 are at the same place"):
        check_distinct_points(points, "mesh.txt")
    check_distinct_points(points[:3], "mesh.txt")


@pytest.mark.parametrize("modes", [3, 6])
def test_modes_not_above_the_rigid_modes_are_refused(tmp_path, capsys, modes):
    """A free 3D bar has 6 rigid-body modes: --modes 6 finds no vibration mode."""
    free = _file(tmp_path, **{"solver": "{type: modal, modes: 20}", "boundary_conditions": "[]"})
    assert main(["validate", free, "--set", f"solver.modes={modes}"]) == 1
    assert "solver.modes = " + str(modes) + ": more than the 6 rigid-body modes of a free 3D body" in (
        capsys.readouterr().err
    )
    assert main(["validate", free, "--set", "solver.modes=7"]) == 0


def test_a_paris_fit_of_identical_points_is_refused():
    from peridyn.errors import InputError
    from peridyn.fatigue.calibration import paris_fit

    with pytest.raises(InputError, match=r"two or more different dK: all 3 are at dK = 2e\+06"):
        paris_fit([2e6, 2e6, 2e6], [1e-8, 2e-8, 3e-8])
    with pytest.raises(InputError, match=r"point 1 has dK = -1"):
        paris_fit([2e6, -1.0], [1e-8, 2e-8])
    m, c = paris_fit([1e6, 2e6, 4e6], [1e-9, 8e-9, 64e-9])  # da/dN = c dK^3
    assert m == pytest.approx(3.0, rel=1e-12) and c == pytest.approx(1e-27, rel=1e-9)


@pytest.mark.parametrize("name", ["..", ".", "../escape", "a/b", "a\\b", ""])
def test_a_case_name_must_be_a_folder_name(name):
    """A case named ``..`` wrote its results outside peridyn-out."""
    raw = _raw()
    raw["name"] = name
    with pytest.raises(CaseFileError, match=r"name = .*a folder name"):
        validate_case(raw)


def test_validate_refuses_what_run_refuses(tmp_path, capsys):
    """A PMB material with the case's nu = 0.3 was valid for validate and refused by run."""
    path = _file(tmp_path, **{"material.model": "pmb"})
    assert main(["validate", path]) == 1
    assert "material.nu = 0.3: a bond-based PMB material has Poisson ratio 0.25" in capsys.readouterr().err


def test_convert_does_not_overwrite_a_file(tmp_path, capsys):
    from pathlib import Path

    deck = Path(__file__).resolve().parents[1] / "data" / "decks" / "bimaterial_bar.xml"
    target = tmp_path / "case.yaml"
    target.write_text("mine\n")
    assert main(["convert", str(deck), "-o", str(target)]) == 1
    assert "exists: pass --overwrite to replace it" in capsys.readouterr().err
    assert target.read_text() == "mine\n"
    assert main(["convert", str(deck), "-o", str(target), "--overwrite"]) == 0
    assert target.read_text() != "mine\n"
