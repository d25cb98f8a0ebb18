"""Dispersion measured on the running code (peridyn.analysis.measured_dispersion)."""

from __future__ import annotations

import numpy as np
import pytest

from peridyn.analysis.dispersion import MARAGING_STEEL, dispersion_relation
from peridyn.analysis.measured_dispersion import lattice_block_model, measure_dispersion
from peridyn.errors import InputError

H = 1e-3  # grid spacing of seed 001 (VALIDATION.md V3), m
#: First half of the Brillouin zone along x, where the issue asks agreement within 1%.
WAVENUMBERS = np.linspace(0.05, 0.5, 6) * np.pi / H


@pytest.mark.parametrize(
    ("model", "dim", "direction", "partial"),
    [
        pytest.param("lps", 3, "x", True, id="lps-3d-x-partial"),
        pytest.param("lps", 3, "xyz", False, id="lps-3d-xyz-centre"),
        pytest.param("pmb", 3, "xy", True, id="pmb-3d-xy-partial"),
        pytest.param("lps", 2, "x", True, id="lps-2d-x-partial"),
    ],
)
def test_measured_dispersion_is_the_discrete_relation(model, dim, direction, partial):
    """Issue 4 asks for 1%; the quotients are exact up to round-off (measured about 1e-9)."""
    k = WAVENUMBERS / (np.sqrt(2.0) if direction == "xy" else 1.0)
    measured = measure_dispersion(
        model, MARAGING_STEEL, 3.015 * H, H, k, dim=dim, direction=direction, partial_volumes=partial
    )
    relation = dispersion_relation(
        model,
        MARAGING_STEEL,
        3.015 * H,
        H,
        dim=dim,
        direction=direction,
        discrete=True,
        partial_volumes=partial,
        wavenumbers=k,
    )
    for name, error in measured.relative_error(relation).items():
        assert np.max(np.abs(error)) < 1e-6, name
    assert measured.interior_points > 0


def test_group_velocity_of_the_relation_is_the_slope_of_the_measured_omega():
    k = np.array([500.0, 1000.0, 1500.0])
    dk = 0.1
    grid = np.sort(np.concatenate([k - dk, k + dk]))
    measured = measure_dispersion("lps", MARAGING_STEEL, 3.015 * H, H, grid)
    relation = dispersion_relation("lps", MARAGING_STEEL, 3.015 * H, H, discrete=True, wavenumbers=k)
    for name, omega in measured.frequency.items():
        slope = (omega[1::2] - omega[0::2]) / (2 * dk)
        branch = relation.branches[name]
        assert slope == pytest.approx(branch.group_velocity, abs=1e-4 * branch.long_wave_limit)


def test_block_interior_has_complete_two_ring_families():
    model, inside = lattice_block_model("lps", MARAGING_STEEL, 3.015 * H, H)
    x = model.body.points
    margin = np.abs(x).max() - np.abs(x[inside]).max(axis=0)
    # twice the reach delta + h sqrt(3) / 2 of a family with partial volumes
    assert np.all(margin >= 2 * (3.015 + np.sqrt(3) / 2) * H - 1e-12)
    assert inside.sum() == 27


def test_one_dimensional_media_are_not_measured():
    with pytest.raises(InputError, match="2D and 3D"):
        measure_dispersion("lps", MARAGING_STEEL, 3e-3, H, [100.0], dim=1)


def test_bad_wavenumbers_are_refused():
    with pytest.raises(InputError, match="wavenumbers"):
        measure_dispersion("lps", MARAGING_STEEL, 3e-3, H, [-1.0])
