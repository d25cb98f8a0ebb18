"""The monitoring job's two damage transfers (docs/monitoring.md, "Damage transfer") on a crack
that is a clean cut: the small notched-hole plate of cases/monitoring/monitor_small.yaml whose
fatigue may break only the bonds across the notch's plane y = 20 mm (``fatigue.crack_plane``),
so the fatigue grows a mode-I crack along it and no damage band. Interrogated at 0, 5.5 and
6.5 mm of crack (the crack then crosses the path t0-t1, x = 22 mm, at least 3.5 mm, more than a
horizon, behind its tip) by the default transfer (``bonds``: the fatigue model's broken bonds
through the thickness), each repeated by the ``cut`` (the crack path as through-thickness cuts).

Where the crack is a clean cut, both give the wave model the same bonds (tests/unit/
test_monitor_plan.py); they still differ at the tip. The cut ends where the crack path of the
points at the tip's damage threshold ends (the tip rule's point); the fatigue model's broken
bonds do not stop there: some across the plane behind that point still hold, and about as many
beyond it have broken (13 bonds at 5.5 mm, 15 at 6.5 mm), the farthest 1 mm past it. The
bonds route's crack reaches farther, and the index of a path that the crack crosses grows with
its length (here 31% per mm), so the bonds route's indices are the higher ones: by 13% (residual
energy) and 14-15% (correlation) at 5.5 and 6.5 mm, outside the 10% the monitoring acceptance asks
there. (Nor does the other check the acceptance allows reach it: the fatigue on the 3D wave plate
itself, interrogated with its own broken bonds, gives indices 27-35% (residual energy) and 10-16%
(correlation) above the bonds route's at the same tip-rule lengths, its broken bonds reaching 1 mm
farther: benchmarks/monitoring_transfer_direct.py.)

The same job on half the spacing (0.5 mm, 5 layers: 6 288 points in 2D, 31 440 in 3D), its fatigue
in steps of 1 000 cycles, meets the acceptance: the process zone is a few spacings long (the
broken bonds reach 1 mm past the tip rule's point at the 1 mm grid's interrogations; on the 0.5 mm
grid, while that point stays put, from 0.25 to 0.75 mm past it), and at each interrogation (at
5.75 and 6.75 mm there, the crack lengths of that grid) the routes' difference is residual energy
13 and 13% -> 6.0 and 5.3%, correlation 14 and 15% -> 3.6 and 2.8%. The schedule interrogates at
the first step at which the crack has its length, when the process zone is at its shortest;
fatigue steps of 2 000 cycles (the 1 mm grid's) land up to 2 000 cycles later, with the zone 0.5
mm long, and give 10.7% (residual energy) at 5.75 mm; steps of 500 cycles give the 1 000-cycle
numbers at 5.75 mm and 3.5 and 1.7% at 6.75 mm (benchmarks/monitoring_transfer_step.py).

The job at 1 mm (fatigue of 80 steps on 1 568 points, 15 wave runs of 4 704 points, two
processes of one thread) takes 34 s on 2 cores at load 4-6, 49 s at load 9; at 0.5 mm (fatigue of
175 steps, runs of 31 440 points) 5.5 minutes at load 1-4, about 19 at load 6-9 (slow).
"""

from pathlib import Path

import numpy as np
import pytest
import yaml

from peridyn.jobs.monitor import read_history, run_monitor

CASES = Path(__file__).parents[2] / "cases" / "monitoring"
#: The notch's plane (the crack plane), m: the notch runs along y = 20 mm to its root at x = 20 mm.
PLANE_Y, ROOT_X = 0.020, 0.020
INDICES = ("residual_energy_index", "correlation_index")


def _job(folder: Path, spacing: float, layers: int, steps: int, tau: float = 5.0e-4):
    """The clean-crack monitoring job on the grid of ``spacing`` (m) with ``layers`` in the wave
    plate and ``steps`` fatigue steps of 1 / ``tau`` cycles: (summary's monitoring block, fatigue
    history)."""
    fatigue = yaml.safe_load((CASES / "monitor_small_fatigue.yaml").read_text())
    fatigue["discretization"]["spacing"] = spacing
    fatigue["fatigue"]["crack_plane"] = {"axis": "y", "at": PLANE_Y}
    fatigue["fatigue"]["mapping"] = [{"steps": steps, "tau": tau}]
    (folder / "fatigue.yaml").write_text(yaml.safe_dump(fatigue))
    wave = yaml.safe_load((CASES / "monitor_small_wave.yaml").read_text())
    wave["discretization"]["spacing"] = spacing
    wave["geometry"]["layers"] = layers
    (folder / "wave.yaml").write_text(yaml.safe_dump(wave))
    mon = yaml.safe_load((CASES / "monitor_small.yaml").read_text())
    mon.update(
        fatigue_case="fatigue.yaml",
        wave_case="wave.yaml",
        schedule={"every_crack_growth": 5.5e-3, "until_crack_length": 6.5e-3},
        output={"plots": False},
    )
    (folder / "monitor.yaml").write_text(yaml.safe_dump(mon))
    out = folder / "out"
    summary = run_monitor(folder / "monitor.yaml", out, executor="processes", workers=2, threads=1)
    return summary["monitoring"], read_history(out / "fatigue")


@pytest.fixture(scope="module")
def job(tmp_path_factory):
    """The clean-crack monitoring job on the cases' 1 mm grid."""
    return _job(tmp_path_factory.mktemp("clean"), 1.0e-3, 3, 80)  # a crack of about 8 mm


@pytest.fixture(scope="module")
def fine_job(tmp_path_factory):
    """The clean-crack monitoring job on half the spacing (5 layers), its fatigue in steps of
    1 000 cycles (a crack of about 7.75 mm)."""
    return _job(tmp_path_factory.mktemp("fine"), 0.5e-3, 5, 175, tau=1.0e-3)


def _crossing_x(points: np.ndarray, pairs: np.ndarray) -> np.ndarray:
    """x (m) at which each bond ((n, 2) point indices) crosses the plane y = PLANE_Y."""
    a, b = points[pairs[:, 0]], points[pairs[:, 1]]
    return a[:, 0] + (PLANE_Y - a[:, 1]) / (b[:, 1] - a[:, 1]) * (b[:, 0] - a[:, 0])


def _reach(history, cycles: float, crack_length: float) -> float:
    """How far (m) past the tip rule's point the bonds broken by ``cycles`` reach along the plane."""
    broken = history.broken_pairs[history.break_cycle <= cycles]
    return float(_crossing_x(history.points, broken).max() - (ROOT_X + crack_length))


def test_on_a_clean_crack_the_bonds_route_reaches_past_the_cut_and_gives_the_higher_indices(job):
    m, history = job
    t = m["transfer"]
    assert (t["route"], t["check"]) == ("bonds", "cut") and m["crossed_paths"] == ["t0-t1"]
    assert t["interrogations"] == [1, 2] and m["final_crack_length_m"] == pytest.approx(6.5e-3)
    # the crack is confined to the plane: every bond the fatigue broke crosses it
    y = history.points[history.broken_pairs, 1]
    assert np.all((y[:, 0] - PLANE_Y) * (y[:, 1] - PLANE_Y) < 0)
    # and its broken bonds reach past the tip rule's point (the cut's end) at the last one
    x = _crossing_x(history.points, history.broken_pairs)
    assert np.count_nonzero(x > ROOT_X + m["final_crack_length_m"]) > 0
    for name in INDICES:
        bonds, cut = np.array(t[name]["bonds"]), np.array(t[name]["cut"])
        assert np.all(cut > 0) and np.all(bonds > cut), name
        # on this grid outside the monitoring acceptance's 10% (measured 13-15%, the same with
        # the fatigue in steps of 1 000 cycles)
        assert t[name]["relative_difference_max"] > 0.10, name


@pytest.mark.slow
@pytest.mark.xdist_group("monitor_transfer_fine")  # one worker makes the fine job
def test_on_a_clean_crack_the_two_transfers_agree_within_ten_percent_on_half_the_spacing(fine_job):
    """The monitoring acceptance's line (docs/monitoring.md, "Where they must agree, and how far
    they do"): the two damage-transfer routes agree on the crossed paths' indices within 10% at
    every interrogation after the crack grew, on the 0.5 mm grid with the fatigue in steps of
    1 000 cycles (measured: residual energy 6.0 and 5.3%, correlation 3.6 and 2.8% at 5.75 and
    6.75 mm; in steps of 500 cycles 6.0, 3.5% and 3.6, 1.7%)."""
    m, _ = fine_job
    assert m["transfer"]["interrogations"] == [1, 2] and m["crossed_paths"] == ["t0-t1"]
    assert m["final_crack_length_m"] == pytest.approx(6.75e-3)
    for name in INDICES:
        assert m["transfer"][name]["relative_difference_max"] <= 0.10, name


@pytest.mark.slow
@pytest.mark.xdist_group("monitor_transfer_fine")  # one worker makes the fine job
def test_the_two_transfers_converge_as_the_grid_is_refined(job, fine_job):
    """The routes' difference is the fatigue model's process zone, a few spacings long
    (docs/monitoring.md, "Where they must agree, and how far they do"): on half the spacing the
    broken bonds reach half as far past the tip rule's point at the last interrogation (1 mm ->
    0.5 mm), and each index's relative difference falls at each interrogation (measured:
    residual energy 13, 13% -> 6.0, 5.3%; correlation 14, 15% -> 3.6, 2.8%; with the 1 mm grid's
    fatigue steps of 2 000 cycles on the 0.5 mm grid too: 10.7, 5.3% and 6.4, 2.8%)."""
    coarse, coarse_history = job
    fine, fine_history = fine_job
    reach = []
    for m, history in ((coarse, coarse_history), (fine, fine_history)):
        a = m["final_crack_length_m"]
        reach.append(_reach(history, history.cycles[np.argmax(history.crack_length >= a)], a))
    assert reach == pytest.approx([1.0e-3, 0.5e-3], abs=1e-9)
    for name in INDICES:
        before = np.array(coarse["transfer"][name]["relative_difference"])
        after = np.array(fine["transfer"][name]["relative_difference"])
        assert np.all(after < before), (name, before, after)
