"""A material plugs in with one file: the test-only conical bond material
(tests/materials/conical_bond.py, registered by conftest) used from a case file as the shipped
ones are, without any module of peridyn naming it.

The case is validated (its name taken from the registry), estimated (bonds and stable step, asked
of the class: ``Model.family_stiffness_bound``), run (a short explicit run) and given a
dispersion relation (``Model.plane_wave_coefficients``), each checked against the conical model
itself.
"""

from __future__ import annotations

import json

import numpy as np
import pytest
import yaml

from peridyn.analysis.bloch import BlochLattice, bloch_cell
from peridyn.analysis.dispersion import MARAGING_STEEL, Medium, dispersion_relation
from peridyn.analysis.measured_dispersion import measure_dispersion
from peridyn.cli import main
from peridyn.discretization import geometry
from peridyn.discretization.bonds import find_bonds
from peridyn.errors import CaseFileError
from peridyn.io.case import load_case
from peridyn.io.results import Results
from peridyn.physics.materials import make_model
from peridyn.setup.estimate import estimate_case
from peridyn.setup.stable_step import estimated_stable_step

SIZE, SPACING, HORIZON = (0.012, 0.004, 0.004), 1.0e-3, 3.015
E, DENSITY = 200.0e9, 7850.0


def _case_file(tmp_path, **material) -> str:
    """A small free bar of the conical material, stretched by an initial displacement."""
    case = {
        "name": "conical_bar",
        "geometry": {"type": "box", "size": list(SIZE)},
        "discretization": {"spacing": SPACING, "horizon": HORIZON},
        "material": {"model": "conical", "E": E, "density": DENSITY, **material},
        "node_sets": {"body": {"type": "all"}},
        "initial_conditions": [
            {
                "set": "body",
                "kind": "displacement",
                "components": "x",
                "value": {"type": "expression", "text": "1e-9 * (x - 0.006)"},
            }
        ],
        "solver": {"type": "explicit", "time": 0.5e-6},
        "output": {"every": 5, "plots": False},
    }
    path = tmp_path / "conical.yaml"
    path.write_text(yaml.safe_dump(case))
    return str(path)


def _model():
    """The conical model on the case's body, built here without the case."""
    body = geometry.box(SIZE, SPACING)
    bonds = find_bonds(body, HORIZON * SPACING, "constant", partial_volumes=True)
    return make_model("conical", body, bonds, E=E, density=DENSITY)


def test_a_case_file_names_the_registered_material_and_its_class_checks_its_keys(tmp_path, capsys):
    path = _case_file(tmp_path)
    assert load_case(path).material.model == "conical"
    assert main(["validate", path, "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["valid"] is True
    # the class's own parameter check (Model.check_parameters): no surface correction
    with pytest.raises(CaseFileError, match="surface_correction must be one of") as err:
        load_case(_case_file(tmp_path, surface_correction="energy"))
    assert err.value.key == "material.surface_correction"
    # a name nobody registered lists the registered ones, the test-only material among them
    with pytest.raises(CaseFileError, match=r"unknown material model 'conicl' .*'conical'") as err:
        load_case(path, ["material.model=conicl"])
    assert err.value.key == "material.model"


def test_the_estimates_of_a_conical_case_are_its_models(tmp_path):
    """The bond count of the estimate and its stable step equal the conical model's own: the
    continuum bound of a bond-based material (B = 2 sum k / |xi|) is exactly the block-Gershgorin
    bound of a grid point whose whole family is in the body (setup/stable_step.py), to round-off.
    Its memory counts the class's own per-bond arrays (``bond_bytes``: 16 B against PMB's 24 B)."""
    case = load_case(_case_file(tmp_path))
    model = _model()
    estimate = estimate_case(case)
    assert estimate.bonds == model.bonds.n_bonds
    pmb = estimate_case(load_case(_case_file(tmp_path), ["material.model=pmb"]))
    assert pmb.parts["bonds"] - estimate.parts["bonds"] == pytest.approx(8.0 * model.bonds.n_bonds, rel=1e-12)
    assert estimated_stable_step(case) == pytest.approx(model.critical_time_step(), rel=1e-12)


def test_a_conical_case_runs_with_the_conical_model(tmp_path, capsys):
    """The run's stable step and its final energies are those the conical model gives for the
    run's final displacements and velocities (to round-off: sums in another order)."""
    out = tmp_path / "out"
    assert main(["run", _case_file(tmp_path), "--json", "--no-progress", "-o", str(out)]) == 0
    summary = json.loads(capsys.readouterr().out)
    model = _model()
    results = Results(out / "results.h5")
    np.testing.assert_allclose(results.array("geometry/points"), model.body.points, rtol=0, atol=1e-15)
    u, v = results.array("final/u"), results.array("final/v")
    assert summary["steps"] > 0 and np.max(np.abs(u)) > 1e-12
    assert summary["stable_dt_s"] == pytest.approx(model.critical_time_step(), rel=1e-12)
    assert summary["strain_energy_j"] == pytest.approx(model.strain_energy(u), rel=1e-10)
    kinetic = 0.5 * np.sum(DENSITY * model.body.volumes * np.sum(v * v, axis=1))
    assert summary["kinetic_energy_j"] == pytest.approx(kinetic, rel=1e-10)


def test_the_conical_dispersion_relation():
    """Long waves travel at the classical speeds of (E, nu = 1/4): the micromodulus is
    calibrated on the bulk energy (Silling and Askari 2005), and a bond-based law has Cauchy's
    nu = 1/4. The discrete relation is the one the conical model's force has on a lattice
    block (``measure_dispersion``: plane-wave quotients of ``Model.force``, exact to about 1e-9,
    tests/unit/analysis/test_measured_dispersion.py)."""
    h = 1e-3
    continuum = dispersion_relation("conical", MARAGING_STEEL, 3.015 * h, h)
    quarter = Medium(MARAGING_STEEL.E, 0.25, MARAGING_STEEL.density).classical_speeds(3)
    assert continuum.classical == pytest.approx(quarter, rel=1e-12)
    branches = continuum.branches
    limits = (branches["longitudinal"].long_wave_limit, branches["shear_1"].long_wave_limit)
    assert limits == pytest.approx(quarter, rel=1e-6)
    k = np.linspace(0.05, 0.5, 4) * np.pi / h
    args = ("conical", MARAGING_STEEL, 3.015 * h, h)
    measured = measure_dispersion(*args, k, dim=2)
    discrete = dispersion_relation(*args, dim=2, discrete=True, wavenumbers=k)
    for name, error in measured.relative_error(discrete).items():
        assert np.max(np.abs(error)) < 1e-6, name


def test_the_bloch_cell_of_a_conical_case_is_its_plane_wave_relation(tmp_path):
    """The Bloch cell of the case (the conical model on tiles, its stiffness assembled from
    ``Model.linearisation``, docs/bloch.md) and the discrete relation of the class's plane-wave
    coefficients are one acoustic tensor of the simple cubic lattice: equal frequencies (to
    round-off, measured 2e-16)."""
    disc = BlochLattice.from_case(load_case(_case_file(tmp_path)))
    cell = bloch_cell(disc)
    k = np.array([200.0, 800.0, 1500.0])
    relation = dispersion_relation(
        "conical", Medium(E, 0.25, DENSITY), disc.horizon, disc.spacing, discrete=True, wavenumbers=k
    )
    for i, kk in enumerate(k):
        expected = sorted(relation.branches[name].frequency[i] for name in relation.branches)
        assert cell.frequencies(np.array([kk, 0.0, 0.0])) == pytest.approx(expected, rel=1e-10)
