"""Issue 17, item 6: points, bonds and peak memory estimated from the case alone, refusal
before allocation, and the grid builders' own guard."""

import copy

import numpy as np
import pytest

from peridyn.discretization import geometry
from peridyn.discretization.bonds import find_bonds
from peridyn.discretization.lattice import build_lattice
from peridyn.errors import InputError
from peridyn.io.case import apply_override, validate_case
from peridyn.setup import estimate
from peridyn.setup.build import build_bonds, build_points

BASE = {
    "name": "tiny",
    "geometry": {"type": "box", "size": [0.012, 0.008, 0.006]},
    "discretization": {"spacing": 1e-3, "horizon": 3.015},
    "material": {"model": "lps", "E": 70e9, "nu": 0.3, "density": 2700},
    "boundary_conditions": [{"set": "all", "kind": "force", "components": "x", "value": 1.0}],
    "solver": {"type": "explicit", "steps": 10},
}


def _case(**changes):
    raw = copy.deepcopy(BASE)
    for key, value in changes.items():
        apply_override(raw, f"{key}={value}")
    return validate_case(raw)


GEOMETRIES = [
    {},
    {"discretization.partial_volumes": "false"},
    {"discretization.spacing": "[1e-3, 1e-3, 2e-3]", "discretization.horizon": "2.2"},
    {"geometry": "{type: plate, size: [0.02, 0.01, 0.002], layers: 3, layer_placement: surface}"},
    {"geometry": "{type: plate, size: [0.02, 0.01, 0.002], layers: 4}", "discretization.horizon": "1.4143"},
    {"geometry": "{type: rectangle, size: [0.03, 0.02], thickness: 0.001}"},
    {
        "geometry": "{type: rectangle, size: [0.03, 0.02], thickness: 0.001, plane: strain}",
        "discretization.partial_volumes": "false",
    },
]


@pytest.mark.parametrize("changes", GEOMETRIES)
def test_lattice_count_equals_the_bond_search(changes):
    """The offsets-times-overlap count is exact on a grid: it equals find_bonds' directed bonds."""
    case = _case(**changes)
    est = estimate.estimate_case(case)
    body = build_points(case)
    assert est.points == body.n_points
    assert est.bonds == build_bonds(case, body).n_bonds


def test_removals_are_measured_on_a_coarse_copy():
    """A removed slot: points within 3 % of the built body (the share of a coarser grid stands
    for the fine grid's); bonds scale with the same share, so the slot's new faces are not
    subtracted: an over-estimate, by under 20 % on this small body."""
    case = _case(**{"removals": "[{type: box, min: [0.004, -1, -1], max: [0.0061, 0.005, 1]}]"})
    est = estimate.estimate_case(case)
    body = build_points(case)
    bonds = find_bonds(body, 3.015e-3).n_bonds
    assert est.points == pytest.approx(body.n_points, rel=0.03)
    assert bonds <= est.bonds <= 1.2 * bonds


def test_parse_bytes():
    assert estimate.parse_bytes("4GB") == 4_000_000_000
    assert estimate.parse_bytes("4 GiB") == 4 * 2**30
    assert estimate.parse_bytes("512MiB") == 512 * 2**20
    assert estimate.parse_bytes("2.5e9") == 2_500_000_000
    for bad in ("lots", "-4GB", "0", "4XB"):
        with pytest.raises(InputError, match="memory size"):
            estimate.parse_bytes(bad)


def test_refusal_names_the_numbers_and_a_spacing_that_fits():
    """The issue's 300 x 200 x 2 mm plate at 1e-5 m: 1.8e9 points, refused from the case alone;
    the suggested spacing passes the same check."""
    case = _case(
        **{
            "geometry": "{type: plate, size: [0.3, 0.2, 0.002], layers: 3, layer_placement: surface}",
            "discretization.spacing": "1e-5",
            "discretization.partial_volumes": "false",
        }
    )
    limit = 16e9
    with pytest.raises(InputError, match=r"1\.8e\+09 points .* more than the 16 GB") as err:
        estimate.check_memory(case, limit)
    suggested = float(str(err.value).split("a spacing of about ")[1].split(" m")[0])
    fits = estimate.check_memory(
        _case(**{**_plate_changes(), "discretization.spacing": str(suggested)}), limit
    )
    assert fits.peak_bytes <= limit
    assert fits.peak_bytes > 0.5 * limit  # the suggestion is not needlessly coarse


def _plate_changes():
    return {
        "geometry": "{type: plate, size: [0.3, 0.2, 0.002], layers: 3, layer_placement: surface}",
        "discretization.partial_volumes": "false",
    }


def test_study_checks_its_largest_run():
    case = _case()
    run = estimate.largest_study_run(case, [2e-3, 1e-3, 1.5e-3], [1.4143, 3.015])
    assert run.discretization.spacing == 1e-3 and run.discretization.horizon == 3.015
    assert run.solver.type == "modal"


def test_grid_builders_refuse_arrays_that_do_not_fit(monkeypatch):
    """geometry.box/plate/rectangle check GRID_BYTES_PER_POINT x points before allocating."""
    monkeypatch.setattr(geometry, "memory_limit", lambda: 1e8)
    n = 100**3
    assert geometry.GRID_BYTES_PER_POINT * n > 1e8
    with pytest.raises(InputError, match=r"1e\+06 points would need"):
        geometry.box([0.1, 0.1, 0.1], 1e-3)
    with pytest.raises(InputError, match="a plate of"):
        geometry.plate(1.0, 1.0, 0.002, spacing=1e-3, layers=3)
    with pytest.raises(InputError, match="a rectangle of"):
        geometry.rectangle(1.0, 1.0, spacing=1e-3, thickness=1e-3)
    assert geometry.box([0.01, 0.01, 0.01], 1e-3).n_points == 1000


def test_memory_limit_is_positive():
    assert geometry.memory_limit() > 0
    assert np.isfinite(estimate.BASE_BYTES)


def test_wide_horizons_fall_back_to_the_ball_volume(monkeypatch):
    """Beyond MAX_OFFSETS offsets, bonds per point are the horizon ball's volume over a cell's:
    at least the exact count (no surface loss) and, on a body 13 horizons wide, within 40 % of it;
    a thin plate's family is a disc (over by 22 % and 25 % here)."""
    case = _case(**{"geometry.size": "[0.05, 0.05, 0.05]", "discretization.horizon": "3.015"})
    exact = estimate.estimate_case(case).bonds
    monkeypatch.setattr(estimate, "MAX_OFFSETS", 10)
    wide = estimate.estimate_case(case).bonds
    assert exact <= wide <= 1.4 * exact
    plate = {"geometry": "{type: plate, size: [0.05, 0.05, 0.002], layers: 3, layer_placement: surface}"}
    monkeypatch.setattr(estimate, "MAX_OFFSETS", 2_000_000)
    exact = estimate.estimate_case(_case(**plate)).bonds
    monkeypatch.setattr(estimate, "MAX_OFFSETS", 10)
    assert 0.7 * exact <= estimate.estimate_case(_case(**plate)).bonds <= 1.4 * exact


@pytest.mark.parametrize("changes", GEOMETRIES[:6])
def test_lattice_storage_estimate_counts_its_broken_words(changes):
    """On lattice storage an explicit job holds one broken bit per grid point and stencil offset
    (64-bit words: ``discretization.lattice``) and no per-bond array; ``auto`` picks it for
    these grids and keeps bond lists for a static job."""
    case = _case(**changes, **{"discretization.storage": "auto"})
    est = estimate.estimate_case(case)
    body = build_points(case)
    lattice = build_lattice(
        body, case.discretization.horizon * body.spacing, "constant", case.discretization.partial_volumes
    )
    assert est.storage == "lattice" and est.bonds == lattice.n_bonds
    assert est.parts["bonds"] == lattice.broken.nbytes
    assert est.parts["points"] == estimate.lattice_point_bytes(case) * body.n_points
    bonded = estimate.estimate_case(_case(**changes))
    assert bonded.storage == "bonds" and bonded.peak_bytes > est.peak_bytes
    assert estimate.estimate_case(case, job="static").storage == "bonds"
