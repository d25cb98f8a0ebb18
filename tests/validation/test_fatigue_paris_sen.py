"""Paris law on the single-edge-notch specimen (VALIDATION.md V5; thesis seed 002 eqs. 7.10-7.14):
the slope of log(da/dN) against log(dK) in phase II is m_II = 4 within 10 %.

Eq. 7.12 is not the K of the thesis's 50 x 8 x 3 mm specimen, loaded on its long faces 4 mm from
the crack (``tests/unit/test_fatigue_paris_specimen.py``); its slope against its own compliance K
is 4.02 at 1 mm but 2.8 at 0.5 mm (docs/fatigue.md), not a settled value, so it is not asserted
here. A tall SEN strip (``cases/sen_fatigue_2d.yaml``), for which eq. 7.12 holds, is measured
against eq. 7.12 itself.
"""

from pathlib import Path

import pytest

from peridyn.io.case import load_case
from peridyn.jobs.fatigue import run_fatigue_case

CASES = Path(__file__).parents[2] / "cases"


@pytest.mark.slow
def test_tall_sen_strip_paris_slope_against_eq_7_12(tmp_path):
    """A SEN strip for which eq. 7.12 holds (10 x 20 mm, 2D plane stress, 0.25 mm, horizon 3
    spacings, ``cases/sen_fatigue_2d.yaml``): slope 4 within 10 % against eq. 7.12 itself.
    Measured: 3.92 from 16 rates (a = 2.75-6.5 mm), 8.3 min of CPU."""
    case = load_case(CASES / "sen_fatigue_2d.yaml", ["output.plots=false"])
    summary = run_fatigue_case(case, tmp_path, modal=False)
    assert summary["crack_length_m"] >= 6.0e-3  # grew through a/b = 0.24-0.6
    assert summary["paris_rates"] >= 10
    assert summary["paris_slope"] == pytest.approx(4.0, rel=0.10)
