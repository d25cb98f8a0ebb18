"""Peridigm's conventions that peridyn's case keys take (docs/peridigm.md): bond filters that
take bonds out of the families (Peridigm's ``PdBondFilter::FinitePlane``), forces that yield to
a prescribed motion, a critical stretch in time, Peridigm's grid numbering and 3D components
of the Exodus output, repeated deck parameters."""

import math

import numpy as np
import pytest
from conftest import STEEL_E, STEEL_NU, STEEL_RHO

from peridyn.discretization import geometry
from peridyn.discretization.bonds import crossing_finite_plane, crossing_mask, find_bonds, without_bonds
from peridyn.errors import CaseFileError, InputError
from peridyn.io.peridigm_deck import read_deck
from peridyn.io.recorder import arranged, grid_order
from peridyn.physics.damage import BondDamage
from peridyn.physics.loads import BoundaryCondition, Loading
from peridyn.physics.materials import make_model
from peridyn.physics.timefunctions import Step

#: The plane y = 0 for 0 <= x <= 2, -1 <= z <= 1: corner (0, 0, -1), normal +y, bottom +x
#: (2 m), side bottom x normal = +z (2 m).
PLANE = {
    "corner": (0, 0, -1),
    "normal": (0, 1, 0),
    "bottom": (1, 0, 0),
    "bottom_length": 2.0,
    "side_length": 2.0,
}


def _meets(a, b, **changes):
    plane = PLANE | changes
    return bool(
        crossing_finite_plane(
            np.array([a], float),
            np.array([b], float),
            plane["corner"],
            plane["normal"],
            plane["bottom"],
            plane["bottom_length"],
            plane["side_length"],
        )[0]
    )


def test_finite_plane_crossing_is_peridigms():
    """A bond crossing inside the rectangle meets it; one ending on the plane (t = 1) too, as
    Peridigm's t in [0, 1] says; one past an edge, or parallel to the plane, does not; an edge
    itself counts (Peridigm's -1e-15 < a, b); the bottom vector is taken as given (not
    normalised): bottom (2, 0, 0) with bottom length 2 reaches x = 1 only."""
    assert _meets((1, -0.5, 0), (1, 0.5, 0))
    assert _meets((1, -0.5, 0), (1, 0.0, 0))
    assert not _meets((3, -0.5, 0), (3, 0.5, 0))
    assert not _meets((1, -0.5, 2), (1, 0.5, 2))
    assert not _meets((0.5, 0.1, 0), (1.5, 0.1, 0))
    assert _meets((0, -0.5, 0), (0, 0.5, 0))
    assert _meets((0.9, -0.5, 0), (0.9, 0.5, 0), bottom=(2, 0, 0))
    assert not _meets((1.1, -0.5, 0), (1.1, 0.5, 0), bottom=(2, 0, 0))


def test_filtered_bonds_leave_the_families():
    """A plane through the middle of a bar takes out exactly the bonds that cross it, both
    copies, from the families (counts, neighbours and per-bond arrays together)."""
    body = geometry.box((4.0, 1.0, 1.0), 1.0)
    bonds = find_bonds(body, 2.015, partial_volumes=False)
    cut = crossing_mask(
        body, bonds, lambda a, b: crossing_finite_plane(a, b, (2, -1, -1), (1, 0, 0), (0, 0, 1), 3.0, 3.0)
    )
    kept = without_bonds(bonds, cut)
    x = body.points[:, 0]
    owners = bonds.owners()
    crossing = (x[owners] - 2) * (x[bonds.neighbours] - 2) < 0
    np.testing.assert_array_equal(cut, crossing)
    assert kept.n_bonds == bonds.n_bonds - crossing.sum()
    np.testing.assert_array_equal(
        np.diff(kept.offsets), np.bincount(owners[~crossing], minlength=body.n_points)
    )
    np.testing.assert_array_equal(kept.neighbours, bonds.neighbours[~crossing])
    np.testing.assert_array_equal(kept.length, bonds.length[~crossing])
    assert np.all((x[kept.owners()] - 2) * (x[kept.neighbours] - 2) > 0)


def _pair():
    body = geometry.box((2e-3, 1e-3, 1e-3), 1e-3)
    body = body.with_node_set("left", body.points[:, 0] < 1e-3).with_node_set("all", np.ones(2, bool))
    model = make_model("lps", body, find_bonds(body, 1.5e-3), E=STEEL_E, nu=STEEL_NU, density=STEEL_RHO)
    return body, model


def test_force_yields_to_a_prescribed_motion_only_when_asked():
    """A body force on a set holding a prescribed component is an error by default; with
    ``where_prescribed="yield"`` it is accepted and still counts in the body-force density
    (Peridigm adds it to the acceleration the reported velocity of the point carries)."""
    body, _ = _pair()
    held = BoundaryCondition("left", "displacement", "x")
    with pytest.raises(InputError, match="prescribed motion and an applied force"):
        Loading(body, [held, BoundaryCondition("all", "body_force", "x")])
    loading = Loading(body, [held, BoundaryCondition("all", "body_force", "x", where_prescribed="yield")])
    density = loading.body_force_density(0.0, np.zeros((2, 3)))
    np.testing.assert_array_equal(density[:, 0], [0.0, 0.0])  # the BC's default value is 0
    with pytest.raises(InputError, match="where_prescribed"):
        BoundaryCondition("all", "body_force", "x", where_prescribed="skip")


def test_critical_stretch_in_time_breaks_after_the_switch():
    """A pair stretched by 1e-3 keeps its bond while the critical stretch is 0.01 (t <= 1 s)
    and loses it at the first update after the switch to 1e-4."""
    _, model = _pair()
    damage = BondDamage(model, schedule=Step(time=1.0, before=1e-2, after=1e-4))
    u = np.zeros((2, 3))
    u[1, 0] = 1e-6  # stretch 1e-6 / 1e-3 = 1e-3
    assert damage.update(u, 0.5) == 0 and damage.update(u, 1.0) == 0
    assert damage.update(u, 1.5) == 2 and not model.bonds.intact.any()


def test_grid_order_and_three_components():
    """Points of a box (peridyn's order: z fastest) in PdQuickGrid's numbering (x fastest),
    values moved with their points, ids counting the file's rows, and 2D vectors padded with a
    zero z component."""
    body = geometry.box((3.0, 2.0, 1.0), 1.0)
    rows = grid_order(body.points)
    np.testing.assert_array_equal(body.points[rows][:4, :2], [[0.5, 0.5], [1.5, 0.5], [2.5, 0.5], [0.5, 1.5]])
    values = {
        "nodal": {"Displacement": body.points[:, :2]},
        "element": {"Volume": np.arange(6.0), "Element_Id": np.arange(1.0, 7.0)},
        "global_": {"Sum": np.array([1.0, 2.0])},
    }
    out = arranged(values, rows, 3)
    np.testing.assert_array_equal(out["nodal"]["Displacement"][:, :2], body.points[rows, :2])
    np.testing.assert_array_equal(out["nodal"]["Displacement"][:, 2], 0.0)
    np.testing.assert_array_equal(out["element"]["Volume"], np.arange(6.0)[rows])
    np.testing.assert_array_equal(out["element"]["Element_Id"], np.arange(1.0, 7.0))
    np.testing.assert_array_equal(out["global_"]["Sum"], [1.0, 2.0, 0.0])


def test_repeated_parameters_of_one_value_are_read(tmp_path):
    """Peridigm's decks repeat some parameters with one value (Bar_TwoDisconnectedPieces_QS):
    read; a repeat with another value, or a repeated list, is refused naming it."""
    deck = tmp_path / "deck.xml"
    line = '<Parameter name="Density" type="double" value="{}"/>'
    lists = '<ParameterList><ParameterList name="M">{}</ParameterList></ParameterList>'
    deck.write_text(lists.format(line.format(1) + line.format(1.0)))
    assert read_deck(deck) == {"M": {"Density": 1.0}}
    deck.write_text(lists.format(line.format(1) + line.format(2)))
    with pytest.raises(CaseFileError, match="M.Density"):
        read_deck(deck)
    deck.write_text('<ParameterList><ParameterList name="M"/><ParameterList name="M"/></ParameterList>')
    with pytest.raises(CaseFileError, match="a list given once"):
        read_deck(deck)


def test_step_time_function():
    """``before`` up to the switch time included, ``after`` later (arrays too)."""
    step = Step(time=2.0, before=5.0, after=1.0)
    np.testing.assert_array_equal(step(np.array([0.0, 2.0, math.nextafter(2.0, 3.0)])), [5.0, 5.0, 1.0])
