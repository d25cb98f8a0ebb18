"""The case file's fatigue block: bad input gets a clear error naming the key (issue 8)."""

from pathlib import Path

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
