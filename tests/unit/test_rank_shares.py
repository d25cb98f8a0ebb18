"""Rank 0's smaller part (``peridyn.jobs.rank_shares``): the shares balance a step in which rank 0
also records, by the model stated in the module docstring."""

from pathlib import Path

import pytest

from peridyn.io.case import load_case
from peridyn.jobs import rank_shares as rs
from peridyn.jobs.build import add_actuators, bond_reach, build_body

CASES = Path(__file__).resolve().parents[2] / "cases"


@pytest.fixture(scope="module")
def lamb():
    case = load_case(CASES / "lamb_plate.yaml")
    body, _ = add_actuators(case, build_body(case, CASES))
    return case, body, bond_reach(case, body)


def test_seed_lamb_plate_counts(lamb):
    """The seed case records its 41 750-point top plane, a 250-point line and 3 sensors (u and v)
    at every step; its points have 74.4 bonds on average (9 322 368 / 125 250, the run's count)."""
    case, body, reach = lamb
    assert rs.recorded_values_per_step(case, body) == 3 * (41_750 + 250 + 2 * 3)
    assert rs.bonds_per_point(body, reach) == pytest.approx(9_322_368 / 125_250, rel=0.01)


@pytest.mark.parametrize("ranks", [2, 3, 8])
def test_shares_balance_recording_and_force(lamb, ranks):
    """Rank 0's force plus its recording (in points) equals every other rank's force."""
    case, body, reach = lamb
    shares = rs.rank_shares(case, body, ranks, reach)
    assert shares.sum() == pytest.approx(body.n_points)
    values = rs.recorded_values_per_step(case, body)
    recording = values * rs.RECORD_COST_BONDS / rs.bonds_per_point(body, reach)
    assert shares[0] + recording == pytest.approx(shares[1:], rel=1e-12)


def test_root_keeps_a_floor_and_static_runs_split_evenly(lamb, monkeypatch):
    case, body, reach = lamb
    monkeypatch.setattr(rs, "RECORD_COST_BONDS", 1e3)  # recording far dearer than a part's force
    shares = rs.rank_shares(case, body, 4, reach)
    assert shares[0] == pytest.approx(rs.MIN_ROOT_SHARE * body.n_points / 4)
    assert shares.sum() == pytest.approx(body.n_points)
    assert rs.rank_shares(case, body, 1, reach) is None
    modal = load_case(CASES / "lamb_plate.yaml", ["solver={type: modal}"])
    assert rs.rank_shares(modal, body, 2, reach) is None
