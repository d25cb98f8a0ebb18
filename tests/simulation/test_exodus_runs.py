"""Case files with Exodus in and out: ``geometry: {type: exodus}`` and ``output.exodus``."""

import copy
from pathlib import Path

import numpy as np
import pytest

from peridyn.errors import InputError
from peridyn.io.case import validate_case
from peridyn.io.exodus import mesh_points, read_exodus
from peridyn.io.results import Results
from peridyn.jobs.run import run_case
from peridyn.setup.build import build, build_body

MESH = Path(__file__).parents[1] / "data" / "peridigm" / "WaveInBar.g"

#: WaveInBar's deck (tests/data/peridigm/WaveInBar.xml) as a peridyn case, shortened: the mesh's
#: end node set gets the deck's initial velocity of -100 m/s.
BAR = {
    "name": "wave_in_bar",
    "geometry": {"type": "exodus", "file": str(MESH)},
    "discretization": {"horizon_m": 0.00601},
    "material": {"model": "lps", "E": 21.5e9, "nu": 0.25, "density": 2200.0},
    "initial_conditions": [{"set": "nodelist_1", "kind": "velocity", "components": "x", "value": -100.0}],
    "solver": {"type": "explicit", "steps": 12},
    "output": {"snapshot_every": 5, "exodus": True, "plots": False, "vtu": False},
}


@pytest.mark.bitwise
def test_exodus_geometry_gives_the_mesh_points_and_sets():
    """A case on an Exodus mesh gets the points, volumes and node sets of ``mesh_points`` of that mesh,
    exactly: the body is made by the same code from the same file."""
    body = build_body(validate_case(copy.deepcopy(BAR)))
    pts = mesh_points(read_exodus(MESH))
    np.testing.assert_array_equal(body.points, pts.points)
    np.testing.assert_array_equal(body.volumes, pts.volumes)
    np.testing.assert_array_equal(body.node_set("nodelist_1"), pts.point_sets["nodelist_1"])
    np.testing.assert_array_equal(body.node_set("block_1"), np.arange(len(pts.points)))


def test_unknown_mesh_set_is_named():
    """The mesh's sets are known once it is read: a wrong name is refused when the case is
    built, naming the sets the mesh has."""
    raw = copy.deepcopy(BAR)
    raw["initial_conditions"][0]["set"] = "nodelist_2"
    with pytest.raises(InputError, match="nodelist_2.*nodelist_1"):
        build(validate_case(raw))


def test_exodus_output_matches_results_h5(tmp_path):
    """results.e holds the snapshots (steps 0, 5, 10 and the last, 12): displacement equal to
    results.h5's field snapshots and, at the last step, to its final displacement, bit for bit;
    velocity, damage and volume per point. Exactly: the same arrays stored in two files."""
    run_case(validate_case(copy.deepcopy(BAR)), tmp_path)
    out = read_exodus(tmp_path / "results.e")
    res = Results(tmp_path / "results.h5")
    steps, times, u = res.series("field_u")
    assert steps.tolist() == [0, 5, 10, 12]
    np.testing.assert_array_equal(out.times, times)
    for c, axis in enumerate("XYZ"):
        np.testing.assert_array_equal(out.nodal_variables[f"Displacement{axis}"], u[:, :, c])
        np.testing.assert_array_equal(
            out.nodal_variables[f"Displacement{axis}"][-1], res.array("final/u")[:, c]
        )
        np.testing.assert_array_equal(out.nodal_variables[f"Velocity{axis}"][-1], res.array("final/v")[:, c])
    np.testing.assert_array_equal(out.element_variables["Damage"][-1], res.array("final/damage"))
    body = build_body(validate_case(copy.deepcopy(BAR)))
    np.testing.assert_array_equal(out.element_variables["Volume"][0], body.volumes)
    np.testing.assert_array_equal(out.coordinates, body.points)
    assert out.node_set("nodelist_1").nodes.tolist() == body.node_set("nodelist_1").tolist()
    # the deck's initial velocity, on the node set only
    v0 = out.nodal_variables["VelocityX"][0]
    np.testing.assert_array_equal(np.flatnonzero(v0), body.node_set("nodelist_1"))
    assert np.all(v0[body.node_set("nodelist_1")] == -100.0)


@pytest.mark.bitwise
def test_exodus_output_survives_a_restart(tmp_path):
    """Checkpoint at step 5, stop at 8, restart to 12: results.e as from one run. Bit for bit: the
    restart continues from the checkpoint's exact state with the same operations in the same order, and
    the kernels are compiled without value-changing fast-math flags (``peridyn.kernels.FASTMATH``), so
    this holds on every CPU."""
    run_case(validate_case(copy.deepcopy(BAR)), tmp_path / "whole")
    short = copy.deepcopy(BAR)
    short["solver"]["steps"] = 8
    run_case(validate_case(short), tmp_path / "split", checkpoint_every=5)
    run_case(validate_case(copy.deepcopy(BAR)), tmp_path / "split", restart=True)
    whole, split = read_exodus(tmp_path / "whole/results.e"), read_exodus(tmp_path / "split/results.e")
    np.testing.assert_array_equal(split.times, whole.times)
    for name, values in whole.nodal_variables.items():
        np.testing.assert_array_equal(split.nodal_variables[name], values)
