"""Per-point stress and strain of a run (``output.stress``, ``output.strain``): a bar under
tension, and the fields read back from results.h5 and the VTU snapshot."""

import copy
from pathlib import Path

import meshio
import numpy as np

from peridyn.io.case import validate_case
from peridyn.io.results import Results
from peridyn.jobs.run import run_case

E = 70e9
LENGTH, WIDTH, THICKNESS, FORCE = 0.060, 0.020, 1e-3, 20.0  # m, m, m, N
#: A plane-stress LPS bar, 60 x 20 points, clamped at x- and pulled by 20 N at x+: the mean
#: stress of a section is F / (W t) = 1 MPa.
BAR = {
    "name": "bar_stress",
    "geometry": {"type": "rectangle", "size": [LENGTH, WIDTH], "thickness": THICKNESS, "plane": "stress"},
    "discretization": {"spacing": 1e-3, "horizon": 4.015},
    "material": {"model": "lps", "E": E, "nu": 0.3, "density": 2700},
    "node_sets": {"clamp": {"type": "face", "face": "x-"}, "end": {"type": "face", "face": "x+"}},
    "boundary_conditions": [
        {"set": "clamp", "kind": "displacement", "components": "xy", "value": 0.0},
        {"set": "end", "kind": "force", "components": "x", "value": FORCE},
    ],
    "solver": {"type": "newton", "tolerance": 1e-10},
    "output": {"stress": True, "strain": True, "plots": False},
}


def test_bar_stress_is_young_modulus_times_strain_at_the_centre(tmp_path):
    """At the centre of the bar (uniaxial stress, 10 spacings from each long side and 30 from
    the ends) sigma_xx = E eps_xx within 1% (issue 18), eps_xx from the strain field. Measured
    0.4%: what is left is the square lattice's fourth-moment anisotropy of the LPS deviatoric
    part (docs/user-guide.md), and the surfaces' stiffening 2.5 horizons away. The section's
    mean sigma_xx also balances the load, F / (W t), to 1e-4 (measured 1e-5): the partial
    stress carries the force through the section. The snapshot's tensors are the final ones, stored in
    another file: compared exactly."""
    run_case(validate_case(copy.deepcopy(BAR)), tmp_path)
    results = Results(tmp_path / "results.h5")
    x = results.array("geometry/points")
    sigma, strain, valid = (results.array(f"final/{k}") for k in ("stress", "strain", "strain_valid"))
    assert sigma.shape == strain.shape == (len(x), 2, 2) and valid.all()
    centre = np.argmin(np.linalg.norm(x - [LENGTH / 2, WIDTH / 2], axis=1))
    assert abs(sigma[centre, 0, 0] / (E * strain[centre, 0, 0]) - 1.0) < 0.01
    section = np.abs(x[:, 0] - x[centre, 0]) < 1e-9
    mean = sigma[section, 0, 0].mean()
    assert abs(mean / (FORCE / (WIDTH * THICKNESS)) - 1.0) < 1e-4
    # the VTU snapshot of the end holds the same fields, as 3 x 3 tensors padded with zeros
    last = sorted(Path(tmp_path, "snapshots").glob("*.vtu"))[-1]
    data = meshio.read(last).point_data
    for name, value in (("stress", sigma), ("strain", strain)):
        tensor = data[name].reshape(-1, 3, 3)
        np.testing.assert_array_equal(tensor[:, :2, :2], value)
        assert np.all(tensor[:, 2, :] == 0.0) and np.all(tensor[:, :, 2] == 0.0)


def test_stress_and_strain_are_written_only_when_asked(tmp_path):
    """Without ``output.stress`` and ``output.strain`` (the default) nothing new is written."""
    raw = copy.deepcopy(BAR)
    raw["discretization"]["horizon"] = 3.015
    del raw["output"]["stress"], raw["output"]["strain"]
    run_case(validate_case(raw), tmp_path)
    results = Results(tmp_path / "results.h5")
    assert not any(results.has(f"final/{k}") for k in ("stress", "strain", "strain_valid"))
    last = sorted(Path(tmp_path, "snapshots").glob("*.vtu"))[-1]
    assert not {"stress", "strain"} & set(meshio.read(last).point_data)
