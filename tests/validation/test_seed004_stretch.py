"""Seed 004 stretching (VALIDATION.md V6), the shipped case as it is: force rising at 1 MN/s
to 100 N over 100 us. The seed (Fig. 2a) shows a straight crack across the plate at 100 us."""

import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).parents[1] / "examples"))
from test_seed004_short import check_straight_crack_from_both_tips, run_stretch  # noqa: E402


@pytest.mark.slow
def test_stretch_case_grows_straight_crack_from_both_tips():
    body, phi = run_stretch()
    rows = check_straight_crack_from_both_tips(body, phi)
    assert rows.min() < 0.5e-3 and rows.max() > 3.5e-3  # through the plate by 100 us (Fig. 2a)
