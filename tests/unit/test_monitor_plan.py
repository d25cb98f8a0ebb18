"""The monitoring job's plan (peridyn.jobs.monitor_plan) and case file (peridyn.io.monitor_case):
the schedule, the crack at a cycle, the two damage transfers into the wave case, and the one-line
errors of a bad monitoring case."""

from pathlib import Path

import numpy as np
import pytest

from peridyn.discretization.bonds import crossing_segment, cut_bonds
from peridyn.errors import CaseFileError
from peridyn.io.case import FatigueTip, load_case
from peridyn.io.monitor_case import load_monitor_case
from peridyn.jobs.monitor import network_case
from peridyn.jobs.monitor_plan import (
    FatigueHistory,
    bonds_case,
    crack_lines,
    cut_case,
    damage_at,
    interrogation_steps,
)
from peridyn.physics.damage import damage_field
from peridyn.setup.build import build

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
    # a 2D grid of 1 mm with a cracked row pair along y = 20 mm from x = 15 to 30 mm; the points
    # beyond x = 20 mm broke one after another (first break = 1000 cycles per mm past 20 mm),
    # each losing its bond across the crack line to the point opposite then
    x, y = np.meshgrid(np.arange(0.5, 40) * 1e-3, np.arange(0.5, 40) * 1e-3)
    points = np.column_stack([x.ravel(), y.ravel()])
    on = (np.abs(points[:, 1] - 0.020) < 0.001) & (points[:, 0] > 0.015) & (points[:, 0] < 0.030)
    first = np.where(on, np.maximum(0.0, points[:, 0] - 0.020) * 1e6, np.inf)
    below = np.flatnonzero(on & (points[:, 1] < 0.020) & (points[:, 0] > 0.020))
    above = np.array([np.argmin(np.hypot(*(points - points[i] - [0, 1e-3]).T)) for i in below])
    pairs = np.column_stack([below, above])
    return FatigueHistory(np.array([0.0]), np.array([0.0]), points, first, pairs, first[below].astype(float))


def _small_crack(end_x: float = 0.023):
    """The small case's fatigue model and a history whose cycles broke the bonds that cross its
    crack line (y = 20 mm) from the notch root (x = 20 mm) to ``end_x`` (m), each at 1000 cycles
    per mm of the crossing from the root."""
    model = build(load_case(TINY / "monitor_small_fatigue.yaml"), TINY).model
    b, points = model.bonds, model.body.points
    owners = b.owners()
    a, c = points[owners], points[b.neighbours]
    cross = crossing_segment(a, c, [0.020, 0.020], [end_x, 0.020]) & (owners < b.neighbours) & b.intact
    at = a[cross, 0] + (0.020 - a[cross, 1]) / (c[cross, 1] - a[cross, 1]) * (c[cross, 0] - a[cross, 0])
    pairs = np.column_stack([owners[cross], b.neighbours[cross]])
    n = model.body.n_points
    history = FatigueHistory(
        np.array([0.0]),
        np.array([0.0]),
        points[:, :2],
        np.full(n, np.inf),
        pairs,
        (at - 0.020) * 1e6,
    )
    return model, history, cross


def test_the_fatigue_damage_at_a_cycle_is_its_model_with_the_bonds_broken_by_then():
    model, history, _ = _small_crack()
    b = model.bonds
    intact = b.intact.copy()
    phi = damage_at(model, history, [0.0, 2400.0, np.inf])
    np.testing.assert_array_equal(b.intact, intact)  # the model is left as given
    np.testing.assert_array_equal(phi[0], damage_field(model))  # the notch alone
    for k, end in ((1, 0.0224), (2, 0.023)):  # 2400 cycles: the bonds crossing up to x = 22.4 mm
        cut_bonds(model.body, b, lambda x, y, end=end: crossing_segment(x, y, [0.020, 0.020], [end, 0.020]))
        np.testing.assert_array_equal(phi[k], damage_field(model))
        b.intact[:] = intact
    lines = crack_lines(history.points, phi[2], 1e-3, FatigueTip(axis="x", start=0.020, damage=0.3))
    # one crack, from the notch root along the line to the last cracked point (at the tip's
    # damage threshold: the points beside the line's last millimetre keep more than 0.7 of
    # their bonds)
    cracked = history.points[phi[2] >= 0.3]
    assert len(lines) == 1
    np.testing.assert_allclose(lines[0][0], [0.020, 0.020], atol=1e-12)
    assert lines[0][-1] == pytest.approx([cracked[:, 0].max(), 0.020], abs=0.5e-3)
    assert cracked[:, 0].max() < 0.023


def test_the_two_transfers_of_a_clean_crack_cut_the_same_3d_bonds_but_those_through_its_ends():
    """A crack line whose every crossing bond the fatigue broke: the cut (a through-thickness
    rectangle on the line) and the broken bonds (their columns) cut the same bonds of the 3D
    plate, but for the bonds whose in-plane projection passes through an end of the line, which
    one transfer or the other may take by round-off (the crossing tests are strict)."""
    _, history, _ = _small_crack()
    wave = network_case(
        load_monitor_case(TINY / "monitor_small.yaml")[0], load_case(TINY / "monitor_small_wave.yaml"), 0
    )
    line = np.array([[0.020, 0.020], [0.023, 0.020]])
    sets = []
    for case in (cut_case(wave, "cut", [line]), bonds_case(wave, "bonds", history, np.inf, 1e-3)):
        setup = build(case, TINY)
        b, points = setup.bonds, setup.body.points
        owners = b.owners()
        broken = ~b.intact & (owners < b.neighbours)
        sets.append({(int(i), int(j)) for i, j in zip(owners[broken], b.neighbours[broken], strict=True)})
    differ = sets[0] ^ sets[1]
    assert len(sets[0] & sets[1]) > 100  # both cut the notch and the crack
    for i, j in differ:  # each through an end of the line, in the plane
        xy = points[[i, j], :2]
        u, w = xy[1] - xy[0], line - xy[0]
        through = np.abs(u[0] * w[:, 1] - u[1] * w[:, 0]) < 1e-12
        assert any(through), (xy, "passes through neither end")


def test_a_cut_crack_becomes_through_thickness_rectangles_and_broken_bonds_a_bonds_precrack():
    wave = network_case(
        load_monitor_case(TINY / "monitor_small.yaml")[0], load_case(TINY / "monitor_small_wave.yaml"), 0
    )
    crack = np.array([[0.020, 0.020], [0.022, 0.020], [0.024, 0.021]])
    cut = cut_case(wave, "cut", [crack])
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
        ("transfer=pieces", "transfer"),
    ],
)
def test_a_bad_monitoring_case_gets_one_line_naming_its_key(setting, key):
    with pytest.raises(CaseFileError) as err:
        load_monitor_case(TINY / "monitor_small.yaml", [setting])
    message = str(err.value)
    assert "\n" not in message and key in message
