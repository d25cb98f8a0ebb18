"""Peridigm decks of several block groups (docs/peridigm.md): a two-material bar deck
(tests/data/decks/bimaterial_bar.xml, a text mesh of block ids 1 and 2) runs as the peridyn
case of two blocks that it stands for, bit for bit, and strains as two materials in series."""

import shutil
from pathlib import Path

import h5py
import numpy as np
import pytest

from peridyn.errors import CaseFileError
from peridyn.io.case import validate_case
from peridyn.io.exodus import read_exodus
from peridyn.io.mesh_text import read_text_mesh
from peridyn.io.peridigm_case import convert_deck, exact_moduli_pair
from peridyn.jobs.run import run_case

DECKS = Path(__file__).parents[1] / "data" / "decks"
FILES = ("bimaterial_bar.txt", "bimaterial_bar_left.txt", "bimaterial_bar_right.txt")


def _deck(tmp_path: Path, edit=lambda text: text) -> Path:
    """A copy of the bimaterial bar deck in ``tmp_path`` (with its mesh and node-set files),
    its text changed by ``edit``."""
    for name in FILES:
        shutil.copy(DECKS / name, tmp_path / name)
    deck = tmp_path / "bimaterial_bar.xml"
    deck.write_text(edit((DECKS / "bimaterial_bar.xml").read_text(encoding="utf-8")), encoding="utf-8")
    return deck


def _hand_case(mesh: Path, horizons: tuple[float, float]) -> dict:
    """The deck written as a peridyn case by hand (docs/blocks.md): the text mesh's blocks
    ``block_1`` and ``block_2`` of two LPS materials from the deck's bulk and shear moduli
    (E and nu picked as ``exact_moduli_pair`` picks them)."""

    def lps(K, mu, rho):  # E and nu whose K and mu are the deck's to the bit, as decks take them
        E, nu = 9.0 * K * mu / (3.0 * K + mu), (3.0 * K - 2.0 * mu) / (2.0 * (3.0 * K + mu))
        E, nu = exact_moduli_pair(E, nu, K, mu)
        return {"model": "lps", "E": E, "nu": nu, "density": rho}

    def ids(name):
        return sorted(int(i) - 1 for i in (DECKS / name).read_text().split())

    blocks = {
        "block_1": {"set": "block_1", "material": "Steel"},
        "block_2": {"set": "block_2", "material": "Aluminium"},
    }
    if horizons[0] != horizons[1]:
        blocks["block_1"]["horizon_m"], blocks["block_2"]["horizon_m"] = horizons
    pull = {"type": "expression", "text": "1.0e-5*t"}
    return {
        "name": "bimaterial_bar",
        "geometry": {"type": "mesh", "file": str(mesh)},
        "discretization": {"horizon_m": max(horizons), "partial_volumes": False},
        "materials": {"Steel": lps(166.0e9, 77.0e9, 7850.0), "Aluminium": lps(70.0e9, 26.0e9, 2700.0)},
        "blocks": blocks,
        "solver": {
            "type": "newton",
            "time": 1.0,
            "load_steps": 1,
            "absolute_tolerance": 1e-7,
            "newton_iterations": 10,
        },
        "node_sets": {
            "left": {"type": "points", "indices": ids(FILES[1])},
            "right": {"type": "points", "indices": ids(FILES[2])},
        },
        "boundary_conditions": [
            {"set": "left", "kind": "displacement", "components": "xyz", "value": 0.0},
            {"set": "right", "kind": "displacement", "components": "x", "value": pull},
        ],
        "output": {
            "plots": False,
            "vtu": False,
            "exodus": {
                "file": "bimaterial_bar.e",
                "every": 1,
                "variables": ["Displacement", "Force_Density", "Dilatation"],
            },
        },
    }


def _numbers(path: Path) -> dict:
    """Every numeric dataset of a results file by name, less the run's wall-clock times."""
    found = {}
    with h5py.File(path) as f:
        f.visititems(
            lambda name, obj: (
                found.__setitem__(name, obj[()])
                if isinstance(obj, h5py.Dataset) and obj.dtype.kind in "fiub"
                else None
            )
        )
    return found


@pytest.mark.bitwise
@pytest.mark.parametrize("horizon_2", [2.015e-3, 3.015e-3])
def test_two_block_groups_are_the_two_block_case_bit_for_bit(tmp_path, horizon_2):
    """The deck (second group's horizon ``horizon_2``) and the hand-written case of two blocks
    give the same results.h5 and Exodus values, bit for bit. Both are the same case, computed by the
    same code in the same order, and the kernels are compiled without value-changing fast-math flags
    (``peridyn.kernels.FASTMATH``), so this holds on every CPU."""
    deck_dir = tmp_path / "deck"
    deck_dir.mkdir()
    deck = _deck(
        deck_dir,
        lambda t: f'value="{horizon_2!r}"'.join(t.rsplit('value="2.015e-3"', 1)),  # group 2's
    )
    raw = convert_deck(deck)
    assert set(raw["blocks"]) == {"block_1", "block_2"}
    assert raw["discretization"]["horizon_m"] == max(2.015e-3, horizon_2)
    run_case(validate_case(raw), tmp_path / "from_deck")
    hand = _hand_case(deck_dir / FILES[0], (2.015e-3, horizon_2))
    run_case(validate_case(hand), tmp_path / "by_hand")
    first, second = _numbers(tmp_path / "from_deck/results.h5"), _numbers(tmp_path / "by_hand/results.h5")
    assert first.keys() == second.keys()
    assert [k for k in first if not np.array_equal(first[k], second[k])] == []
    a = read_exodus(tmp_path / "from_deck/bimaterial_bar.e").nodal_variables
    b = read_exodus(tmp_path / "by_hand/bimaterial_bar.e").nodal_variables
    assert a.keys() == b.keys() and all(np.array_equal(a[k], b[k]) for k in a)


def _strains(tmp_path: Path, deck: Path) -> tuple[float, float]:
    """Run ``deck``; the strain du/dx fitted along the bar's centre line in x in (3, 9) mm and
    (15, 21) mm: two horizons and more from the ends and from the interface at 12 mm."""
    run_case(validate_case(convert_deck(deck)), tmp_path)
    points, _, _ = read_text_mesh(deck.parent / FILES[0])
    u = read_exodus(tmp_path / "bimaterial_bar.e").nodal_variables["DisplacementX"][-1]
    line = (np.abs(points[:, 1] - 3e-3) < 0.6e-3) & (np.abs(points[:, 2] - 3e-3) < 0.6e-3)
    out = []
    for lo, hi in ((3e-3, 9e-3), (15e-3, 21e-3)):
        near = line & (points[:, 0] > lo) & (points[:, 0] < hi)
        out.append(np.polyfit(points[near, 0], u[near], 1)[0])
    return out[0], out[1]


def test_two_block_groups_strain_as_two_materials_in_series(tmp_path):
    """1D elasticity of a bar of two materials in series: one stress, so the strains of the
    halves are in the ratio eps1 / eps2 = E2 / E1 (Young's moduli of the deck's K and mu,
    E = 9 K mu / (3 K + mu)). The same bar of one material (both groups steel) measures how far
    the lattice and the clamped end leave the fitted strains from uniform (its ratio, ideally 1,
    is measured 1.011). Both within 2% (test_blocks.py's in-series bar: 2.2% of elongation at
    the interface, where the jump of E is smeared over a horizon; measured 0.006%)."""
    E1 = 9.0 * 166.0e9 * 77.0e9 / (3.0 * 166.0e9 + 77.0e9)
    E2 = 9.0 * 70.0e9 * 26.0e9 / (3.0 * 70.0e9 + 26.0e9)
    (tmp_path / "two").mkdir()
    (tmp_path / "one").mkdir()
    two = _strains(tmp_path / "two/out", _deck(tmp_path / "two"))
    one = _strains(
        tmp_path / "one/out",
        _deck(tmp_path / "one", lambda t: t.replace('value="Aluminium"/>', 'value="Steel"/>')),
    )
    print("two materials", two[0] / two[1], "one material", one[0] / one[1], "E2 / E1", E2 / E1)
    assert one[0] / one[1] == pytest.approx(1.0, rel=0.02)
    assert two[0] / two[1] == pytest.approx(E2 / E1, rel=0.02)


def test_several_block_groups_refused_where_they_cannot_run(tmp_path):
    """A block named by two groups, and groups of different material models, are errors
    naming the deck parameter."""
    both = _deck(tmp_path, lambda t: t.replace('value="block_2"', 'value="block_2 block_1"'))
    with pytest.raises(CaseFileError, match="Blocks.Aluminium Block.Block Names"):
        convert_deck(both)
    mixed = _deck(
        tmp_path,
        lambda t: t.replace(
            'value="Elastic"/>\n      <Parameter name="Density" type="double" value="2700.0"',
            'value="Elastic Bond Based"/>\n      <Parameter name="Density" type="double" value="2700.0"',
        ),
    )
    with pytest.raises(CaseFileError, match="Materials.Aluminium.Material Model"):
        convert_deck(mixed)
