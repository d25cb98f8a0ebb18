"""The case file's fatigue block: bad input gets a clear error naming the key (issue 8)."""

from pathlib import Path

import numpy as np
import pytest

from peridyn.errors import CaseFileError
from peridyn.io.case import load_case
from peridyn.jobs.fatigue import check_fatigue_case

CASE = Path(__file__).resolve().parents[2] / "cases" / "dogbone_fatigue.yaml"


@pytest.mark.parametrize(
    "override, message",
    [
        ("fatigue.A_I=-1.0", "fatigue.A_I"),
        ("fatigue.m_II=0", "fatigue.m_II"),
        ("fatigue.eps_inf=-0.001", "fatigue.eps_inf"),
        ("fatigue.load_ratio=1.0", "fatigue.load_ratio"),
        ("fatigue.load_ratio=-1.5", "fatigue.load_ratio"),
        ("fatigue.phi_c=0", "fatigue.phi_c"),
        ("fatigue.mapping=[]", "fatigue.mapping"),
        ("fatigue.mapping.0.tau=-1e-5", "fatigue.mapping[0].tau"),
        ("fatigue.tip.depth_axis=y", "tip.axis and tip.depth_axis must differ"),
        ("fatigue.tip.sense=down", "fatigue.tip.sense"),
        ("fatigue.crack_plane={axis: w, at: 0.02}", "fatigue.crack_plane.axis"),
        ("fatigue.crack_plane={axis: y}", "fatigue.crack_plane.at"),
    ],
)
def test_bad_fatigue_values_name_their_key(override, message):
    with pytest.raises(CaseFileError, match=message.replace("[", r"\[").replace("]", r"\]")):
        load_case(CASE, [override])


def test_missing_parameter_is_named(tmp_path):
    text = CASE.read_text().replace("  A_I: 426.0\n", "")
    path = tmp_path / "c.yaml"
    path.write_text(text)
    with pytest.raises(CaseFileError, match="fatigue.A_I.*required key that is missing"):
        load_case(path)


def test_fatigue_case_without_cyclic_load_is_refused():
    case = load_case(CASE, ["boundary_conditions=[]"])
    with pytest.raises(CaseFileError, match="boundary_conditions.*a cyclic load"):
        check_fatigue_case(case)


def test_unknown_no_damage_set_is_refused():
    case = load_case(CASE, ["fatigue.no_damage_sets=[left_edn]"])
    with pytest.raises(CaseFileError, match="fatigue.no_damage_sets.*did you mean"):
        check_fatigue_case(case)


def test_paris_fit_refuses_a_crack_measured_from_inside_the_body():
    """The Paris fit's K (eqs. 7.12-7.13, or the specimen's compliance) takes the crack length
    from the specimen's edge: a tip rule measuring from an interior start is refused by name."""
    sen = CASE.parent / "sen_fatigue_2d.yaml"
    with pytest.raises(CaseFileError, match="leave tip.start and tip.sense at their defaults"):
        load_case(sen, ["fatigue.tip.start=0.01"])


def test_a_crack_plane_leaves_only_the_bonds_across_it_breakable():
    """``fatigue.crack_plane`` (docs/fatigue.md): a bond may break iff its ends lie strictly on
    opposite sides of the plane, and a no-damage set still protects its points' bonds. On the
    small monitoring plate's 1 mm grid (rows at y = 19.5 and 20.5 mm about the plane y = 20 mm)
    the count of breakable bonds is the count of bonds across the plane less the protected ones."""
    from peridyn.fatigue.loop import breakable_bonds
    from peridyn.setup.build import build

    small = CASE.parent / "monitoring" / "monitor_small_fatigue.yaml"
    case = load_case(small, ["fatigue.crack_plane={axis: y, at: 0.020}"])
    model = build(case, small.parent).model
    b, y = model.bonds, model.body.points[:, 1]
    owners = b.owners()
    across = (y[owners] - 0.020) * (y[b.neighbours] - 0.020) < 0
    free = breakable_bonds(model, case.fatigue.no_damage_sets)
    confined = breakable_bonds(model, case.fatigue.no_damage_sets, plane=case.fatigue.crack_plane)
    np.testing.assert_array_equal(confined, free & across)
    assert 0 < confined.sum() < across.sum() < free.sum()
