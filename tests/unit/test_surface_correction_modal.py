"""Acceptance of the modal default ``surface_correction: energy`` against the continuum
(VALIDATION.md V4, FE column: 27-node hexahedra, 1706.1, 1982.9, 4268.0, 4542.4, 6607.0,
6868.0 Hz for 1B, 1T, 2T, 2B, TB, IPB), and the case files that use it."""

from pathlib import Path

import numpy as np
import pytest

from peridyn.analysis.modes import classify_modes
from peridyn.discretization import geometry
from peridyn.discretization.bonds import find_bonds
from peridyn.io.case import load_case
from peridyn.physics.materials import make_model
from peridyn.solvers.modal import modal_analysis

FE = [1706.1, 1982.9, 4268.0, 4542.4, 6607.0, 6868.0]
TYPES = [
    "1st bending",
    "1st torsional",
    "2nd torsional",
    "2nd bending",
    "1st transverse bending",
    "1st in-plane bending",
]
CASES = Path(__file__).resolve().parents[2] / "cases"


def test_pmma_cases_use_the_energy_correction():
    """docs/modal_study.md: energy is the option closest to the continuum, so the modal
    cases of the PMMA plate use it."""
    for path in sorted(CASES.glob("pmma_plate*.yaml")):
        assert load_case(path).material.surface_correction == "energy", path.name


def _elastic_by_type(spacing: float, method: str) -> tuple[dict, int]:
    """Elastic frequencies (Hz) by type of the free PMMA plate, energy correction, 1.4143 h."""
    body = geometry.box((0.10, 0.05, 0.008), spacing)
    bonds = find_bonds(body, 1.4143 * spacing, partial_volumes=False)
    model = make_model("lps", body, bonds, E=5.35e9, nu=0.33, density=1200.0, surface_correction="energy")
    result = modal_analysis(model, 12, method=method)
    types = classify_modes(body.points, result.shapes, model.density * body.volumes, result.rigid)
    by_type = {str(t): f for t, f, r in zip(types, result.frequencies, result.rigid, strict=True) if not r}
    assert np.all(result.residuals[~result.rigid] < 1e-6)
    return by_type, result.n_rigid


@pytest.mark.slow
def test_40k_points_with_the_energy_correction_match_the_continuum():
    """40 000 points, horizon 1.4143 h (docs/modal_study.md): every elastic mode within 1.2 %
    of FE, matched by type (measured -0.85 ... +0.99 %; plain LPS +3.9 ... +10.8 %,
    shear-factor -4.1 ... -0.8 %); about 2 minutes and 4.6 GB on an idle machine."""
    by_type, n_rigid = _elastic_by_type(1e-3, "shift-invert")
    assert n_rigid == 6
    assert sorted(by_type) == sorted(TYPES)
    np.testing.assert_allclose([by_type[t] for t in TYPES], FE, rtol=0.012)


@pytest.mark.slow
def test_135k_points_with_the_energy_correction_are_within_1_5_percent_of_the_continuum():
    """Issue 9 acceptance: 135 000 points (h = 0.6667 mm), horizon 1.4143 h, the default
    correction: all six elastic modes within 1.5 % of FE, matched by type. Measured (LOBPCG,
    5.0 min, 5.3 GB peak): 1709.04, 1977.21, 4263.01, 4555.35, 6669.73, 6914.06 Hz, i.e.
    +0.17, -0.29, -0.12, +0.29, +0.95, +0.67 % (the thesis: 1.35 %; shear-factor 2.5 %)."""
    by_type, n_rigid = _elastic_by_type(0.1 / 150, "lobpcg")
    assert n_rigid == 6
    assert sorted(by_type) == sorted(TYPES)
    np.testing.assert_allclose([by_type[t] for t in TYPES], FE, rtol=0.015)
