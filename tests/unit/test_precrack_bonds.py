"""A ``bonds`` pre-crack (listed bonds, by their ends' in-plane positions): in a plate it cuts
the bonds between the two columns of points of each pair, at every pair of layers, and no other;
listed by their ends' 3D positions, it cuts those bonds alone (docs/user-guide.md, the case file;
the monitoring job's bond transfer and its direct check: docs/monitoring.md)."""

import numpy as np
import pytest

from peridyn.errors import CaseFileError
from peridyn.io.case import validate_case
from peridyn.setup.build import build

H = 1e-3


def _plate(precracks) -> dict:
    return {
        "name": "plate",
        "geometry": {"type": "plate", "size": [0.010, 0.008, 0.002], "layers": 3},
        "discretization": {"spacing": H, "horizon": 3.015},
        "material": {"model": "lps", "E": 68.9e9, "nu": 0.33, "density": 2700},
        "precracks": precracks,
        "node_sets": {"left": {"type": "face", "face": "x-", "depth": H}},
        "boundary_conditions": [{"set": "left", "kind": "velocity", "components": "x", "value": 1.0}],
        "solver": {"type": "explicit", "time": 1e-7},
        "output": {"plots": False},
    }


def _cut_columns(setup) -> set:
    """The broken bonds as pairs of columns (in-plane positions rounded to a tenth of the spacing)."""
    b = setup.bonds
    xy = np.round(setup.body.points[:, :2] / (0.1 * H)).astype(int)
    owners, broken = b.owners(), ~b.intact
    return {
        tuple(sorted((tuple(xy[i]), tuple(xy[j]))))
        for i, j in zip(owners[broken], b.neighbours[broken], strict=True)
    }


def test_listed_bonds_are_cut_between_their_columns_at_every_layer_pair():
    # two bonds of the 1 mm grid (points at 0.5, 1.5, ... mm): a horizontal one and a diagonal
    # one of length sqrt(5) mm, the second listed with its ends swapped and 1e-5 m off the grid
    pairs = [[0.0045, 0.0035, 0.0055, 0.0035], [0.00651, 0.00449, 0.0045, 0.0035]]
    setup = build(validate_case(_plate([{"type": "bonds", "pairs": pairs, "tolerance": 0.25 * H}]), "plate"))
    cut = _cut_columns(setup)
    assert cut == {((45, 35), (55, 35)), ((45, 35), (65, 45))}
    # every layer pair of the two columns (3 x 3 directed both ways): 18 directed bonds a pair
    assert int((~setup.bonds.intact).sum()) == 2 * 18


def test_lattice_storage_cuts_the_same_listed_bonds():
    pairs = [[0.0045, 0.0035, 0.0055, 0.0035], [0.00651, 0.00449, 0.0045, 0.0035]]
    case = _plate([{"type": "bonds", "pairs": pairs, "tolerance": 0.25 * H}])
    case["discretization"]["storage"] = "lattice"
    setup = build(validate_case(case, "plate"))
    assert setup.storage == "lattice" and setup.bonds.n_broken() == 2 * 18


def test_bonds_listed_in_space_are_cut_alone_with_either_storage():
    # the horizontal bond of the first test between the bottom and the middle layer, and the
    # diagonal one within the top layer (one end 1e-5 m off the grid): 2 directed bonds each,
    # no other bond between their columns
    z = np.unique(build(validate_case(_plate([]), "plate")).body.points[:, 2])
    pairs = [
        [0.0045, 0.0035, z[0], 0.0055, 0.0035, z[1]],
        [0.00651, 0.00449, z[2], 0.0045, 0.0035, z[2] + 1e-5],
    ]
    case = _plate([{"type": "bonds", "pairs": pairs, "tolerance": 0.25 * H}])
    setup = build(validate_case(case, "plate"))
    b = setup.bonds
    p = setup.body.points
    ends = np.sort(np.stack([p[b.owners()[~b.intact], 2], p[b.neighbours[~b.intact], 2]], axis=1), axis=1)
    assert _cut_columns(setup) == {((45, 35), (55, 35)), ((45, 35), (65, 45))}
    assert len(ends) == 2 * 2
    assert {tuple(e) for e in ends} == {(z[0], z[1]), (z[2], z[2])}
    case["discretization"]["storage"] = "lattice"
    assert build(validate_case(case, "plate")).bonds.n_broken() == 2 * 2


def test_a_bonds_precrack_lists_pairs_of_one_kind():
    mixed = [[0.0045, 0.0035, 0.0055, 0.0035], [0.0045, 0.0035, 0.0, 0.0055, 0.0035, 0.0]]
    with pytest.raises(CaseFileError, match="all"):
        validate_case(_plate([{"type": "bonds", "pairs": mixed, "tolerance": 0.25 * H}]), "plate")


def test_a_bonds_precrack_needs_its_tolerance_and_ends_on_the_body():
    with pytest.raises(CaseFileError, match="tolerance"):
        validate_case(_plate([{"type": "bonds", "pairs": [[0.0045, 0.0035, 0.0055, 0.0035]]}]), "plate")
    far = _plate([{"type": "bonds", "pairs": [[0.5, 0.5, 0.501, 0.5]], "tolerance": 0.25 * H}])
    with pytest.raises(CaseFileError, match="precracks"):
        build(validate_case(far, "plate"))
