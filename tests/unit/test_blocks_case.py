"""Bodies of several blocks (docs/blocks.md): the case schema and its errors, and the rules for
bonds between blocks (micromodulus, critical stretch, stable step)."""

import copy

import numpy as np
import pytest

from peridyn.analysis.bloch import BlochLattice
from peridyn.errors import CaseFileError, InputError
from peridyn.io.case import validate_case
from peridyn.io.mesh_text import to_text_mesh
from peridyn.physics.materials.blocks import assign_blocks
from peridyn.physics.materials.elastic import check_elastic
from peridyn.physics.materials.pmb import pmb_micromodulus
from peridyn.setup.build import build
from peridyn.setup.stable_step import STEP_MARGIN, estimated_stable_step

STEEL = {"model": "pmb", "E": 200e9, "density": 7850}
ALUMINIUM = {"model": "pmb", "E": 70e9, "density": 2700}
LEFT = {"type": "box", "min": [-1, -1, -1], "max": [0.003, 1, 1]}
RIGHT = {"type": "box", "min": [0.003, -1, -1], "max": [1, 1, 1]}
GOOD = {
    "name": "blocks",
    "geometry": {"type": "box", "size": [0.006, 0.004, 0.004]},
    "discretization": {"spacing": 1e-3, "horizon": 2.015, "partial_volumes": False},
    "materials": {"steel": STEEL, "aluminium": ALUMINIUM},
    "blocks": {
        "left": {"region": LEFT, "material": "steel"},
        "right": {"region": RIGHT, "material": "aluminium"},
    },
    "node_sets": {"end": {"type": "face", "face": "x+"}},
    "boundary_conditions": [{"set": "end", "kind": "force", "components": "x", "value": 10.0}],
    "solver": {"type": "explicit", "steps": 10},
}


def _raw(**sections):
    raw = copy.deepcopy(GOOD)
    raw.update(copy.deepcopy(sections))
    return raw


def test_bond_between_blocks_has_the_mean_micromodulus():
    """docs/blocks.md, PMB: a bond within a block has its block's c0 (Silling and Askari
    2005), a bond between blocks the mean of its ends' c0."""
    setup = build(validate_case(_raw()))
    b, model = setup.bonds, setup.model
    c_steel = pmb_micromodulus(200e9, 3, b.horizon, "constant")
    c_alu = pmb_micromodulus(70e9, 3, b.horizon, "constant")
    left = setup.body.points[:, 0] < 0.003
    i, j = b.owners(), b.neighbours
    c = np.asarray(model.bond_stiffness) / (b.influence * model.bond_volume)
    np.testing.assert_allclose(c[left[i] & left[j]], c_steel, rtol=1e-14)
    np.testing.assert_allclose(c[~left[i] & ~left[j]], c_alu, rtol=1e-14)
    np.testing.assert_allclose(c[left[i] != left[j]], 0.5 * (c_steel + c_alu), rtol=1e-14)


def test_bond_between_blocks_breaks_at_the_smaller_critical_stretch():
    """docs/blocks.md: a bond breaks when either end's material breaks it, at the smaller of the
    two critical stretches; a block without damage keeps its own bonds."""
    materials = {
        "steel": {**STEEL, "damage": {"critical_stretch": 2e-3}},
        "aluminium": {**ALUMINIUM, "damage": {"critical_stretch": 1e-3}},
    }
    setup = build(validate_case(_raw(materials=materials)))
    b, left = setup.bonds, setup.body.points[:, 0] < 0.003
    i, j = b.owners(), b.neighbours
    stretch = setup.damage.critical_stretch
    assert np.all(stretch[left[i] & left[j]] == 2e-3)
    assert np.all(stretch[~left[i] | ~left[j]] == 1e-3)
    materials["steel"].pop("damage")
    setup = build(validate_case(_raw(materials=materials)))
    breakable = setup.damage.breakable
    assert not breakable[left[i] & left[j]].any()
    assert breakable[~left[i] | ~left[j]].all()
    assert np.all(setup.damage.critical_stretch[~left[i] | ~left[j]] == 1e-3)


def test_stable_step_of_blocks():
    """Silling and Askari (2005) bound per point: a body of two PMB blocks is stable at no
    longer a step than either material alone, and the estimate of ``peridyn validate`` (largest
    E over smallest density) is no longer than STEP_MARGIN above the model's step."""
    case = validate_case(_raw())
    two = build(case).model.critical_time_step()
    alone = []
    for mat in (STEEL, ALUMINIUM):
        raw = _raw()
        raw.pop("materials"), raw.pop("blocks")
        alone.append(build(validate_case({**raw, "material": mat})).model.critical_time_step())
    assert two <= min(alone)
    assert estimated_stable_step(case) <= (1 + STEP_MARGIN) * two


@pytest.mark.parametrize(
    "change, key, message",
    [
        (
            {"materials": {"steel": STEEL}, "blocks": {"left": {"region": LEFT, "material": "steel"}}},
            "blocks",
            r"point \d+ lies in no block \(48 points in none",
        ),
        (
            {
                "blocks": {
                    "left": {"region": LEFT, "material": "steel"},
                    "all": {"set": "all", "material": "aluminium"},
                }
            },
            "blocks",
            "lies in blocks 'left' and 'all'",
        ),
        (
            {
                "blocks": {
                    "left": {
                        "region": {"type": "sphere", "center": [1, 1, 1], "radius": 0.001},
                        "material": "steel",
                    },
                    "right": {"set": "all", "material": "aluminium"},
                }
            },
            "blocks",
            "block 'left' holds no point",
        ),
    ],
)
def test_points_in_no_block_or_two_are_refused(change, key, message):
    with pytest.raises(CaseFileError, match=message) as err:
        build(validate_case(_raw(**change)))
    assert err.value.key == key


@pytest.mark.parametrize(
    "change, key, message",
    [
        ({"material": STEEL}, "blocks", "either material .* or materials and blocks"),
        ({"blocks": {}}, "materials", "give blocks too"),
        (
            {"blocks": {"left": {"region": LEFT, "material": "steal"}}},
            "blocks.left.material",
            "did you mean 'steel'",
        ),
        (
            {"blocks": {"left": {"set": "all", "material": "steel"}}},
            "materials.aluminium",
            "no block is made of it",
        ),
        (
            {"materials": {"steel": STEEL, "aluminium": {**ALUMINIUM, "model": "lps", "nu": 0.3}}},
            "materials.aluminium.model",
            "share one model",
        ),
        (
            {"materials": {"steel": STEEL, "aluminium": {**ALUMINIUM, "surface_correction": "energy"}}},
            "materials.aluminium.surface_correction",
            "share one model and surface correction",
        ),
        (
            {
                "materials": {
                    "steel": {**STEEL, "model": "lps", "nu": 0.3},
                    "aluminium": {**ALUMINIUM, "model": "lps"},
                }
            },
            "materials.aluminium.nu",
            "needs Poisson's ratio",
        ),
        (
            {"blocks": {"left": {"material": "steel"}, "right": {"set": "all", "material": "aluminium"}}},
            "blocks.left",
            "exactly one of region or set",
        ),
        (
            {
                "blocks": {
                    "left": {"set": "lefty", "material": "steel"},
                    "right": {"set": "all", "material": "aluminium"},
                }
            },
            "blocks.left.set",
            "unknown node set 'lefty'",
        ),
        ({"contact": {"radius": 0.9}}, "contact", "several blocks"),
    ],
)
def test_bad_blocks_are_refused_naming_the_key(change, key, message):
    with pytest.raises(CaseFileError, match=message) as err:
        validate_case(_raw(**change))
    assert err.value.key == key


def test_missing_material_and_blocks_is_refused():
    raw = _raw()
    raw.pop("materials"), raw.pop("blocks")
    with pytest.raises(CaseFileError, match="material: a required key that is missing"):
        validate_case(raw)


def test_features_without_blocks_refuse_them():
    """Bloch analyses take one material (yet): a clear error, not a wrong answer (MPI runs take
    blocks: tests/mpi/test_mpi_decks.py)."""
    case = validate_case(_raw())
    with pytest.raises(InputError, match="body of one material"):
        BlochLattice.from_case(case)


def test_assign_blocks_and_per_point_constants_errors():
    assert assign_blocks({"a": np.array([True, False]), "b": np.array([False, True])}).tolist() == [0, 1]
    with pytest.raises(InputError, match="point 1 lies in no block"):
        assign_blocks({"a": np.array([True, False])})
    with pytest.raises(InputError, match="material E must be positive and finite, got -1.0"):
        check_elastic(np.array([1.0, -1.0]), 0.25, 1.0)


def test_blocks_of_a_text_mesh_by_their_sets(tmp_path):
    """A Peridigm text mesh's block ids are node sets ``block_<id>`` (``io.mesh_text``), so a
    case's blocks can name them; a set the mesh lacks is refused when the mesh is read."""
    grid = validate_case(_raw())
    body = build(grid).body
    to_text_mesh(body, tmp_path / "bar.txt", block_ids=np.where(body.points[:, 0] < 0.003, 1, 2))
    raw = _raw(
        geometry={"type": "mesh", "file": str(tmp_path / "bar.txt")},
        blocks={
            "left": {"set": "block_1", "material": "steel"},
            "right": {"set": "block_2", "material": "aluminium"},
        },
    )
    raw["discretization"].pop("spacing", None)
    mesh, direct = build(validate_case(raw)), build(grid)
    u = np.random.default_rng(2).normal(scale=1e-6, size=body.points.shape)
    np.testing.assert_allclose(mesh.model.force(u), direct.model.force(u), rtol=1e-12, atol=0)
    raw["blocks"]["right"]["set"] = "block_3"
    with pytest.raises(CaseFileError, match="block_3") as err:
        build(validate_case(raw))
    assert err.value.key == "blocks.right.set"


@pytest.mark.bitwise
def test_blocks_of_their_own_horizons():
    """docs/blocks.md: a bond between blocks exists within the smaller of its ends' horizons,
    and weighs its influence and partial volume with it. A point whose family lies in its own
    block has the family of the one-material body of its block's horizon (bit for bit), and
    its PMB c0 is that of its horizon (Silling and Askari 2005: c0 = 18 K / (pi delta^4)). Bit for bit:
    the same bond's coefficients are computed by the same code in the same order."""
    raw = _raw(materials={"steel": STEEL, "aluminium": STEEL})
    raw["geometry"]["size"] = [0.012, 0.006, 0.006]
    raw["discretization"]["partial_volumes"] = True
    raw["blocks"]["left"]["region"]["max"][0] = raw["blocks"]["right"]["region"]["min"][0] = 0.006
    raw["blocks"]["right"]["horizon_m"] = 3.015e-3
    setup = build(validate_case(raw))
    b, x = setup.bonds, setup.body.points
    delta = np.where(x[:, 0] < 0.006, 2.015e-3, 3.015e-3)
    np.testing.assert_allclose(b.point_horizon, delta, rtol=1e-15)
    i, j = b.owners(), b.neighbours
    near = np.minimum(delta[i], delta[j])
    assert np.all(b.length <= near + 0.5 * np.sqrt(3) * 1e-3)  # partial volumes: the cell reaches in
    for wide, key, value, inner in ((2.015e-3, "horizon", 2.015, 1), (3.015e-3, "horizon_m", 3.015e-3, 10)):
        one = _raw(material=STEEL)
        one.pop("materials"), one.pop("blocks")
        one["geometry"]["size"] = raw["geometry"]["size"]
        one["discretization"] = {"spacing": 1e-3, key: value}
        alone = build(validate_case(one))
        p = int(np.flatnonzero((np.abs(x[:, 0] - (0.0005 + 1e-3 * inner)) < 1e-9) & (x[:, 1] > 0.002))[0])
        mine, theirs = (
            slice(b.offsets[p], b.offsets[p + 1]),
            slice(alone.bonds.offsets[p], alone.bonds.offsets[p + 1]),
        )
        assert np.array_equal(b.neighbours[mine], alone.bonds.neighbours[theirs])
        assert np.array_equal(b.volume_factor[mine], alone.bonds.volume_factor[theirs])
        assert np.array_equal(b.influence[mine], alone.bonds.influence[theirs])
        assert setup.model.c0[p] == alone.model.c0
        assert alone.model.c0 == pytest.approx(pmb_micromodulus(200e9, 3, wide, "constant"), rel=1e-14)


@pytest.mark.parametrize(
    "block, key, message",
    [
        ({"horizon": 2.0, "horizon_m": 2e-3}, "blocks.left", "at most one of horizon"),
        ({"horizon": 0.5}, "blocks.left", "at least 1"),
        ({"horizon_m": 0.5e-3}, "blocks.left.horizon_m", "below the spacing"),
    ],
)
def test_bad_block_horizons_are_refused(block, key, message):
    raw = _raw()
    raw["blocks"]["left"].update(block)
    with pytest.raises(CaseFileError, match=message) as err:
        validate_case(raw)
    assert err.value.key == key
