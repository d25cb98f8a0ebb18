"""The monitoring job's plan (peridyn.jobs.monitor_plan) and case file (peridyn.io.monitor_case):
the schedule, the crack at a cycle, the two damage transfers into the wave case, and the one-line
errors of a bad monitoring case."""

from pathlib import Path

import numpy as np
import pytest

from peridyn.errors import CaseFileError
from peridyn.io.case import FatigueTip, load_case
from peridyn.io.monitor_case import load_monitor_case
from peridyn.jobs.monitor import network_case
from peridyn.jobs.monitor_plan import (
    FatigueHistory,
    bonds_case,
    crack_at,
    cut_case,
    grown_crack,
    interrogation_steps,
)

TINY = Path(__file__).parents[2] / "cases" / "monitoring"


def test_schedule_takes_the_baseline_each_growth_step_each_cycle_mark_and_the_end():
    cycles = np.arange(0.0, 11.0) * 1000
    a = np.array([0, 0, 0, 0.5, 1.0, 1.2, 2.0, 2.1, 3.5, 3.6, 3.7]) * 1e-3
    # growth marks: first step reaching +1 mm since the last one: a = 1.0 (k 4), 2.0 (k 6), 3.5 (k 8)
    assert interrogation_steps(cycles, a, every_growth=1e-3).tolist() == [0, 4, 6, 8, 10]
    # cycle marks every 4000: the last step at or before 4000 and 8000
    assert interrogation_steps(cycles, a, every_cycles=4000).tolist() == [0, 4, 8, 10]
    # until 2 mm: the history ends at the first step with a >= 2 mm (k 6)
    assert interrogation_steps(cycles, a, every_growth=1e-3, until=2e-3).tolist() == [0, 4, 6]
    # at most 3: the baseline, the first other one, the last
    assert interrogation_steps(cycles, a, every_growth=1e-3, most=3).tolist() == [0, 4, 10]


def _straight_history() -> FatigueHistory:
    # a 2D grid of 1 mm with a damaged row pair along y = 20 mm from x = 15 to 30 mm; the points
    # beyond x = 20 mm broke one after another (first break = 1000 cycles per mm past 20 mm),
    # each losing its bond across the crack line to the point opposite then
    x, y = np.meshgrid(np.arange(0.5, 40) * 1e-3, np.arange(0.5, 40) * 1e-3)
    points = np.column_stack([x.ravel(), y.ravel()])
    on = (np.abs(points[:, 1] - 0.020) < 0.001) & (points[:, 0] > 0.015) & (points[:, 0] < 0.030)
    damage = np.where(on, 0.4, 0.0)
    first = np.where(on, np.maximum(0.0, points[:, 0] - 0.020) * 1e6, np.inf)
    below = np.flatnonzero(on & (points[:, 1] < 0.020) & (points[:, 0] > 0.020))
    above = np.array([np.argmin(np.hypot(*(points - points[i] - [0, 1e-3]).T)) for i in below])
    pairs = np.column_stack([below, above])
    return FatigueHistory(
        np.array([0.0]), np.array([0.0]), points, damage, first, pairs, first[below].astype(float)
    )


def test_the_crack_at_a_cycle_is_the_final_path_from_the_start_cut_to_the_crack_length():
    tip = FatigueTip(axis="x", start=0.020, damage=0.3)
    whole = grown_crack(_straight_history(), 1e-3, tip)
    # the path starts at tip.start on the crack line and runs along +x to the last cracked column
    np.testing.assert_allclose(whole[0], [0.020, 0.020], atol=1e-12)
    assert whole[-1][0] == pytest.approx(0.0295, abs=1e-3)
    crack = crack_at(whole, 0.004)
    np.testing.assert_allclose(crack[-1], [0.024, 0.020], atol=1e-12)
    assert crack_at(whole, 0.0) is None


def test_a_cut_crack_becomes_through_thickness_rectangles_and_broken_bonds_a_bonds_precrack():
    wave = network_case(
        load_monitor_case(TINY / "monitor_small.yaml")[0], load_case(TINY / "monitor_small_wave.yaml"), 0
    )
    crack = np.array([[0.020, 0.020], [0.022, 0.020], [0.024, 0.021]])
    cut = cut_case(wave, "cut", crack)
    added = cut.precracks[len(wave.precracks) :]
    assert [p.type for p in added] == ["rectangle", "rectangle"]
    # each rectangle spans its segment in the plane and the whole 2 mm thickness (with margins)
    assert added[1].origin == pytest.approx([0.022, 0.020, -0.002])
    assert added[1].edge_u == pytest.approx([0.002, 0.001, 0.0])
    assert added[1].edge_v[2] > 3 * 0.002 - 1e-12
    bonds = bonds_case(wave, "bonds", _straight_history(), 3000.0, 1e-3)
    (added,) = bonds.precracks[len(wave.precracks) :]
    # the bonds across the crack line of x in (20, 23] mm broke by 3000 cycles: 3 of them, each
    # from (x, 19.5 mm) to (x, 20.5 mm), found within a quarter spacing
    assert added.type == "bonds" and added.tolerance == pytest.approx(0.25e-3)
    np.testing.assert_allclose(
        added.pairs, [[x, 0.0195, x, 0.0205] for x in (0.0205, 0.0215, 0.0225)], atol=1e-12
    )
    assert cut.actuators.keys() == {"t0"} and len(cut.output.pzt_sensors) == 3


@pytest.mark.parametrize(
    ("setting", "key"),
    [
        ("transducers.centers=[[0.01, 0.01], [0.02, 0.02]]", "transducers.centers"),
        ("schedule={max_interrogations: 5}", "schedule"),
        ("noise.level=-0.01", "noise.level"),
        ("processing.index=energy", "processing"),
        ("transducers.colour=red", "transducers.colour"),
    ],
)
def test_a_bad_monitoring_case_gets_one_line_naming_its_key(setting, key):
    with pytest.raises(CaseFileError) as err:
        load_monitor_case(TINY / "monitor_small.yaml", [setting])
    message = str(err.value)
    assert "\n" not in message and key in message
