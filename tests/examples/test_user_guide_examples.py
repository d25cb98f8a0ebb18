"""The Python examples of docs/user-guide.md run as printed, on their own models, and what they
compute obeys the physics: each block is taken from the page (so an edited example is the one
tested), shortened only in its number of steps or its simulated time."""

import json
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import yaml
from scipy.spatial import cKDTree

from peridyn.cli import main

GUIDE = Path(__file__).parents[2] / "docs" / "user-guide.md"
CASES = Path(__file__).parents[2] / "cases"


def python_block(containing: str, language: str = "python") -> str:
    """The one ```python (or other ``language``) block of the user guide holding ``containing``."""
    blocks = re.findall(rf"```{language}\n(.*?)```", GUIDE.read_text(), flags=re.S)
    found = [block for block in blocks if containing in block]
    assert len(found) == 1, f"{len(found)} {language} blocks of the user guide hold {containing!r}"
    return found[0]


def shortened(block: str, old: str, new: str) -> str:
    """``block`` with its one ``old`` replaced by ``new``."""
    assert block.count(old) == 1, f"{old!r} is not in the example once"
    return block.replace(old, new)


def _mirror(points: np.ndarray, length: float) -> np.ndarray:
    """Index of each point's mirror image across x = length / 2 (the grid is symmetric)."""
    mirrored = points * [-1.0, 1.0, 1.0] + [length, 0.0, 0.0]
    distance, index = cKDTree(points).query(mirrored)
    assert distance.max() < 1e-9
    return index


@pytest.mark.slow
def test_python_section_runs_and_its_waves_and_stretch_are_physical():
    """The "Python" section's two blocks (a 38 400-point LPS plate; the explicit run cut from
    500 to 100 steps, Newmark from 100 to 3):

    - the tone burst at the plate's centre and the plate are symmetric about x = 30 mm, so are
      the explicit and the Newmark waves: u_z mirrors, u_x changes sign, to 1e-9 of the largest
      displacement (round-off of the families' summation order; measured below 1e-12 x);
    - after 3 Newmark steps (60 ns, within the burst's first positive half-cycle) the patch
      moves along +z, as the force pushes;
    - Newton's stretch (left end held, right end moved 6 um) converges and moves the middle by
      half of it, 3 um, within 2% (measured 1.2% less: the held end cannot contract sideways)."""
    first = shortened(python_block("pd.geometry.plate(0.06"), "n_steps=500", "n_steps=100")
    second = shortened(python_block("NewmarkSolver(model, loads"), "n_steps=100", "n_steps=3")
    scope: dict = {}
    exec(compile(first, "user-guide: Python", "exec"), scope)
    body = scope["body"]
    mirror = _mirror(body.points, 0.06)
    explicit = scope["state"].u
    scale = np.abs(explicit).max()
    assert scale > 0
    assert np.abs(explicit[mirror, 2] - explicit[:, 2]).max() < 1e-9 * scale
    assert np.abs(explicit[mirror, 0] + explicit[:, 0]).max() < 1e-9 * scale

    exec(compile(second, "user-guide: implicit", "exec"), scope)
    result, implicit = scope["result"], scope["state"].u
    assert implicit[body.node_sets["patch"], 2].min() > 0
    scale = np.abs(implicit).max()
    assert np.abs(implicit[mirror, 2] - implicit[:, 2]).max() < 1e-9 * scale
    assert np.abs(implicit[mirror, 0] + implicit[:, 0]).max() < 1e-9 * scale
    assert result.converged
    middle = np.abs(body.points[:, 0] - 0.03) < 0.3e-3
    assert result.u[middle, 0].mean() == pytest.approx(3e-6, rel=0.02)


@pytest.mark.slow
def test_results_examples_read_a_pulse_that_arrives_no_faster_than_sound(tmp_path):
    """The "Results" blocks (``Results`` and xarray) read ``bar_pulse`` run to 30 us: no sensor
    moves before the fastest wave, the P wave at sqrt(E (1 - nu) / (rho (1 + nu) (1 - 2 nu))) =
    5 778 m/s, can reach it from the driven end: until then |u| stays below 1% of its later peak
    (measured 0.13% at x = 50 mm and 0.18% at 100 mm: the Hann pulse's smooth onset and the
    nonlocal precursor of the grid)."""
    out = tmp_path / "bar_pulse"
    subprocess.run(
        [sys.executable, "-m", "peridyn", "run", str(CASES / "bar_pulse.yaml"), "--set", "solver.time=30e-6"]
        + ["--output", str(out), "--no-progress"],
        check=True,
        capture_output=True,
    )
    scope: dict = {}
    path = "peridyn-out/bar_pulse/results.h5"
    block = python_block("from peridyn.io.results import Results").replace(path, str(out / "results.h5"))
    exec(compile(block, "user-guide: Results", "exec"), scope)
    times, u, names = scope["times"], scope["u"], scope["names"]
    c_p = np.sqrt(200e9 * (1 - 0.29) / (7850 * (1 + 0.29) * (1 - 2 * 0.29)))
    for name, distance in (("x50", 0.050), ("x100", 0.100)):
        ux = np.abs(u[:, list(names).index(name), 0])
        assert ux[times < distance / c_p].max() < 0.01 * ux.max()
    labelled = scope["sensors"]["sensor_u"]
    assert np.allclose(labelled.sel(sensor="x50", component="x").values, u[:, 0, 0])

    xarray_block = python_block("import xarray as xr").replace(path, str(out / "results.h5"))
    exec(compile(xarray_block, "user-guide: xarray", "exec"), scope)
    assert scope["u"].dims == ("time", "sensor", "component") and scope["u"].attrs["units"] == "m"
    np.testing.assert_array_equal(scope["u"].values, u)
    np.testing.assert_array_equal(scope["root"]["sensor_u"].values, u)


def test_case_file_reference_is_a_valid_case_with_a_stable_step_below_the_cfl_limit(tmp_path, capsys):
    """The "Case files" reference block, every key as printed, is a valid case (``peridyn
    validate``), and so is the contact block added to it; the stable step it estimates for the
    aluminium plate (1.2 mm spacing) lies below the continuum's spacing / c_P (c_P = 6 197 m/s:
    a peridynamic family is stiffer than one cell, Silling and Askari 2005)."""
    reference = yaml.safe_load(python_block("name: my_case", "yaml"))
    reference.update(yaml.safe_load(python_block("contact:", "yaml")))
    path = tmp_path / "my_case.yaml"
    path.write_text(yaml.safe_dump(reference))
    assert main(["validate", str(path), "--json"]) == 0
    found = json.loads(capsys.readouterr().out)
    assert found["valid"]
    E, nu, rho = 68.9e9, 0.33, 2700.0
    c_p = np.sqrt(E * (1 - nu) / (rho * (1 + nu) * (1 - 2 * nu)))
    assert 0 < found["estimated_stable_dt_s"] < 1.2e-3 / c_p


def test_crack_path_example_finds_the_angle_of_a_straight_crack():
    """The "Fracture" block on a damage field whose crack is known: a 1 mm grid, a pre-crack
    along y = 50 mm up to the tip at x = 30 mm, and damage 1 within one spacing of a 40 mm
    crack leaving the tip at 30 degrees: the block's departure angle is 30 degrees to within
    2 (the band of damaged grid points is one to two spacings wide around the line; measured
    29.75)."""
    spacing = 1e-3
    x, y = np.meshgrid(np.arange(0.0, 0.1, spacing), np.arange(0.0, 0.1, spacing), indexing="ij")
    points = np.column_stack([x.ravel(), y.ravel()])
    tip = np.array([0.030, 0.050])
    direction = np.array([np.cos(np.radians(30.0)), np.sin(np.radians(30.0))])
    along = (points - tip) @ direction
    across = np.abs((points - tip) @ [-direction[1], direction[0]])
    phi = ((along >= 0) & (along <= 0.040) & (across <= spacing)).astype(float)
    (x0, y0), (x1, y1) = (0.0, 0.050), tip
    scope = {"points": points, "phi": phi, "spacing": spacing, "tip": tip}
    scope.update(x0=x0, y0=y0, x1=x1, y1=y1)
    exec(compile(python_block("departure_angle(crack, tip"), "user-guide: Fracture", "exec"), scope)
    assert scope["angle"] == pytest.approx(30.0, abs=2.0)


def test_console_example_prints_what_the_command_prints():
    """The console block of "Commands" (a refused density, ``--json``) shows the exact line the
    command writes, run from the repository as it is shown; exit status 1 (an input error)."""
    block = re.search(r"```console\n\$ (.*?)\n(.*?)\n```", GUIDE.read_text(), flags=re.S)
    command, shown = block.group(1).split(), block.group(2)
    assert command[0] == "peridyn"
    run = subprocess.run(
        [sys.executable, "-m", "peridyn", *command[1:]], cwd=CASES.parent, capture_output=True, text=True
    )
    assert run.returncode == 1
    assert json.loads(run.stdout) == json.loads(shown)
